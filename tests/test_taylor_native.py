"""The oracle's native Taylor stepping (pendulum_fmu/oracle/_taylor_native.c) against the Python
integrator it transcribes (_taylor.integrate_piece), bit for bit: run by run over random windows,
and through reference() and judge() with the native stepping on and off; its failures in the
Python integrator's words.
"""

import numpy as np
import pytest

from pendulum_fmu import reference
from pendulum_fmu._errors import InvalidInput
from pendulum_fmu.judging._judge import judge
from pendulum_fmu.oracle import _taylor_native
from pendulum_fmu.oracle._taylor import Diverged, integrate_piece

GRAVITY_MOMENT, INVERSE_INERTIA = 196.2, 1.0 / 30.0


def test_the_native_stepping_is_built():
    assert _taylor_native.available(), "build it: pip install -e ."


def _python_runs(runs, bounds, reports, state, model, tolerance):
    """integrate_piece run by run, as integrate_window's fallback calls it."""
    theta, omega = state
    thetas, omegas = [], []
    for r, (t0, t1, u0, rate) in enumerate(zip(*(column.tolist() for column in runs), strict=True)):
        clipped = np.clip(reports[bounds[r] : bounds[r + 1]], t0, t1)
        x, v, theta, omega = integrate_piece(theta, omega, (t0, t1), (u0, rate), model, tolerance, clipped)
        thetas.append(x)
        omegas.append(v)
    return np.concatenate([np.empty(0), *thetas]), np.concatenate([np.empty(0), *omegas]), theta, omega


def _assert_same(runs, bounds, reports, state, model, tolerance):
    native = _taylor_native.integrate_runs(runs, bounds, reports, state, model, tolerance)
    python = _python_runs(runs, bounds, reports, state, model, tolerance)
    assert np.array_equal(native[0], python[0]) and np.array_equal(native[1], python[1])
    assert native[2:] == python[2:]


def _window(rng, runs, lengths, reports_per_second, rates):
    """Random runs of the given lengths and their reports, a rounding past the window's ends too."""
    spans = rng.choice(lengths, size=runs) * rng.uniform(0.5, 1.5, size=runs)
    ends = np.cumsum(spans)
    starts = np.r_[0.0, ends[:-1]]
    u0s = rng.normal(0.0, 40.0, runs)
    ramps = rng.normal(0.0, 60.0, runs) * (rng.random(runs) < 0.5) if rates else np.zeros(runs)
    count = rng.poisson(reports_per_second * ends[-1])
    reports = np.sort(rng.uniform(-1e-12, ends[-1] + 1e-12, count))
    bounds = np.searchsorted(reports, ends, side="right")
    bounds[-1] = count
    return (starts, ends, u0s, ramps), np.r_[0, bounds], reports


@pytest.mark.parametrize("seed", range(40))
def test_random_windows_are_integrate_pieces_numbers_bit_for_bit(seed):
    rng = np.random.default_rng(seed)
    lengths = [0.0, 1e-3, 1e-3, 0.05, 0.7, 3.0]
    runs, bounds, reports = _window(rng, int(rng.integers(1, 50)), lengths, rng.choice([0.5, 20, 2000]), seed % 2)
    model = (rng.uniform(0.0, 300.0), rng.choice([0.0, rng.uniform(0.0, 5.0)]), rng.uniform(0.01, 2.0))
    tolerance = (10 ** rng.uniform(-16, -6), 10 ** rng.uniform(-16, -6))
    state = (rng.normal(0.0, 3.0), rng.normal(0.0, 10.0))
    _assert_same(runs, bounds, reports, state, model, tolerance)


@pytest.mark.parametrize("tolerance", [1e-6, 1e-10, 1e-14, 1e-16])
@pytest.mark.parametrize("state", [(0.0, 0.0), (-0.0, 1e-300), (3.1, 0.0), (1e4, -300.0), (-2e3, 45.0)])
def test_large_and_small_swings_at_every_tolerance(state, tolerance):
    # Large angles reach sin's and cos's argument reduction; a long run takes many steps.
    rng = np.random.default_rng(7)
    runs, bounds, reports = _window(rng, 6, [1e-3, 2.0, 10.0], 30, rates=True)
    _assert_same(runs, bounds, reports, state, (GRAVITY_MOMENT, 0.7, INVERSE_INERTIA), (tolerance, tolerance))


@pytest.mark.parametrize("count", [0, 1, 8, 9, 200, 20000])
def test_few_and_many_reports_in_a_step(count):
    # Up to 8 reports in a step are Horner sums, more numpy's polyval: both, summed alike.
    runs = (np.array([0.0, 0.4, 0.4]), np.array([0.4, 0.4, 1.5]), np.array([5.0, 9.0, -3.0]), np.array([0.0, 2.0, 7.0]))
    reports = np.sort(np.r_[np.linspace(0.0, 1.5, count), [0.4, 0.4, 1.5]])
    bounds = np.r_[0, np.searchsorted(reports, runs[1], side="right")]
    bounds[-1] = len(reports)
    _assert_same(runs, bounds, reports, (0.3, -1.0), (GRAVITY_MOMENT, 0.0, INVERSE_INERTIA), (1e-14, 1e-14))


def test_a_run_of_zero_length_reports_its_start():
    runs = (np.array([0.25]), np.array([0.25]), np.array([3.0]), np.array([1.0]))
    thetas, omegas, theta, omega = _taylor_native.integrate_runs(
        runs, np.array([0, 2]), np.array([0.25, 0.25]), (0.5, 2.0), (GRAVITY_MOMENT, 0.0, 1.0), (1e-14, 1e-14)
    )
    assert thetas.tolist() == [0.5, 0.5] and omegas.tolist() == [2.0, 2.0] and (theta, omega) == (0.5, 2.0)


