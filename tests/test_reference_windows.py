"""reference_windows: the oracle a window of grid steps at a time, against reference() whole."""

from __future__ import annotations

import contextlib
import math
import time
import tracemalloc

import numpy as np
import pytest

from pendulum_fmu import InvalidInput
from pendulum_fmu.oracle import _reference, _taylor_native
from pendulum_fmu.oracle._reference import reference, reference_schedule, reference_windows
from pendulum_fmu.signals._torque_schedule import schedule, schedule_windows


def walked(torque, window_steps, **kwargs):
    """The windows' results at each window's schedule points (less the shared boundary), joined."""
    parts = []
    with reference_windows(torque, window_steps=window_steps, **kwargs) as oracle:
        windows = list(schedule_windows(torque, window_steps=window_steps, **kwargs))
        assert oracle.windows == len(windows)
        for j, window in enumerate(windows):
            parts.append(oracle.next(window.time)[0 if j == 0 else 1 :])
        with pytest.raises(InvalidInput, match="no window left"):
            oracle.next(np.array([]))
    return np.concatenate(parts)


def assert_close(torque, window_steps=7, **kwargs):
    joined = walked(torque, window_steps, **kwargs)
    whole = reference(torque, at=joined["time"], **kwargs)
    assert np.array_equal(joined["time"], schedule(torque, **kwargs).time)
    # The series restarts at each window's end: equal to rounding, not bit for bit.
    assert np.abs(joined["theta"] - whole["theta"]).max() < 1e-13
    assert np.abs(joined["omega"] - whole["omega"]).max() < 1e-12
    assert np.array_equal(joined["torque"], whole["torque"])
    assert np.abs(joined["alpha"] - whole["alpha"]).max() < 1e-11


def write(path, rows):
    path.write_text("time,torque\n" + "".join(f"{t!r},{u!r}\n" for t, u in rows))
    return path


def test_constant():
    assert_close(20.0, stop_time=0.5)
    assert_close(150.0, 64, start_time=0.25, stop_time=1.2345, step_size=1e-3)


def test_callable():
    assert_close(lambda t: 20 * math.sin(5 * t), 7, stop_time=0.3)
    assert_close(lambda t: 40 * t, 5, stop_time=0.2, ramp=True)


def test_csv_with_jumps_off_the_grid(tmp_path):
    table = write(
        tmp_path / "torque.csv",
        [(0.0, 1.0), (0.027, 1.0), (0.027, 31.0), (0.0301, 31.0), (0.0301, -5.0), (0.2, 4.0), (0.2, 0.5), (0.5, 2.0)],
    )
    assert_close(table, 3, step_size=0.009)
    assert_close(table, 2, step_size=0.009, ramp=True)
    assert_close(table, 5, start_time=0.004, stop_time=0.4441, step_size=0.009)


def test_reports_anywhere_in_the_window_and_none():
    """Reports off the grid, and a window with none, leave the carried state as it is."""
    with reference_windows(20.0, stop_time=1.0, window_steps=100) as oracle:
        first = oracle.next(np.array([0.0123, 0.05]))
        assert len(oracle.next(np.array([]))) == 0
        middle = oracle.next(np.array([0.25]))
        for _ in range(oracle.windows - 4):
            assert len(oracle.next(np.array([]))) == 0
        last = oracle.next(np.array([0.999, 1.0]))
    whole = reference(20.0, stop_time=1.0, at=np.array([0.0123, 0.05, 0.25, 0.999, 1.0]))
    got = np.concatenate([first, middle, last[-2:]])
    assert np.abs(got["theta"] - whole["theta"]).max() < 1e-13
    with reference_windows(20.0, stop_time=1.0, window_steps=100) as oracle, pytest.raises(InvalidInput) as outside:
        oracle.next(np.array([0.2]))
    assert str(outside.value) == "at: 0.2 is no time of window 0 of the run, 0 to 0.1 s"


def test_a_huge_run_is_refused_at_the_call(monkeypatch):
    """As tests/test_work.py's: refused in reference()'s words, nothing integrated."""
    integrated = []
    monkeypatch.setattr(_reference, "integrate_window", lambda *a: integrated.append(a))
    started = time.process_time()
    with pytest.raises(InvalidInput) as whole:
        reference(20.0, stop_time=1e10, step_size=1e9)
    with pytest.raises(InvalidInput) as windowed:
        reference_windows(20.0, stop_time=1e10, step_size=1e9, window_steps=3)
    assert str(windowed.value) == str(whole.value)
    assert str(windowed.value).startswith("the reference would take about 40,")
    assert not integrated and time.process_time() - started < 10


def test_the_checks_of_reference_at_the_call(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("time,torque\n0,1\n1,x\n")
    for args, kwargs in [
        ((object(),), {}),
        (([1.0],), {"ramp": True}),
        ((str(bad),), {}),
        ((20.0,), {"step_size": float("nan")}),
        ((20.0,), {"rtol": 0.0}),
        ((20.0,), {"theta0": float("inf")}),
        ((20.0,), {"stop_time": 1e5}),
    ]:
        with pytest.raises(InvalidInput) as whole:
            reference(*args, **kwargs)
        with pytest.raises(InvalidInput) as windowed:
            reference_windows(*args, **kwargs)
        assert str(windowed.value) == str(whole.value)


def test_the_progress_bar_spans_the_windows(monkeypatch):
    seen = []

    @contextlib.contextmanager
    def counting(steps, start, stop):
        seen.append((steps, start, stop))
        yield lambda t: seen.append(t)

    monkeypatch.setattr(_reference, "progress", counting)
    # Every Taylor step, as the Python integrator reports them (the native one: a chunk of runs).
    monkeypatch.setattr(_taylor_native, "available", lambda: False)
    with reference_windows(300.0, stop_time=30.0, step_size=1.0, window_steps=4) as oracle:
        for j in range(oracle.windows):
            oracle.next(np.array([4.0 * j]))
    (steps, start, stop), reached = seen[0], seen[1:]
    assert (start, stop) == (0.0, 30.0) and reached[-1] == 30.0 and reached == sorted(reached)
    # The estimate of the walk is the steps taken within the factor tests/test_work.py allows.
    assert 0.5 * len(reached) <= steps <= 4 * len(reached)
    seen.clear()
    reference_schedule(schedule(300.0, stop_time=30.0, step_size=1.0), show_progress=False)
    assert seen == []


@pytest.mark.slow
def test_memory_does_not_grow_with_the_run():
    """3,000,000 steps of a constant, walked with reports at every grid point: tens of MB at most,
    where reference() whole holds the run's reports (120 MB) and its grid.
    """
    tracemalloc.start()
    try:
        with reference_windows(20.0, stop_time=3000.0, max_steps=3_000_000) as oracle:
            for window in schedule_windows(20.0, stop_time=3000.0, max_steps=3_000_000):
                end = oracle.next(window.time)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert end["time"][-1] == 3000.0 and np.isfinite(end["theta"][-1])
    assert peak < 40 * 2**20, peak
