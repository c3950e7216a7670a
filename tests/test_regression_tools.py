"""csv-compare's tube and the FMI cross-check's band (pendulum_fmu/judging/_regression_tools.py).

Against the tube's definition evaluated plainly, the band against fmpy's own function,
hand-checkable steps, and a one-step-late master that the tube passes while the judge names it
late.
"""

import warnings

import numpy as np
import pytest

from pendulum_fmu import judge, simulate
from pendulum_fmu.judging._regression_tools import (
    CROSS_CHECK_OUTSIDE_SHARE,
    cross_check_band,
    csv_compare_tube,
    tube_envelopes,
)


def brute_force_envelopes(t_ref, y_ref, at, half_width, half_height):
    """The tube's definition, point by point.

    The reference line's lowest and highest value over [t - half_width, t + half_width], each
    segment's extremes at the ends of its part inside.
    """
    lower, upper = [], []
    for t in at:
        a, b = t - half_width, t + half_width
        seen = []
        for i in range(len(t_ref) - 1):
            t0, t1, y0, y1 = t_ref[i], t_ref[i + 1], y_ref[i], y_ref[i + 1]
            lo, hi = max(a, t0), min(b, t1)
            if lo > hi:
                continue
            for s in (lo, hi):
                seen.append(y0 if t1 == t0 else y0 + (y1 - y0) * (s - t0) / (t1 - t0))
        lower.append(min(seen) - half_height)
        upper.append(max(seen) + half_height)
    return np.array(lower), np.array(upper)


@pytest.mark.parametrize("seed", range(5))
def test_envelopes_match_the_definition_evaluated_plainly(seed):
    rng = np.random.default_rng(seed)
    t_ref = np.cumsum(rng.uniform(0.001, 0.1, 300))
    y_ref = np.cumsum(rng.normal(size=300))
    at = rng.uniform(t_ref[0], t_ref[-1], 400)
    half_width = rng.uniform(0.001, 2.0)
    lower, upper = tube_envelopes(t_ref, y_ref, at, half_width, 0.01)
    expected_lower, expected_upper = brute_force_envelopes(t_ref, y_ref, at, half_width, 0.01)
    np.testing.assert_allclose(lower, expected_lower, rtol=0, atol=1e-12)
    np.testing.assert_allclose(upper, expected_upper, rtol=0, atol=1e-12)


# A unit step at 5 s sampled every 1 ms over 10 s: the tube is +-0.002 * 10 s = +-20 ms wide
# and +-0.002 * 1 high.
TIME = np.linspace(0.0, 10.0, 10001)
STEP = (TIME >= 5.0).astype(float)


def test_a_step_10_ms_late_passes_the_tube():
    verdict = csv_compare_tube(TIME, STEP, TIME, (TIME >= 5.010).astype(float))
    assert (verdict.passed, verdict.outside, verdict.points) == (True, 0, 10001)
    assert verdict.half_width == pytest.approx(0.02, abs=1e-15)
    assert verdict.half_height == pytest.approx(0.002, abs=1e-15)


def test_a_step_25_ms_late_fails_the_tube_where_the_window_has_left_the_step():
    # The result is 0 up to 5.025 s; the tube's lower envelope is above 0 once its window starts
    # past the reference's ramp 4.999..5.000 s plus 0.002 of it: at 5.020 .. 5.025 s, 6 points.
    verdict = csv_compare_tube(TIME, STEP, TIME, (TIME >= 5.0255).astype(float))
    assert (verdict.passed, verdict.outside) == (False, 6)


def test_a_step_early_fails_on_the_other_side():
    # The result is 1 from 4.975 s; the upper envelope reaches 1 once its window's end is within
    # 0.002 of the ramp's top: from 4.979998 s. Outside: 4.975 .. 4.979 s, 5 points (the ramp
    # sits before 5 s, so the early side has one point fewer than the late side).
    verdict = csv_compare_tube(TIME, STEP, TIME, (TIME >= 4.9745).astype(float))
    assert (verdict.passed, verdict.outside) == (False, 5)


