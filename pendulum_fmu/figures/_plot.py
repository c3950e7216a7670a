"""Figures in the style of the OpenSim tutorial: theta and omega over time, tools overlaid."""

from __future__ import annotations

import functools
import numbers
import os
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.backend_bases import FigureCanvasBase
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.layout_engine import TightLayoutEngine
from matplotlib.lines import Line2D
from numpy.typing import ArrayLike

from .._atomic_files import replacing_path
from .._errors import InvalidInput
from ..fmu._parameters import Fmu, merged_parameters, unit

THETA_LABEL = r"Position $\theta$ in rad"
OMEGA_LABEL = r"Velocity $\omega$ in rad/s"
TIME_LABEL = r"Time $t$ in s"


def case_title(
    torque,
    parameters: dict[str, float] | None = None,
    theta0: float = 0.0,
    omega0: float = 0.0,
    fmu_path: Fmu = None,
) -> str:
    """'Torque-driven pendulum: torque 20 N.m, gravity 9.81 m/s2', then every parameter the user
    set and a start value other than 0, each with the unit the FMU declares.

    torque: a constant (its value is shown), a CSV path (its file name) or any other signal.
    """
    if isinstance(torque, numbers.Real):
        shown = [f"torque {torque:g} {unit('torque', fmu_path)}"]
    elif isinstance(torque, (str, os.PathLike)):
        shown = [f"torque from {Path(torque).name}"]
    else:
        shown = ["a torque signal"]
    values = {
        "gravity": merged_parameters(parameters, fmu_path)["gravity"],
        **(parameters or {}),
        **{name: value for name, value in (("theta0", theta0), ("omega0", omega0)) if value},
    }
    shown += [f"{name} {value:g} {unit(name, fmu_path)}" for name, value in values.items()]
    return f"Torque-driven pendulum: {', '.join(shown)}"


def check_figure_path(path: str | Path) -> None:
    """Refuse, before any work, a figure name whose extension matplotlib writes no format for.

    Parameters
    ----------
    path : str or Path
        The figure to write; without an extension it is a PNG.

    Raises
    ------
    InvalidInput
        An extension such as .csv, which no figure format has.
    """
    suffix = Path(path).suffix.lstrip(".").lower()
    formats = FigureCanvasBase.get_supported_filetypes()
    if suffix and suffix not in formats:
        raise InvalidInput(
            f"{path}: a figure cannot be written as .{suffix}; end its name in .png, "
            f".pdf or .svg (or {', '.join('.' + name for name in sorted(formats))})"
        )


# The largest magnitude a figure draws. matplotlib's margins, ticks and log decades overflow near
# the largest double (1e307 on a log axis already), failing or warning mid-draw; a value this
# large has long stopped being a pendulum's anyway.
DRAWABLE = 1e300


def _too_large(values) -> float | None:
    """The first value of magnitude over DRAWABLE, or infinite, or None (NaNs are gaps)."""
    values = np.asarray(values, dtype=float).ravel()
    bad = values[np.abs(np.nan_to_num(values, nan=0.0)) > DRAWABLE]
    return float(bad[0]) if len(bad) else None


def _leave_out_undrawable(ax) -> None:
    """Take out of the panel every line or band reaching past DRAWABLE and write in its place
    one line saying what and how large, rather than fail or draw a garbage scale.
    """
    notes = []
    for artist in [*ax.lines, *ax.collections]:
        values: tuple[ArrayLike, ...]  # one array for an axhline, two for a line, one per path else
        if isinstance(artist, Line2D):
            if artist.get_transform() is not ax.transData:  # axhline: its x is the panel's width
                values = (artist.get_ydata(),)
            else:
                values = (artist.get_xdata(), artist.get_ydata())
        else:
            values = tuple(path.vertices for path in artist.get_paths())
        extreme = next((v for v in map(_too_large, values) if v is not None), None)
        if extreme is not None:
            label = artist.get_label()
            notes.append(
                f"{label if label and not label.startswith('_') else 'a line'} reaches {extreme:.3g}: too large to draw"
            )
            artist.remove()
    for index, note in enumerate(dict.fromkeys(notes)):
        ax.text(0.5, 0.88 - 0.12 * index, note, transform=ax.transAxes, ha="center", va="center", fontsize=10)
    if notes:
        ax.relim()
        ax.autoscale_view()
        # With nothing left to scale to, matplotlib keeps the limits the removed data set.
        for limits, scale, set_limits in (
            (ax.get_xlim(), ax.get_xscale(), ax.set_xlim),
            (ax.get_ylim(), ax.get_yscale(), ax.set_ylim),
        ):
            if _too_large(limits) is not None:
                set_limits((1, 10) if scale == "log" else (0, 1))


