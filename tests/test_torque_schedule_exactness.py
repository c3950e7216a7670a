"""A user's torque signal reaches the FMU as written, judged by the independent oracle
(reference.reference reads the CSV itself and shares no code with torque_schedule.schedule).

The cases are the ones that went wrong: jumps at plain decimal times whose grid point is an ulp
below them, running-sum times, kinks between communication points under --ramp, per-step arrays,
and randomized signals over step sizes that include the awkward ones.
"""

import numpy as np
import pytest

from benchmarks.signal_cases import random_step_rows, write_rows
from pendulum_fmu.comparing._compare import compare
from pendulum_fmu.fmu._simulate import simulate
from pendulum_fmu.oracle._reference import reference
from pendulum_fmu.signals._torque_schedule import ScheduleWindows

# 0.0003, 0.0006, 0.0007, 0.0009, 0.009, 0.03 and 0.3 are doubles below their decimals, so k*h
# falls an ulp below a jump written at a multiple of them; 1/3 ms is no decimal at all.
AWKWARD_STEPS = (3e-4, 6e-4, 7e-4, 9e-4, 1e-3, 9e-3, 0.03, 0.3, 1 / 3000)
BOUND = 1e-9


def worst(run, oracle):
    assert np.allclose(run["time"], oracle["time"], rtol=0, atol=1e-12)
    return max(np.max(np.abs(run["theta"] - oracle["theta"])), np.max(np.abs(run["omega"] - oracle["omega"])))


def check(fmu, signal, **arguments):
    run = simulate(signal, fmu_path=fmu, tolerance=1e-12, **arguments)
    oracle = reference(signal, **arguments)
    assert worst(run, oracle) < BOUND
    # The torque the FMU received at each step's start is the signal's value just after it, to
    # rounding (a steep ramp turns an ulp of time into more than an ulp of torque).
    scale = 1 + np.max(np.abs(oracle["torque"]))
    assert np.max(np.abs(run["torque"][:-1] - oracle["torque"][:-1])) < 1e-10 * scale
    return run, oracle


def test_jump_at_a_grid_point_an_ulp_above_k_h(fmu, tmp_path):
    # 3 * 0.009 = 0.026999999999999996 < 0.027: the repro, 3.5e-3 rad off before.
    csv = write_rows(tmp_path / "j.csv", [(0, 10), (0.027, 10), (0.027, -20), (2, -20)])
    run, _ = check(fmu, csv, step_size=0.009)
    k = np.flatnonzero(np.isclose(run["time"], 0.027, rtol=0, atol=1e-15))
    assert len(k) == 1 and run["torque"][k[0]] == -20 and run["torque"][k[0] - 1] == 10


def test_jumps_at_decimal_times_on_a_30_ms_grid(fmu, tmp_path):
    csv = write_rows(tmp_path / "j.csv", [(0, 5), (0.33, 5), (0.33, -30), (0.45, -30), (0.45, 25), (1.5, 25)])
    check(fmu, csv, step_size=0.03)


def test_first_row_jump(fmu, tmp_path):
    csv = write_rows(tmp_path / "j.csv", [(0, 0), (0, 20), (1, 20)])
    run, _ = check(fmu, csv, step_size=1e-3)
    assert run["torque"][0] == 20


@pytest.mark.parametrize("step_size", AWKWARD_STEPS)
def test_jumps_at_every_multiple_of_an_awkward_step(fmu, tmp_path, step_size):
    # A jump at each of several decimal multiples of the step, written as decimals.
    decimals = len(repr(step_size).split(".")[-1]) if step_size != 1 / 3000 else 6
    times = sorted({round(k * step_size, decimals) for k in (3, 7, 11, 25, 40)})
    rows, level = [(0.0, 10.0)], 10.0
    for t in times:
        rows += [(t, level), (t, -level)]
        level = -level
    rows.append((times[-1] + 5 * step_size, level))
    check(fmu, write_rows(tmp_path / "j.csv", rows), step_size=step_size)


@pytest.mark.parametrize("seed", range(4))
def test_random_step_signal_with_running_sum_times(fmu, tmp_path, seed):
    rows = random_step_rows(np.random.default_rng(seed), running_sum=True)
    assert any(len(str(t)) > 8 for t, _ in rows)  # the running sums are not round decimals
    check(fmu, write_rows(tmp_path / "r.csv", rows), step_size=1e-3)


@pytest.mark.parametrize("seed", range(6))
def test_random_step_signal_at_random_awkward_steps(fmu, tmp_path, seed):
    rng = np.random.default_rng(100 + seed)
    step_size = AWKWARD_STEPS[rng.integers(len(AWKWARD_STEPS))]
    rows = random_step_rows(rng, stop_time=2.0)
    check(fmu, write_rows(tmp_path / "r.csv", rows), step_size=step_size)