@pytest.mark.parametrize(("offset", "passed"), [(0.0019, True), (0.0021, False), (-0.0021, False)])
def test_an_offset_passes_only_within_the_tube_height(offset, passed):
    assert csv_compare_tube(TIME, STEP, TIME, STEP + offset).passed is passed


def test_a_constant_reference_takes_its_magnitude_as_its_range():
    # funnel's tubeSize.c: a range of zero falls back to |max|: +-0.002 * 3 around 3.
    assert csv_compare_tube(TIME, np.full_like(TIME, 3.0), TIME, np.full_like(TIME, 3.0059)).passed
    assert not csv_compare_tube(TIME, np.full_like(TIME, 3.0), TIME, np.full_like(TIME, 3.0061)).passed


def fmpy_band_outside(t_ref, y_ref, t, y) -> int:
    """The outliers fmpy.cross_check.validate_signal finds, over the reference's span."""
    from fmpy.cross_check import validate_signal

    with warnings.catch_warnings():  # fmpy imports scipy.ndimage.filters, deprecated in scipy 1.x
        warnings.simplefilter("ignore", DeprecationWarning)
        return int(np.count_nonzero(validate_signal(t, y, t_ref, y_ref, t_ref[0], t_ref[-1])[3]))


@pytest.mark.parametrize("seed", range(12))
def test_cross_check_band_finds_the_outliers_fmpys_function_finds(seed):
    # Random references (repeated times, flat ones, one of zeros among them) and results near the
    # band's edges, on their own time grids, partly outside the reference's span.
    rng = np.random.default_rng(seed)
    t_ref = np.sort(rng.uniform(0.0, 10.0, rng.integers(30, 3000)))
    t_ref[rng.integers(1, len(t_ref), 5)] = t_ref[rng.integers(0, len(t_ref) - 1, 5)]
    t_ref = np.sort(t_ref)
    y_ref = np.cumsum(rng.normal(size=len(t_ref))) * [1.0, 0.0, 1e-9, 3.0][seed % 4]
    if seed % 4 == 3:
        y_ref[:] = 3.0
    t = np.sort(rng.uniform(-1.0, 11.0, rng.integers(50, 4000)))
    y = np.interp(t, t_ref, y_ref) + rng.normal(scale=0.3 * (np.ptp(y_ref) or 1.0), size=len(t))
    verdict = cross_check_band(t_ref, y_ref, t, y)
    expected = fmpy_band_outside(t_ref, y_ref, t, y)
    assert verdict.outside == expected
    assert verdict.passed == (expected <= CROSS_CHECK_OUTSIDE_SHARE * len(t))
    assert 0 < expected < len(t)  # near the edges: some points in, some out


def test_cross_check_band_passes_a_late_step_and_fails_one_two_seconds_late():
    # The band is +-10 samples of 1000 over 10 s (+-0.1 s) and +-10 % of the range high;
    # a step 2 s late has 1.9 s of its 10 s, 19 % of its points, outside: more than 10 %.
    assert cross_check_band(TIME, STEP, TIME, (TIME >= 5.05).astype(float)).passed
    late = cross_check_band(TIME, STEP, TIME, (TIME >= 7.0).astype(float))
    assert not late.passed
    assert 1850 <= late.outside <= 1920


def test_one_step_late_master_passes_both_tools_while_the_judge_names_it_late():
    # h = 10 ms on a 10 s run: the master applies the torque step one step (10 ms) late.
    late = simulate(lambda t: 0.0 if t < 5.01 else 20.0, stop_time=10.0, step_size=0.01)
    judgement = judge(late, lambda t: 0.0 if t < 5.0 else 20.0, stop_time=10.0, step_size=0.01)
    assert (judgement.verdict, judgement.diagnosis) == ("fail", "input one step late")
    tube, band = judgement.regression_tools
    assert (tube["tool"], tube["passed"], tube["outside"]) == ("csv-compare tube", True, 0)
    assert tube["half_width"] == pytest.approx(0.02, abs=1e-15)
    assert (band["tool"], band["passed"]) == ("FMI cross-check band", True)
    assert judgement.summary()["regression_tools"] == judgement.regression_tools