def _drawing(plot):
    """plot, with numpy's overflow warnings silenced while it draws: values near the largest
    double overflow in differences and in matplotlib's autoscaling, which runs as each panel is
    drawn, before _finish leaves such values out and resets the limits they set.
    """

    @functools.wraps(plot)
    def quietly(*args, **kwargs):
        with np.errstate(over="ignore", invalid="ignore"):
            return plot(*args, **kwargs)

    return quietly


# Dots per inch of every figure written.
DPI = 120


def _figure(width: float, height: float) -> Figure:
    # A Figure of its own, not pyplot's: no backend is chosen or changed (a notebook's inline
    # plots stay as they are), no display is needed, and nothing is kept once the file is written.
    # Drawn at the dpi it is saved at, on an Agg canvas of its own, so that laying it out and
    # writing it share one renderer and measure each text once (a bare Figure lays out on a
    # throwaway renderer at 100 dpi, and savefig measures everything again at 120).
    fig = Figure(figsize=(width, height), dpi=DPI)
    FigureCanvasAgg(fig)
    return fig


def _finish(fig, axes, title: str, path: str | Path) -> Path:
    for ax in np.ravel(axes):
        _leave_out_undrawable(ax)
        ax.grid(True, alpha=0.4)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(loc="upper left", fontsize=9, frameon=True)
    fig.suptitle(title, fontsize=13)
    # fig.tight_layout()'s layout, for less. Its engine, given rect (0, 0, 1, 1) as tight_layout
    # gives it, measures every panel twice, the second time with the margins of the first, to
    # the same result; with no rect (matplotlib's get_tight_layout_figure: the whole figure) it
    # measures once. Run here rather than set on the figure, it leaves no engine behind, so
    # savefig draws once instead of laying out again in a draw of its own first.
    TightLayoutEngine(rect=None).execute(fig)  # type: ignore[arg-type]  # the stubs allow a tuple only
    path = Path(path)
    check_figure_path(path)
    with replacing_path(path) as partial:
        fig.savefig(partial, dpi=DPI, format=path.suffix.lstrip(".") or "png")
    return path


@_drawing
def plot_overlay(runs: dict[str, np.ndarray], path: str | Path, title: str) -> Path:
    r"""Theta and omega of each run, overlaid (dashed after the first, so coincident lines show).

    Parameters
    ----------
    runs : dict of str to numpy.ndarray
        Result arrays (as simulate() and reference() return them) by their labels in the legend.
    path : str or Path
        The figure to write, whole or not at all; its extension says the format (none: PNG).
    title : str
        The figure's title.

    Returns
    -------
    Path
        path.

    Raises
    ------
    InvalidInput
        An extension no figure format has (such as .csv).
    CannotWrite
        path cannot be written.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from pendulum_fmu import plot_overlay, reference, simulate
    >>> runs = {"fmu": simulate(20.0, stop_time=1.0), "reference": reference(20.0, stop_time=1.0)}
    >>> figure = plot_overlay(runs, Path(tempfile.mkdtemp(), "overlay.png"), "20 N.m from rest")
    >>> figure.name, figure.read_bytes()[:4]
    ('overlay.png', b'\x89PNG')
    """
    fig = _figure(10, 6)
    axes = fig.subplots(2, 1, sharex=True)
    for i, (label, run) in enumerate(runs.items()):
        style = dict(linewidth=2 if i == 0 else 1.5, linestyle="-" if i == 0 else "--")
        axes[0].plot(run["time"], run["theta"], label=label, **style)
        axes[1].plot(run["time"], run["omega"], label=label, **style)
    axes[0].set_ylabel(THETA_LABEL)
    axes[1].set_ylabel(OMEGA_LABEL)
    axes[1].set_xlabel(TIME_LABEL)
    return _finish(fig, axes, title, path)


