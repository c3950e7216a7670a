"""What the field's regression tools would say about a result, beside the judge's diagnosis.

csv-compare's tube and the FMI cross-check's band both compare a result with a reference result
and pass differences that a tolerance in time hides, so a master that is a step late can pass
them. The judge shows their verdicts so a user sees when that happens.

csv-compare's tube (modelica-tools/csv-compare; lbl-srg/funnel's pyfunnel computes the same
tube). Around each reference point (t_i, y_i) stands a rectangle of half-width
``dx = tolerance * (max t - min t)`` and half-height ``dy = tolerance * (max y - min y)``
(a range of zero falls back to ``|max|``, then to 1 in time and 1e-16 in value, as funnel's
tubeSize.c does). The tube is what the rectangle sweeps moving along the reference's line; its
upper envelope at t is ``dy`` plus the highest value of the reference line within
``[t - dx, t + dx]``, its lower envelope ``-dy`` plus the lowest. A result passes when each of
its points inside the reference's time span lies within the tube. The default tolerance is
csv-compare's, 0.002: at h = 10 ms on a 10 s run the tube is +-20 ms wide, two steps.

The FMI cross-check's band (modelica/fmi-cross-check's rules, as fmpy.cross_check validates a
submitted result): the reference resampled on 1000 points over the run, widened by a running
minimum and maximum over 21 samples and by 10 % of its range; a result fails when more than
10 % of its samples lie outside. fmpy.cross_check.validate_signal's steps, in numpy: fmpy's
function imports scipy.ndimage for its running minimum and maximum, about a third of a judge's
start-up (issue 42); tests/test_regression_tools.py holds this band to fmpy's function.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ._theta_series import ThetaSeries, series_of

CSV_COMPARE_TOLERANCE = 0.002  # csv-compare's default --tolerance
# The tube's times taken at once (tube_envelopes).
_BLOCK = 1 << 16
# fmi-cross-check's rule: a result fails with more than this share of its samples outside the band.
CROSS_CHECK_OUTSIDE_SHARE = 0.1


@dataclass(frozen=True)
class ToolVerdict:
    """One regression tool's verdict on one signal.

    Attributes
    ----------
    tool : str
        "csv-compare tube" or "FMI cross-check band".
    passed : bool
    outside : int
        The result's points outside the tube or band.
    points : int
        The result's points the tool looks at.
    half_width : float
        The tube's half-width in time (s); for the band, half its running window (s).
    half_height : float
        The tube's or band's half-height beside the reference (the signal's unit).
    note : str or None
        What the verdict rests on beyond the tool's rule: for the band of a long run, that its
        1,000 samples of the reference miss the reference's swings.
    """

    tool: str
    passed: bool
    outside: int
    points: int
    half_width: float
    half_height: float
    note: str | None = None


def _base(values: np.ndarray, smallest: float) -> float:
    """A signal's range as funnel's tubeSize.c takes it: max - min, else |max|, else smallest."""
    span = float(np.max(values) - np.min(values))
    return span or abs(float(np.max(values))) or smallest


def _range_max(values: np.ndarray, first: np.ndarray, end: np.ndarray) -> np.ndarray:
    """max(values[first:end]) for each pair (-inf where empty), by a sparse table.

    The table holds log2(longest query) levels of maxima over 2**k points, so each query reads
    two entries.
    """
    length = end - first
    table = [values]
    # Levels up to the longest query only: a tube's window holds a small share of the points.
    while 2 ** len(table) <= min(int(length.max(initial=0)), len(values)):
        half = 2 ** (len(table) - 1)
        table.append(np.maximum(table[-1][:-half], table[-1][half:]))
    level = np.floor(np.log2(np.maximum(length, 1))).astype(int)
    result = np.full(len(first), -np.inf)
    for k in np.unique(level[length > 0]):
        chosen = (level == k) & (length > 0)
        result[chosen] = np.maximum(table[k][first[chosen]], table[k][end[chosen] - 2**k])
    return result


def tube_envelopes(t_ref, y_ref, at, half_width: float, half_height: float) -> tuple[np.ndarray, np.ndarray]:
    """The tube's lower and upper envelopes at the times ``at``.

    Parameters
    ----------
    t_ref, y_ref : array_like
        The reference's points, in increasing time.
    at : array_like
        Times within [t_ref[0], t_ref[-1]].
    half_width, half_height : float
        The rectangle's half-width (time) and half-height (value).

    Returns
    -------
    lower, upper : numpy.ndarray
        The lowest and highest value of the reference line within ``at +- half_width``, less
        and plus ``half_height``.

    Examples
    --------
    >>> lower, upper = tube_envelopes([0.0, 1.0, 2.0], [0.0, 0.0, 1.0], [1.0, 1.5], 0.25, 0.1)
    >>> [round(float(v), 3) for v in lower], [round(float(v), 3) for v in upper]
    ([-0.1, 0.15], [0.35, 0.85])
    """
    t_ref, y_ref, at = (np.asarray(a, dtype=float) for a in (t_ref, y_ref, at))
    lower, upper = np.empty(len(at)), np.empty(len(at))
    # A block of the times at once, over the reference's points its windows reach (and one
    # either side, for the line's value at a window's end): the sparse table of a long run's
    # extremes spans a block's windows, not the run (13 levels of 3 million points were 300 MB).
    for begin in range(0, len(at), _BLOCK):
        block = slice(begin, begin + _BLOCK)
        start = np.clip(at[block] - half_width, t_ref[0], t_ref[-1])
        stop = np.clip(at[block] + half_width, t_ref[0], t_ref[-1])
        reached = slice(
            max(int(np.searchsorted(t_ref, start.min(), side="left")) - 1, 0),
            int(np.searchsorted(t_ref, stop.max(), side="right")) + 1,
        )
        lower[block], upper[block] = _envelopes(t_ref[reached], y_ref[reached], start, stop)
    return lower - half_height, upper + half_height


def _envelopes(
    t_ref: np.ndarray, y_ref: np.ndarray, start: np.ndarray, stop: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The lowest and highest value of the reference line within each window [start, stop]."""
    # A line's extremes over a window lie at its vertices inside it or at the window's ends.
    first = np.searchsorted(t_ref, start, side="left")
    end = np.searchsorted(t_ref, stop, side="right")
    ends = np.stack([np.interp(start, t_ref, y_ref), np.interp(stop, t_ref, y_ref)])
    highest = np.maximum(ends.max(axis=0), _range_max(y_ref, first, end))
    lowest = np.minimum(ends.min(axis=0), -_range_max(-y_ref, first, end))
    return lowest, highest


def csv_compare_tube(t_ref, y_ref, t, y, tolerance: float = CSV_COMPARE_TOLERANCE) -> ToolVerdict:
    """csv-compare's verdict on one signal: its tube at a relative tolerance (module docstring).

    Parameters
    ----------
    t_ref, y_ref : array_like
        The reference result's times (increasing) and values.
    t, y : array_like
        The result's times and values; points outside the reference's time span are not judged.
    tolerance : float
        Relative to the reference's ranges in time and value (csv-compare's default 0.002).

    Returns
    -------
    ToolVerdict

    Examples
    --------
    A unit step at 5 s, and the same step 10 ms late, inside a +-20 ms tube:

    >>> import numpy as np
    >>> t = np.linspace(0.0, 10.0, 1001)
    >>> verdict = csv_compare_tube(t, 1.0 * (t >= 5.0), t, 1.0 * (t >= 5.01))
    >>> verdict.passed, verdict.half_width
    (True, 0.02)
    """
    t_ref, y_ref, t, y = (np.asarray(a, dtype=float) for a in (t_ref, y_ref, t, y))
    half_width = tolerance * _base(t_ref, 1.0)
    half_height = tolerance * _base(y_ref, 1e-16)
    inside_span = (t >= t_ref[0]) & (t <= t_ref[-1])
    lower, upper = tube_envelopes(t_ref, y_ref, t[inside_span], half_width, half_height)
    judged = y[inside_span]
    outside = int(np.count_nonzero((judged < lower) | (judged > upper)))
    return ToolVerdict("csv-compare tube", outside == 0, outside, len(judged), half_width, half_height)


def _running(values: np.ndarray, window: int, extreme) -> np.ndarray:
    """scipy.ndimage's minimum_filter1d or maximum_filter1d (extreme np.min or np.max) of an odd
    window, at its default edges ("reflect": d c b a | a b c d | d c b a).
    """
    half = window // 2
    padded = np.pad(values, half, mode="symmetric")
    return extreme(np.lib.stride_tricks.sliding_window_view(padded, window), axis=1)


def _band_outliers(t, y, t_ref, y_ref, samples: int, window: int, height: float) -> tuple[np.ndarray, np.ndarray]:
    """fmpy.cross_check.validate_signal over the reference's span: the band's times and which
    points of the result lie outside it.
    """
    band_time = np.linspace(t_ref[0], t_ref[-1], samples)
    # Of repeated reference times the first, as fmpy keeps them.
    first = np.concatenate(([True], np.diff(t_ref) > 0))
    band = np.interp(band_time, t_ref[first], y_ref[first])
    low, high = np.min(band), np.max(band)
    if low == high:
        width = 0.5 if low == 0 else np.abs(low) * height
    else:
        width = (high - low) * height
    lower = np.interp(t, band_time, _running(band, window, np.min) - width)
    upper = np.interp(t, band_time, _running(band, window, np.max) + width)
    outside = ((y < lower) | (y > upper)) & (t >= t_ref[0]) & (t <= t_ref[-1])
    return band_time, outside


def cross_check_band(t_ref, y_ref, t, y) -> ToolVerdict:
    """The FMI cross-check's verdict on one signal: fmpy.cross_check's band (module docstring).

    Parameters
    ----------
    t_ref, y_ref : array_like
        The reference result's times (increasing) and values; the band spans its times.
    t, y : array_like
        The result's times and values.

    Returns
    -------
    ToolVerdict

    Examples
    --------
    >>> import numpy as np
    >>> t = np.linspace(0.0, 10.0, 1001)
    >>> cross_check_band(t, np.sin(t), t, np.sin(t - 0.05)).passed
    True
    """
    t_ref, y_ref, t, y = (np.asarray(a, dtype=float) for a in (t_ref, y_ref, t, y))
    samples, window = 1000, 21  # fmpy.cross_check.validate_signal's defaults, the rules' band
    band_time, outside = _band_outliers(t, y, t_ref, y_ref, samples, window, 0.1)
    half_height = 0.1 * _base(np.interp(band_time, t_ref, y_ref), 5.0)
    count = int(np.count_nonzero(outside))
    return ToolVerdict(
        "FMI cross-check band",
        count <= CROSS_CHECK_OUTSIDE_SHARE * len(y),
        count,
        len(y),
        float((window // 2) * (band_time[-1] - band_time[0]) / (samples - 1)),
        half_height,
    )


def regression_verdicts(times, reference, result) -> list[dict]:
    """Both tools' verdicts on theta: the result against the reference at the same times.

    Parameters
    ----------
    times : array_like
        The result's times (s).
    reference, result : array_like
        theta (rad) of the reference and of the result at those times.

    Returns
    -------
    list of dict
        ToolVerdict's fields, csv-compare's tube first.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.linspace(0.0, 10.0, 1001)
    >>> [v["passed"] for v in regression_verdicts(t, t**2, (t - 0.01) ** 2)]
    [True, True]
    """
    time, reference_theta, result_theta = (np.asarray(values, dtype=float) for values in (times, reference, result))
    with series_of(time, reference_theta, result_theta) as series:
        return series_verdicts(series)


def series_verdicts(series: ThetaSeries) -> list[dict]:
    """regression_verdicts of a result judged a window at a time: two passes over its spilled
    rows, a block at a time (the tube's reach either side of a block read with it).

    Parameters
    ----------
    series : ThetaSeries
        The result's times and theta, and the reference's theta at them.

    Returns
    -------
    list of dict
        As regression_verdicts.
    """
    first, last = series.first_time, series.last_time
    half_width = CSV_COMPARE_TOLERANCE * ((last - first) or abs(last) or 1.0)
    span = series.highest - series.lowest
    half_height = CSV_COMPARE_TOLERANCE * (span or abs(series.highest) or 1e-16)
    samples, window = 1000, 21  # fmpy.cross_check.validate_signal's defaults, the rules' band
    band_time = np.linspace(first, last, samples)
    band = _resampled(series, band_time)
    low, high = float(np.min(band)), float(np.max(band))
    if low == high:
        width = 0.5 if low == 0 else abs(low) * 0.1
    else:
        width = (high - low) * 0.1
    band_lower, band_upper = _running(band, window, np.min) - width, _running(band, window, np.max) + width
    tube_outside = band_outside = reference_outside = 0
    for time, reference, theta in series.blocks():
        near_time, near_theta = series.reference_between(time[0] - half_width, time[-1] + half_width)
        lower, upper = tube_envelopes(near_time, near_theta, time, half_width, half_height)
        tube_outside += int(np.count_nonzero((theta < lower) | (theta > upper)))
        lower, upper = np.interp(time, band_time, band_lower), np.interp(time, band_time, band_upper)
        band_outside += int(np.count_nonzero((theta < lower) | (theta > upper)))
        reference_outside += int(np.count_nonzero((reference < lower) | (reference > upper)))
    return [
        asdict(ToolVerdict("csv-compare tube", tube_outside == 0, tube_outside, series.rows, half_width, half_height)),
        asdict(
            ToolVerdict(
                "FMI cross-check band",
                band_outside <= CROSS_CHECK_OUTSIDE_SHARE * series.rows,
                band_outside,
                series.rows,
                float((window // 2) * (band_time[-1] - band_time[0]) / (samples - 1)),
                0.1 * (high - low or abs(high) or 5.0),
                _coarse_band(reference_outside, series.rows, band_time),
            )
        ),
    ]


def _coarse_band(reference_outside: int, rows: int, band_time: np.ndarray) -> str | None:
    """A line saying the band cannot follow the signal: the reference itself lies outside it
    (its 1,000 samples, one every band_time's spacing, miss the reference's swings); or None.
    """
    if not reference_outside:
        return None
    return (
        f"the reference itself lies outside it at {reference_outside:,} of {rows:,} points: its 1,000 "
        f"samples, one every {band_time[1] - band_time[0]:.3g} s, are coarser than the signal"
    )


def _resampled(series: ThetaSeries, at: np.ndarray) -> np.ndarray:
    """The reference's line at the times `at` (increasing, within the series), of repeated times
    the first row's value, as fmpy keeps them: a block at a time, with the last row kept before it.
    """
    out = np.empty(len(at))
    done = 0
    kept_time, kept_theta = np.empty(0), np.empty(0)
    for time, theta, _ in series.blocks():
        xp, fp = np.r_[kept_time, time], np.r_[kept_theta, theta]
        first = np.r_[True, np.diff(xp) > 0]
        xp, fp = xp[first], fp[first]
        reached = done + int(np.searchsorted(at[done:], xp[-1], side="right"))
        out[done:reached] = np.interp(at[done:reached], xp, fp)
        done = reached
        kept_time, kept_theta = xp[-1:], fp[-1:]
    out[done:] = kept_theta[-1]
    return out


def format_verdicts(verdicts: list[dict]) -> list[str]:
    """One line per tool, as the judge prints it.

    Parameters
    ----------
    verdicts : list of dict
        As regression_verdicts returns them.

    Returns
    -------
    list of str

    Examples
    --------
    >>> format_verdicts([{"tool": "csv-compare tube", "passed": True, "outside": 0, "points": 11,
    ...                   "half_width": 0.02, "half_height": 0.5}])
    ['csv-compare tube: pass (0 of 11 points outside; +-0.02 s, +-0.5 rad)']
    """
    return [
        f"{v['tool']}: {'pass' if v['passed'] else 'fail'} ({v['outside']} of {v['points']} points "
        f"outside; +-{v['half_width']:.3g} s, +-{v['half_height']:.3g} rad)"
        + (f"; {v['note']}" if v.get("note") else "")
        for v in verdicts
    ]


__all__ = [
    "CSV_COMPARE_TOLERANCE",
    "ToolVerdict",
    "cross_check_band",
    "csv_compare_tube",
    "format_verdicts",
    "regression_verdicts",
    "series_verdicts",
    "tube_envelopes",
]
