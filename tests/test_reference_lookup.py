"""The oracle's torque look-ups, from doubles precomputed once, against the plain exact ones.

The oracle decides which step holds a time in exact fractions (docs/signals.md's tolerance); its
look-ups over whole arrays (Holding.values_after, TorqueFile.held_after) decide most times with
doubles and must give the very same values. The signals are random, with jumps on step
boundaries (decimal multiples of awkward steps), an ulp off them and within or just outside the
tolerance; the times are the grid, the jumps, and the doubles around where a time's tolerance
reaches a point, where only exact arithmetic can tell the side.
"""

import itertools
import math
from fractions import Fraction

import numpy as np
import pytest

from benchmarks.signal_cases import random_step_rows, write_rows
from pendulum_fmu.oracle._exact_signal import (
    TOLERANCE_STEPS,
    Holding,
    SignalWindows,
    exact_time,
    exact_times,
    time_doubles,
    time_grid,
    with_events,
)
from pendulum_fmu.oracle._file_rows import FileRows

AWKWARD_STEPS = (3e-4, 7e-4, 9e-4, 1e-3, 9e-3, 0.03, 0.3, 1 / 3000)


def _events(rng, start: Fraction, step: Fraction, stop: Fraction) -> list[Fraction]:
    """Jump times: on step boundaries as a person writes them, an ulp off, within and just
    outside the tolerance of one, and anywhere.
    """
    count = int((stop - start) / step)
    events = []
    for k in rng.integers(1, count, size=12).tolist():
        boundary = float(start + k * step)
        tolerance = float(TOLERANCE_STEPS * step)
        events += [
            exact_time(boundary),
            exact_time(math.nextafter(boundary, math.inf)),
            exact_time(boundary + 0.5 * tolerance),
            exact_time(boundary - 0.5 * tolerance),
            exact_time(boundary + 2 * tolerance),
        ]
    events += [exact_time(t) for t in rng.uniform(float(start), float(stop), size=12).tolist()]
    return sorted(set(events))


def _times(rng, points: list[Fraction], step: Fraction) -> np.ndarray:
    """The grid as a master computes it (start + k*h), the points, and the doubles around where
    t + tolerance(t) reaches a point.
    """
    doubles = np.array([float(p) for p in points])
    grid = doubles[0] + float(step) * np.arange(len(points))
    reach = doubles - np.maximum(float(TOLERANCE_STEPS * step), 64 * np.spacing(np.abs(doubles)))
    nudged = [reach]
    for k in range(1, 4):  # k ulp either side
        below, above = reach.copy(), reach.copy()
        for _ in range(k):
            below, above = np.nextafter(below, -np.inf), np.nextafter(above, np.inf)
        nudged += [below, above]
    anywhere = rng.uniform(doubles[0], doubles[-1], size=200)
    return np.concatenate([grid, doubles, *nudged, anywhere])


@pytest.mark.parametrize("seed", range(8))
def test_values_after_equals_the_exact_look_up_on_random_signals(seed):
    rng = np.random.default_rng(seed)
    step = exact_time(AWKWARD_STEPS[seed % len(AWKWARD_STEPS)])
    start = exact_time([0.0, 0.25, -1.5, 1e4][seed % 4])
    stop = start + 60 * step
    points = with_events(time_grid(start, stop, step), _events(rng, start, step, stop), step)
    values = rng.uniform(-40, 40, size=len(points) - 1).tolist()
    for signal_step in (step, Fraction(0)):  # a signal's tolerance, and a schedule's (none)
        holding = Holding(points, values, signal_step)
        times = _times(rng, points, step)
        exact = [holding.value_after(exact_time(t)) for t in times.tolist()]
        assert holding.values_after(times).tolist() == exact