def _draw_difference(ax, time: np.ndarray, difference: np.ndarray, label: str, index: int) -> None:
    """|difference| on a log axis. Exact zeros have no place there: they are left out and the
    label says how many (a point between two of them is marked, having no line); a difference
    that is zero everywhere is written into the panel instead of drawn.
    """
    ax.set_yscale("log")
    identical = difference == 0
    if identical.all():
        ax.text(
            0.5,
            1 - 0.12 * index,
            f"{label}: identical at every point",
            transform=ax.transAxes,
            ha="center",
            va="center",
            fontsize=10,
        )
        return
    note = (
        f" ({np.count_nonzero(identical)} of {len(difference)} points identical, not drawn)" if identical.any() else ""
    )
    (line,) = ax.plot(time, np.where(identical, np.nan, difference), label=label + note)
    gap = np.r_[True, identical, True]
    alone = ~identical & gap[:-2] & gap[2:]
    if alone.any():
        ax.plot(time[alone], difference[alone], ".", color=line.get_color())


@_drawing
def plot_comparison(runs: dict[str, np.ndarray], path: str | Path, title: str) -> Path:
    """Left: theta and omega of every tool overlaid. Right: |difference| of each tool against
    the first one, on a log scale, where agreement to 1e-10 is visible.
    """
    fig = _figure(14, 6)
    axes = fig.subplots(2, 2, sharex=True)
    labels = list(runs)
    base = runs[labels[0]]
    for i, label in enumerate(labels):
        run = runs[label]
        style = dict(linewidth=2 if i == 0 else 1.5, linestyle="-" if i == 0 else "--")
        axes[0, 0].plot(run["time"], run["theta"], label=label, **style)
        axes[1, 0].plot(run["time"], run["omega"], label=label, **style)
        if i:
            for row, name in enumerate(("theta", "omega")):
                _draw_difference(axes[row, 1], run["time"], np.abs(run[name] - base[name]), f"{label} - {labels[0]}", i)
    axes[0, 0].set_ylabel(THETA_LABEL)
    axes[1, 0].set_ylabel(OMEGA_LABEL)
    axes[0, 1].set_ylabel(r"$|\Delta\theta|$ in rad")
    axes[1, 1].set_ylabel(r"$|\Delta\omega|$ in rad/s")
    for ax in axes[1]:
        ax.set_xlabel(TIME_LABEL)
    return _finish(fig, axes, title, path)


@_drawing
def plot_cases(runs: dict[str, np.ndarray], path: str | Path, title: str) -> Path:
    """Theta and omega of many cases, coloured along a colormap; labelled when few enough."""
    fig = _figure(10, 6)
    axes = fig.subplots(2, 1, sharex=True)
    colors = matplotlib.colormaps["viridis"](np.linspace(0, 0.9, max(len(runs), 1)))
    labelled = len(runs) <= 12
    for color, (label, run) in zip(colors, runs.items(), strict=False):
        axes[0].plot(run["time"], run["theta"], color=color, linewidth=1.5, label=label if labelled else None)
        axes[1].plot(run["time"], run["omega"], color=color, linewidth=1.5)
    axes[0].set_ylabel(THETA_LABEL)
    axes[1].set_ylabel(OMEGA_LABEL)
    axes[1].set_xlabel(TIME_LABEL)
    return _finish(fig, axes, title, path)


QUANTILE_BANDS = ((0.05, 0.95), (0.25, 0.75))
# More distinct values than this on an axis are pooled into this many equal-width bins.
BAND_LEVELS = 50


