"""schedule_windows: a run a window of grid steps at a time, joined bit for bit into schedule()'s."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from pendulum_fmu._errors import InvalidInput
from pendulum_fmu.signals import _time_grid
from pendulum_fmu.signals._torque_csv import TorqueFileError
from pendulum_fmu.signals._torque_schedule import schedule, schedule_windows


def joined(windows):
    """The windows' arrays end to end, each later window less its first point (the boundary)."""
    windows = list(windows)
    for before, after in itertools.pairwise(windows):
        assert before.time[-1] == after.time[0]
    time = np.concatenate([windows[0].time] + [w.time[1:] for w in windows[1:]])
    return windows, time, np.concatenate([w.torque for w in windows]), np.concatenate([w.torque_rate for w in windows])


def assert_same(torque, window_steps, **kwargs):
    whole = schedule(torque, **kwargs)
    windows, time, values, rates = joined(schedule_windows(torque, window_steps=window_steps, **kwargs))
    assert np.array_equal(time, whole.time)
    assert np.array_equal(values, whole.torque)
    assert np.array_equal(rates, whole.torque_rate)
    return windows


def write(path, rows):
    path.write_text("time,torque\n" + "".join(f"{t!r},{u!r}\n" for t, u in rows))
    return path


@pytest.mark.parametrize("window_steps", [1, 7, 64, 1000, 10**6])
@pytest.mark.parametrize("ramp", [False, True])
def test_callable_and_constant(window_steps, ramp):
    assert_same(lambda t: np.sin(7 * t) + t, window_steps, stop_time=0.4567, step_size=1e-3, ramp=ramp)
    assert_same(20.0, window_steps, start_time=1.25, stop_time=1.7, step_size=3e-4, ramp=ramp)


def test_windows_split_the_grid_steps():
    """Window j is grid steps j*W to min((j+1)W, N): 10 steps in 3s are 3, 3, 3, 1."""
    windows = list(schedule_windows(1.0, stop_time=0.01, window_steps=3))
    assert [len(w.torque) for w in windows] == [3, 3, 3, 1]
    assert windows[-1].time[-1] == 0.01


def test_callable_sampled_once_a_point():
    seen = []

    def torque(t):
        seen.append(t)
        return 2.0 * t

    assert len(list(schedule_windows(torque, stop_time=0.05, window_steps=7, ramp=True))) == 8
    assert len(seen) == 51 and len(set(seen)) == 51


def test_array(tmp_path):
    values = np.random.default_rng(3).normal(size=1001)
    assert_same(values, 17, step_size=1e-3)
    assert_same(values.tolist(), 1, start_time=2.0, step_size=1e-3)


@pytest.mark.parametrize("window_steps", [1, 3, 50, 1 << 17])
def test_csv_jumps_on_and_off_the_grid(tmp_path, window_steps):
    # 0.027 on a 9 ms grid is a grid point (3 * 0.009 = 0.026999999999999996); 0.0301 is not.
    table = write(
        tmp_path / "torque.csv",
        [(0.0, 1.0), (0.027, 1.0), (0.027, 31.0), (0.0301, 31.0), (0.0301, -5.0), (0.2, 4.0), (0.2, 0.5), (0.5, 2.0)],
    )
    for ramp in (False, True):
        windows = assert_same(table, window_steps, step_size=0.009, ramp=ramp)
        assert_same(table, window_steps, start_time=0.004, stop_time=0.4441, step_size=0.009, ramp=ramp)
        if window_steps == 3:  # the jump off the grid is a point of the window that holds it
            assert any(0.0301 in w.time[1:-1] for w in windows)


@pytest.mark.parametrize("seed", range(12))
def test_random_csvs(tmp_path, seed):
    rng = np.random.default_rng(seed)
    rows = int(rng.integers(2, 60))
    times = np.sort(rng.uniform(-0.05, 1.0, rows)).round(int(rng.integers(2, 5)))
    times = np.sort(np.concatenate([times, times[rng.integers(0, rows, 4)]]))
    kept = [t for i, t in enumerate(times.tolist()) if i < 2 or not t == times[i - 1] == times[i - 2]]
    if seed % 3 == 0:  # times a tool wrote as running sums
        kept = np.cumsum(np.full(len(kept), 0.007)).tolist()
    table = write(tmp_path / "torque.csv", zip(kept, rng.normal(0, 10, len(kept)).tolist(), strict=False))
    step = float(rng.choice([1e-3, 3e-4, 7e-4, 9e-3, 0.03, 1 / 3000]))
    start = float(rng.choice([0.0, -0.01, 0.0123]))
    stop = float(max(kept) + 0.0537) if seed % 2 else None
    for ramp in (False, True):
        kwargs = {"start_time": start, "stop_time": stop, "step_size": step, "ramp": ramp}
        if stop is None and max(kept) <= start:
            continue
        for window_steps in (1, 7, int(rng.integers(2, 500))):
            assert_same(table, window_steps, **kwargs)


def test_checks_at_the_call(tmp_path):
    """Each refusal of schedule() is made at the call, in its words, before any window."""
    bad = write(tmp_path / "bad.csv", [(0.0, 1.0), (0.5, 2.0)])
    bad.write_text("time,torque\n0,1\n1,x\n")
    cases = [
        ((20.0,), {"stop_time": 1e10, "step_size": 1e-3}),
        ((20.0,), {"step_size": -1.0}),
        (([1.0, 2.0],), {"ramp": True}),
        (([1.0, 2.0],), {"stop_time": 5.0}),
        ((object(),), {}),
        ((float("inf"),), {}),
        ((lambda: 1.0,), {}),
        ((str(bad),), {}),
    ]
    for args, kwargs in cases:
        with pytest.raises((InvalidInput, TorqueFileError)) as whole:
            schedule(*args, **kwargs)
        with pytest.raises(type(whole.value)) as windowed:
            schedule_windows(*args, **kwargs)  # not iterated: the call itself refuses
        assert str(windowed.value) == str(whole.value)


def test_a_sample_is_refused_in_its_window():
    windows = schedule_windows(lambda t: 1.0 if t < 0.01 else float("nan"), stop_time=0.02, window_steps=4)
    assert len(next(windows).torque) == 4
    with pytest.raises(InvalidInput) as windowed:
        list(windows)
    with pytest.raises(InvalidInput) as whole:
        schedule(lambda t: 1.0 if t < 0.01 else float("nan"), stop_time=0.02)
    assert str(windowed.value) == str(whole.value)


def test_no_memory_check_but_max_steps(monkeypatch):
    """The whole run's memory is no window's: a run too big to hold is walked; max_steps holds."""
    monkeypatch.setattr(_time_grid, "_available_memory", lambda: 2**20)
    with pytest.raises(InvalidInput, match="GiB free"):
        schedule(20.0, stop_time=2000.0)
    first = next(schedule_windows(20.0, stop_time=2000.0, window_steps=10))
    assert np.array_equal(first.time, 1e-3 * np.arange(11))
    with pytest.raises(InvalidInput, match="over the limit of 1,000"):
        schedule_windows(20.0, stop_time=2000.0, max_steps=1000)
    with pytest.raises(InvalidInput, match="window steps 0"):
        schedule_windows(20.0, window_steps=0)


def test_memory_does_not_grow_with_the_run():
    """3,000,000 steps of a constant, walked: a window's arrays, never the run's (72 MB)."""
    import tracemalloc

    tracemalloc.start()
    try:
        steps = sum(len(w.torque) for w in schedule_windows(20.0, stop_time=3000.0, window_steps=1 << 16))
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert steps == 3_000_000
    assert peak < 8 * 2**20