@pytest.mark.parametrize("step_size", [0.01, 0.1])
def test_ramp_follows_kinks_between_communication_points(fmu, tmp_path, step_size):
    # The kink at 0.3915 s lies inside a step at both sizes: before, 1.7e-5 and 1.0e-3 rad.
    csv = write_rows(tmp_path / "k.csv", [(0, 0), (0.3915, 20), (1, -5), (1.2345, 12), (2, 10)])
    run, _ = check(fmu, csv, step_size=step_size, ramp=True)
    assert 0.3915 in run["time"] and 1.2345 in run["time"]


@pytest.mark.parametrize("seed", range(3))
def test_random_piecewise_linear_signal_ramped(fmu, tmp_path, seed):
    rng = np.random.default_rng(200 + seed)
    times = np.unique(np.round(np.sort(rng.uniform(0, 2, size=25)), 4))
    rows = [(0, 0.0)] + [(repr(float(t)), rng.uniform(-30, 30)) for t in times] + [(2.5, 5.0)]
    step_size = AWKWARD_STEPS[rng.integers(len(AWKWARD_STEPS) - 1)]
    check(fmu, write_rows(tmp_path / "p.csv", rows), step_size=step_size, ramp=True)


def test_a_per_step_array_is_held(fmu):
    values = np.linspace(-10, 10, 2000)
    run, _ = check(fmu, values, step_size=1e-3)
    assert run["time"][-1] == pytest.approx(2.0) and np.array_equal(run["torque"][:-1], values)
    listed, _ = check(fmu, [5.0, -5.0, 7.5], step_size=0.1)
    assert np.array_equal(listed["torque"], [5.0, -5.0, 7.5, 7.5])


def test_a_per_step_array_of_the_wrong_length_says_so(fmu):
    with pytest.raises(ValueError, match=r"has 3 values but 0 to 1 s in steps of 0\.1 s is 10 steps"):
        simulate([1.0, 2.0, 3.0], step_size=0.1, stop_time=1.0, fmu_path=fmu)
    with pytest.raises(ValueError, match="one value per step"):
        simulate(np.ones((2, 2)), fmu_path=fmu)
    with pytest.raises(ValueError, match="must be finite"):
        simulate([1.0, float("nan")], fmu_path=fmu)


def test_constant_and_callable_signals(fmu):
    check(fmu, 20.0, stop_time=1.0, step_size=9e-3)
    check(fmu, lambda t: 30 * np.sin(4 * t), stop_time=1.0, step_size=7e-3)
    check(fmu, lambda t: 30 * np.sin(4 * t), stop_time=1.0, step_size=0.03, ramp=True)


def test_compare_catches_a_schedule_that_does_not_carry_the_signal(tmp_path, monkeypatch):
    # The old schedule read the value at a grid point an ulp below the jump: the pre-jump value.
    csv = write_rows(tmp_path / "j.csv", [(0, 10), (0.027, 10), (0.027, -20), (0.5, -20)])

    made = ScheduleWindows.__next__

    def late_by_one_step(windows):
        # compare walks the schedule's windows (one here): each carries its first jump a step late.
        plan = made(windows)
        jumps = np.flatnonzero(np.diff(plan.torque))
        if len(jumps):
            plan.torque[jumps[0] + 1] = plan.torque[jumps[0]]
        return plan

    monkeypatch.setattr(ScheduleWindows, "__next__", late_by_one_step)
    comparison = compare(csv, ["fmu", "reference"], output_dir=tmp_path / "out", step_size=0.009)
    assert not comparison.agree
    assert comparison.worst > 1e-5
    assert comparison.torque_worst == 30.0


def test_compare_agrees_on_the_awkward_cases(fmu, tmp_path):
    csv = write_rows(tmp_path / "j.csv", [(0, 10), (0.027, 10), (0.027, -20), (0.5, -20)])
    comparison = compare(csv, ["fmu", "reference"], output_dir=tmp_path / "held", step_size=0.009, fmu_path=fmu)
    assert comparison.agree and comparison.torque_worst < 1e-12
    kinks = write_rows(tmp_path / "k.csv", [(0, 0), (0.3915, 20), (1, -5)])
    ramped = compare(kinks, ["fmu", "reference"], output_dir=tmp_path / "ramp", step_size=0.1, ramp=True, fmu_path=fmu)
    assert ramped.agree and ramped.worst < BOUND


def test_compare_ramp_refuses_a_tool_that_cannot_ramp(tmp_path):
    pytest.importorskip("opensim")
    kinks = write_rows(tmp_path / "k.csv", [(0, 0), (0.3915, 20), (1, -5)])
    with pytest.raises(ValueError, match="opensim holds the torque over each step and cannot ramp"):
        compare(kinks, ["fmu", "opensim"], output_dir=tmp_path, ramp=True)