def test_values_after_decides_a_grid_by_doubles(monkeypatch):
    """The grid a master steps on, 3001 points, needs no exact look-up at all."""
    step = exact_time(1e-3)
    points = time_grid(Fraction(0), Fraction(3), step)
    holding = Holding(points, [float(k % 7) for k in range(len(points) - 1)], step)
    exact_calls = []
    plain = holding.value_after
    monkeypatch.setattr(holding, "value_after", lambda t: exact_calls.append(t) or plain(t))
    times = 1e-3 * np.arange(3001)
    assert holding.values_after(times).tolist() == [plain(exact_time(t)) for t in times.tolist()]
    assert exact_calls == []


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("running_sum", [False, True])
def test_held_after_equals_the_exact_look_up_on_random_files(tmp_path, seed, running_sum):
    rng = np.random.default_rng(300 + seed)
    step = exact_time(AWKWARD_STEPS[seed % len(AWKWARD_STEPS)])
    rows = random_step_rows(rng, stop_time=1.0, running_sum=running_sum)
    # Jumps on step boundaries, and a sloped stretch (held at each step's start, not a row's).
    boundary = repr(float(40 * step))
    # Rows around the edge of a point's tolerance, an ulp or two either side of it.
    edge = float(20 * step) + float(TOLERANCE_STEPS * step)
    edges = [edge]
    for _ in range(2):
        edges = [math.nextafter(edges[0], -math.inf), *edges, math.nextafter(edges[-1], math.inf)]
    added = [(boundary, 7.0), (boundary, -7.0), (1.2, 3.0), (1.5, -9.0)]
    added += [(repr(t), u) for t, u in zip(edges, rng.uniform(-40, 40, size=len(edges)).tolist(), strict=True)]
    taken = {float(t) for t, _ in added}
    rows = sorted([*[row for row in rows if float(row[0]) not in taken], *added], key=lambda row: float(row[0]))
    file = FileRows(write_rows(tmp_path / "signal.csv", rows))
    signal = file.rows(Fraction(-1), file.last + 1)
    points = with_events(time_grid(Fraction(0), Fraction(2), step), signal.jumps(), step)
    exact = [signal.after(signal.latest_event_near(p, step)) for p in points]
    assert signal.held_after(points, step, time_doubles(points), exact_times(points, signal)).tolist() == exact
    assert signal.held_after(points, step, time_doubles(points), None).tolist() == exact


@pytest.mark.parametrize("seed", range(6))
def test_ramp_pieces_equal_the_exact_look_ups_on_random_files(tmp_path, seed):
    """A ramp's pieces, made in exact integers a window at once, against the definition in
    fractions: a piece between consecutive row times, its torque just after its start and its
    rate to the torque just before its end; its events the rows off the grid; its reports.
    """
    rng = np.random.default_rng(500 + seed)
    step = exact_time(AWKWARD_STEPS[seed % len(AWKWARD_STEPS)])
    rows = random_step_rows(rng, stop_time=1.0, running_sum=bool(seed % 2))
    # Rows on the grid as a recorded torque has them, an ulp off and within the tolerance.
    on_grid = [(repr(float(k * step)), float(rng.uniform(-40, 40))) for k in range(1, 30)]
    edge = float(17 * step) + 0.5 * float(TOLERANCE_STEPS * step)
    added = [*on_grid, (repr(math.nextafter(float(31 * step), math.inf)), 5.0), (repr(edge), -5.0)]
    # Rows around the edge of a point's tolerance, a few ulp either side of it.
    edges = [float(35 * step) + float(TOLERANCE_STEPS * step)]
    for _ in range(3):
        edges = [math.nextafter(edges[0], -math.inf), *edges, math.nextafter(edges[-1], math.inf)]
    added += [(repr(t), float(u)) for t, u in zip(edges, rng.uniform(-40, 40, size=len(edges)), strict=True)]
    taken = {float(t) for t, _ in added}
    rows = sorted([*[row for row in rows if float(row[0]) not in taken], *added], key=lambda row: float(row[0]))
    path = write_rows(tmp_path / "signal.csv", rows)
    windows = SignalWindows(str(path), Fraction(0), Fraction(1), step, True, None)
    for k0 in range(0, windows.steps, 40):
        k1 = min(k0 + 40, windows.steps)
        pieces, grid = windows.window(k0, k1), windows.window_grid(k0, k1)
        signal = windows._rows(grid)
        times = signal.times
        inside = [t for t in times if grid[0] < t < grid[-1]]
        starts = sorted({grid[0], grid[-1], *inside})
        assert list(pieces.starts) == starts[:-1]
        assert list(pieces.u0) == [signal.after(a) for a in starts[:-1]]
        rates = [(signal.before(b) - signal.after(a)) / float(b - a) for a, b in itertools.pairwise(starts)]
        assert list(pieces.rate) == rates
        assert list(pieces.points) == list(with_events(grid, times, step))
        at = _times(rng, list(grid), step)
        at = at[(at >= float(grid[0])) & (at <= float(grid[-1]))]
        expected = [signal.after(signal.latest_event_near(exact_time(t), step)) for t in at.tolist()]
        assert pieces.values_after(at).tolist() == expected