def test_the_progress_bar_hears_each_calls_steps(monkeypatch):
    # Seven runs of one step each, three steps a call: the time reached after the third, the
    # sixth and the last.
    monkeypatch.setattr(_taylor_native, "STEPS_PER_CALL", 3)
    ends = np.arange(1, 8) * 1e-3
    runs = (ends - 1e-3, ends, np.ones(7), np.zeros(7))
    reached = []
    _taylor_native.integrate_runs(
        runs, np.zeros(8, int), np.empty(0), (0.0, 0.0), (1.0, 0.0, 1.0), (1e-14, 1e-14), reached.append
    )
    assert reached == [ends[2], ends[5], ends[6]]


@pytest.mark.parametrize("steps_per_call", [1, 2, 7])
def test_a_run_taken_up_again_after_a_pause_gives_the_same_bits(monkeypatch, steps_per_call):
    # One long run of a held torque with reports inside its steps: paused every few Taylor steps,
    # it is integrate_piece's run straight through.
    runs = (np.array([0.0]), np.array([3.0]), np.array([20.0]), np.array([0.0]))
    reports = np.linspace(0.0, 3.0, 301)
    model, tolerance = (GRAVITY_MOMENT, 0.5, INVERSE_INERTIA), (1e-14, 1e-14)
    expected = integrate_piece(0.3, -0.2, (0.0, 3.0), (20.0, 0.0), model, tolerance, reports)
    reached = []
    monkeypatch.setattr(_taylor_native, "STEPS_PER_CALL", steps_per_call)
    got = _taylor_native.integrate_runs(
        runs, np.array([0, 301]), reports, (0.3, -0.2), model, tolerance, reached.append
    )
    assert np.array_equal(got[0], expected[0]) and np.array_equal(got[1], expected[1])
    assert got[2:] == expected[2:]
    assert len(reached) > 1 and reached == sorted(reached) and reached[-1] == 3.0


@pytest.mark.parametrize(
    ("model", "state", "span", "message"),
    [
        ((1e308, 0.0, 1e308), (1.0, 0.0), (0.0, 1.0), "a Taylor coefficient is not finite"),
        ((GRAVITY_MOMENT, 0.0, INVERSE_INERTIA), (1.0, 0.0), (1e17, 2e17), "the step needed underflows at t = 1e+17 s"),
    ],
)
def test_failures_are_the_python_integrators(model, state, span, message):
    # A run of no length first: the failure is the second run's, named by its start.
    runs = (np.array([span[0], span[0]]), np.array([span[0], span[1]]), np.zeros(2), np.zeros(2))
    with pytest.raises(Diverged) as python:
        _python_runs(runs, np.zeros(3, int), np.empty(0), state, model, (1e-14, 1e-14))
    with pytest.raises(_taylor_native.RunDiverged) as native:
        _taylor_native.integrate_runs(runs, np.zeros(3, int), np.empty(0), state, model, (1e-14, 1e-14))
    assert str(native.value) == str(python.value) and str(native.value).startswith(message)
    assert native.value.start == span[0]


def _both(monkeypatch, call):
    """call() with the native stepping, then with the Python integrator."""
    native = call()
    monkeypatch.setattr(_taylor_native, "available", lambda: False)
    python = call()
    monkeypatch.undo()
    return native, python


@pytest.mark.parametrize(
    ("torque", "options"),
    [
        (20.0, {"stop_time": 30.0}),
        (lambda t: 20 * np.sin(2 * np.pi * 0.5 * t), {"stop_time": 3.0}),
        (lambda t: 50 * np.sign(np.sin(7 * t)), {"stop_time": 2.0, "ramp": True, "parameters": {"damping": 1.5}}),
        (np.random.default_rng(3).normal(0, 30, 1000), {"theta0": 2.0, "omega0": -4.0, "rtol": 1e-9, "atol": 1e-12}),
    ],
)
def test_reference_is_the_same_with_and_without_the_native_stepping(monkeypatch, torque, options):
    at = None if "ramp" not in options else np.sort(np.random.default_rng(4).uniform(0, 2.0, 5000))
    native, python = _both(monkeypatch, lambda: reference(torque, at=at, **options))
    for name in native.dtype.names:
        assert np.array_equal(native[name], python[name]), name


def test_the_failure_is_worded_alike_with_and_without_the_native_stepping(monkeypatch):
    def failing():
        with pytest.raises(InvalidInput, match="a Taylor coefficient is not finite") as error:
            reference(20.0, stop_time=0.01, parameters={"mass": 1e308})
        return str(error.value)

    native, python = _both(monkeypatch, failing)
    assert native == python


def test_judge_is_the_same_with_and_without_the_native_stepping(monkeypatch, tmp_path):
    from pendulum_fmu import simulate

    t = np.arange(2001) * 1e-3
    signal = tmp_path / "torque.csv"
    np.savetxt(signal, np.c_[t, 20 * np.sin(2 * np.pi * 0.5 * t)], delimiter=",", header="time,torque", comments="")
    result = simulate(str(signal), stop_time=2.0)
    native, python = _both(monkeypatch, lambda: judge(result, str(signal), stop_time=2.0))
    assert (native.verdict, native.diagnosis, native.residual, native.max_abs_dtheta, native.worst_time) == (
        python.verdict,
        python.diagnosis,
        python.residual,
        python.max_abs_dtheta,
        python.worst_time,
    )
    assert native.candidates == python.candidates
    for name in native.drawn.dtype.names:
        assert np.array_equal(native.drawn[name], python.drawn[name], equal_nan=True)