def _quantiles(x: np.ndarray, y: np.ndarray, quantiles) -> tuple[np.ndarray, list[np.ndarray]]:
    """The levels of x (bin centres when there are many) and, per level, the quantiles of the y
    sharing it (numpy's linear method), in one sort rather than a call per level.
    """
    levels = np.unique(x)
    if len(levels) > BAND_LEVELS:
        edges = np.linspace(levels[0], levels[-1], BAND_LEVELS + 1)
        bins = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, BAND_LEVELS - 1)
        x = ((edges[:-1] + edges[1:]) / 2)[bins]
    order = np.lexsort((y, x))
    x, y = x[order], y[order]
    starts = np.flatnonzero(np.r_[True, x[1:] != x[:-1]])
    counts = np.diff(np.r_[starts, len(x)])
    values = []
    for q in quantiles:
        position = starts + q * (counts - 1)
        low = np.floor(position).astype(int)
        high = np.minimum(low + 1, starts + counts - 1)
        values.append(y[low] + (y[high] - y[low]) * (position - low))
    return x[starts], values


@_drawing
def plot_case_bands(
    values: dict[str, np.ndarray],
    summaries: dict[str, np.ndarray],
    path: str | Path,
    title: str,
    units: dict[str, str] | None = None,
) -> Path:
    """For many cases: each summary (a row of panels) against each swept value (a column), as
    the median and the 5-95 % and 25-75 % bands over the cases sharing that value; where each
    value has one case there is nothing to spread, and the cases alone are drawn. One sort per
    panel, so 100,000 cases draw about as fast as 100. NaN summaries (failed cases) are left out.
    units: {swept name: unit} for the axes.
    """
    # min < max rather than counting distinct values: no sort of every case's value.
    swept = {name: column for name, column in values.items() if column.min() < column.max()} or values
    fig = _figure(4.5 * len(swept) + 1, 6)
    # A column's panels share its x axis, so only the bottom one writes its tick labels: the
    # rows above would repeat them, each label another text to lay out and draw.
    axes = fig.subplots(len(summaries), len(swept), squeeze=False, sharex="col", sharey="row")
    labelled = set()

    def once(text):  # each legend entry on the first panel that draws it
        if text in labelled:
            return None
        labelled.add(text)
        return text

    for column, (name, x) in enumerate(swept.items()):
        for row, (label, y) in enumerate(summaries.items()):
            ax = axes[row, column]
            keep = np.isfinite(y)
            if column == 0:
                ax.set_ylabel(label)
            if row == len(summaries) - 1:
                ax.set_xlabel(f"{name} in {units[name]}" if units and units.get(name) else name)
            if not keep.any():
                continue
            quantiles = [q for band in QUANTILE_BANDS for q in band] + [0.5]
            levels, (*bands, median) = _quantiles(x[keep], y[keep], quantiles)
            if len(levels) == np.count_nonzero(keep):  # one case per value: no spread to show
                ax.plot(levels, median, color="C0", marker=".", label=once("one case per value"))
                continue
            for (low, high), (q_low, q_high), alpha in zip(
                QUANTILE_BANDS, zip(bands[::2], bands[1::2], strict=False), (0.25, 0.45), strict=False
            ):
                ax.fill_between(
                    levels,
                    q_low,
                    q_high,
                    alpha=alpha,
                    color="C0",
                    linewidth=0,
                    label=once(f"{low:.0%}-{high:.0%} of cases"),
                )
            ax.plot(levels, median, color="C0", marker="." if len(levels) < 30 else None, label=once("median"))
    return _finish(fig, axes, title, path)


def _log_difference(ax, time: np.ndarray, difference: np.ndarray, label: str, **style) -> int:
    """|difference| on a log axis, leaving out the points where it is exactly zero (a log axis has
    no zero, and a floor would draw them as spikes); returns how many were left out.
    """
    magnitude = np.abs(difference)
    zero = magnitude == 0
    if not zero.all():
        ax.semilogy(time, np.where(zero, np.nan, magnitude), label=label, **style)
    return int(zero.sum())


@_drawing
def plot_judgement(judgement, path: str | Path, title: str) -> Path:
    """A judged result (judge.Judgement): the torque the run asks for and, when the diagnosis
    names a variant, the torque that variant applies (N.m); theta of the result and of the
    reference (rad); |theta_result - theta_reference| and the variant's own difference from the
    reference (rad, log), with the tolerance. Exact zeros are said in words, not drawn. A long
    run comes drawn from Judgement.drawn: a few thousand points that keep every extreme.
    """
    drawn = judgement.drawn
    time, torque, theta, given = drawn["time"], drawn["torque"], drawn["reference"], drawn["result"]
    difference = given - theta
    explained = not np.all(np.isnan(drawn["explained_theta"]))
    zeros, points = judgement.exact_zeros, judgement.points
    fig = _figure(10, 8)
    axes = fig.subplots(3, 1, sharex=True)
    axes[0].step(time, torque, where="post", linewidth=2, label="the run's torque")
    if explained and not np.array_equal(drawn["explained_torque"], torque):
        axes[0].step(
            time,
            drawn["explained_torque"],
            where="post",
            linestyle="--",
            linewidth=1.5,
            label=f"applied if {judgement.diagnosis}",
        )
    axes[0].set_ylabel(r"Torque $\tau$ in N.m")
    axes[1].plot(time, theta, linewidth=2, label="reference")
    axes[1].plot(time, given, linestyle="--", linewidth=1.5, label=judgement.source)
    axes[1].set_ylabel(THETA_LABEL)
    _log_difference(axes[2], time, difference, "|result - reference|", linewidth=1.5)
    if explained:
        _log_difference(
            axes[2],
            time,
            drawn["explained_theta"] - theta,
            f"|{judgement.diagnosis} - reference|",
            linestyle="--",
            linewidth=1.5,
        )
    axes[2].axhline(judgement.tolerance, color="grey", linestyle=":", label=f"tolerance {judgement.tolerance:g} rad")
    axes[2].set_yscale("log")
    if zeros:
        note = (
            "the result equals the reference exactly at every point (difference 0 rad)"
            if zeros == points
            else f"difference exactly 0 rad at {zeros:,} of {points:,} points (not drawn)"
        )
        axes[2].text(0.01, 0.04, note, transform=axes[2].transAxes, fontsize=9)
    axes[2].set_ylabel(r"$|\Delta\theta|$ in rad")
    axes[2].set_xlabel(TIME_LABEL)
    return _finish(fig, axes, f"{title}: {judgement.verdict}, {judgement.diagnosis}", path)


@_drawing
def plot_calls(judged: dict, path: str | Path, title: str) -> Path:
    """What a master did to each instance, from its calls (calls.judge_calls's result).

    Parameters
    ----------
    judged : dict
        As pendulum_fmu.judging._call_judge.judge_calls returns it.
    path : str or Path
        The figure's file.
    title : str

    Returns
    -------
    Path

    Examples
    --------
    >>> plot_calls(judge_calls("run.log", None, {0: "torque"}), "calls.png", "run.log")  # doctest: +SKIP
    """
    fig = _figure(10, 3 + 2.5 * len(judged))
    axes = fig.subplots(len(judged), 1, squeeze=False)
    for ax, (name, result) in zip(axes[:, 0], judged.items(), strict=True):
        steps = result["steps"]
        time = [step["time"] for step in steps]
        ax.step(
            time,
            [step["torque"] for step in steps],
            where="post",
            linewidth=2,
            label="torque at each step's start, as the master set it",
        )
        if result["intended_torque"] is not None:
            intended = result["intended_torque"][: len(time)]
            ax.step(
                time[: len(intended)], intended, where="post", linestyle="--", linewidth=1.5, label="the intended run's"
            )
        found = result["differences"]
        ax.set_title(f"instance {name}" + ("" if found is None else f": {len(found)} difference(s)"), fontsize=10)
        if found:
            ax.text(0.01, 0.04, "\n".join(found[:4]), transform=ax.transAxes, fontsize=7, verticalalignment="bottom")
        ax.set_ylabel(r"Torque $\tau$ in N.m")
        ax.set_xlabel(TIME_LABEL)
    return _finish(fig, axes, title, path)
