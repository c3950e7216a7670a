"""The reference's estimate of its work (pendulum_fmu/oracle/_work.py), against the steps the
integrator actually takes, the bound on |omega| against the trajectories, and the run it refuses.
"""

import contextlib
import math
import sys
import time

import numpy as np
import pytest

from pendulum_fmu import InvalidInput, reference
from pendulum_fmu.oracle import _reference, _taylor_native, _work
from pendulum_fmu.oracle._reference import model_constants
from pendulum_fmu.oracle._work import MAX_STEPS, Spans, speed_bound

# How far from the steps taken the estimate may be, as a factor: below and above.
ESTIMATE_WITHIN = (0.5, 4.0)
DEFAULTS = {"mass": 40.0, "length": 0.5, "inertia": 20.0, "gravity": 9.81, "damping": 0.0}

# (what, reference()'s arguments): the README's quick start and the tests' usual runs, swings,
# spins, damping, ramps, a torque changing each step, gravity off, other tolerances.
CASES = {
    "the README's quick start": ((20.0,), {"stop_time": 1.0}),
    "20 N.m for 1,000 s, held in its well": ((20.0,), {"stop_time": 1000.0, "step_size": 1.0}),
    "a swing from theta0 = 3": ((0.0,), {"stop_time": 100.0, "step_size": 1.0, "theta0": 3.0}),
    "a spin at 300 N.m": ((300.0,), {"stop_time": 30.0, "step_size": 1.0}),
    "over the barrier at 190 N.m": ((190.0,), {"stop_time": 30.0, "step_size": 1.0}),
    "300 N.m against damping 10": ((300.0,), {"stop_time": 100.0, "step_size": 1.0, "parameters": {"damping": 10}}),
    "omega0 = 100 rad/s": ((0.0,), {"stop_time": 10.0, "step_size": 1.0, "omega0": 100.0}),
    "gravity 0, a parabola": ((20.0,), {"stop_time": 100.0, "step_size": 1.0, "parameters": {"gravity": 0}}),
    "gravity -9.81": ((20.0,), {"stop_time": 100.0, "step_size": 1.0, "parameters": {"gravity": -9.81}}),
    "rtol = atol = 1e-8": ((20.0,), {"stop_time": 100.0, "step_size": 1.0, "rtol": 1e-8, "atol": 1e-8}),
    "a ramp to 300 N.m": ((lambda t: 30 * t,), {"stop_time": 10.0, "step_size": 0.1, "ramp": True}),
    "a pulse, then free": ((lambda t: 300.0 if t < 1 else 0.0,), {"stop_time": 100.0, "step_size": 0.5}),
    "a torque changing every step": ((lambda t: 20 * math.sin(t),), {"stop_time": 3.0}),
}


def steps_taken(monkeypatch, arguments, keywords) -> tuple[float, int, np.ndarray]:
    """(the estimate, the integrator's steps, the run) of reference(*arguments, **keywords)."""
    seen = {}

    @contextlib.contextmanager
    def counting(steps, start, stop):
        seen["estimate"], seen["taken"] = steps, 0

        def count(t):
            seen["taken"] += 1

        yield count

    monkeypatch.setattr(_reference, "progress", counting)
    # The Python integrator hears every Taylor step; the native one, which takes the same steps
    # to the bit (tests/test_taylor_native.py), a chunk of runs at a time.
    monkeypatch.setattr(_taylor_native, "available", lambda: False)
    run = reference(*arguments, **keywords)
    return seen["estimate"], seen["taken"], run


@pytest.mark.parametrize("case", CASES)
def test_the_estimate_is_the_steps_taken_within_a_factor(monkeypatch, case):
    estimate, taken, _ = steps_taken(monkeypatch, *CASES[case])
    # Measured 0.67 (theta0 = 3, near the top: the swing's harmonics) to 2.6 (the ramp: the
    # largest torque taken from the start) at the time of writing.
    assert ESTIMATE_WITHIN[0] * taken <= estimate <= ESTIMATE_WITHIN[1] * taken, (estimate, taken)


@pytest.mark.parametrize("case", CASES)
def test_omega_stays_under_its_bound(case):
    arguments, keywords = CASES[case]
    run = reference(*arguments, at=None, **keywords)
    parameters = {**DEFAULTS, **keywords.get("parameters", {})}
    model = model_constants(parameters)
    # The run's own torque as held (or ramped) spans, as the reference integrates it.
    times, torque = run["time"], run["torque"]
    rate = np.diff(torque) / np.diff(times) if keywords.get("ramp") else np.zeros(len(times) - 1)
    spans = Spans(times[:-1], times[1:], torque[:-1], rate)
    bound, _ = speed_bound(spans, model, keywords.get("theta0", 0.0), keywords.get("omega0", 0.0))
    assert (np.abs(run["omega"][1:]) <= bound(times[1:]) * (1 + 1e-9)).all()


def test_a_held_torque_in_its_well_keeps_a_bound_that_does_not_grow():
    # 20 N.m against m g L = 196.2 N.m: from rest the pendulum swings between 0 and 2 asin(0.1),
    # however long; its top speed sqrt(2 (E - E_bottom) / I) with E - u theta conserved.
    model = model_constants(DEFAULTS)
    spans = Spans(np.array([0.0]), np.array([1e6]), np.array([20.0]), np.array([0.0]))
    bound, _ = speed_bound(spans, model, 0.0, 0.0)
    bottom = math.asin(20 / 196.2)
    depth = 20 * bottom - 196.2 * (1 - math.cos(bottom))
    assert bound(np.array([1.0, 1e6])) == pytest.approx([math.sqrt(2 * depth / 30)] * 2, rel=1e-12)
    assert abs(reference(20.0, stop_time=30.0)["omega"]).max() == pytest.approx(math.sqrt(2 * depth / 30), rel=1e-3)


def test_a_run_of_billions_of_steps_is_refused_before_it_starts():
    started = time.process_time()
    with pytest.raises(InvalidInput) as refused:
        reference(20.0, stop_time=1e10, step_size=1e9)
    assert str(refused.value).startswith("the reference would take about 40,")
    assert f"over its limit of {MAX_STEPS:,}: give a shorter stop time" in str(refused.value)
    assert time.process_time() - started < 10  # refused, not integrated for hours


def test_a_run_allowed_more_steps_may_take_as_many_taylor_steps_more(monkeypatch):
    # A recorded torque changes at every step, and the series restarts at each: an overnight
    # run allowed 30,000,000 steps (--max-steps) takes as many Taylor steps at least.
    monkeypatch.setattr(_work, "MAX_STEPS", 1000)
    torque = 20 * np.sin(np.arange(2000) / 50.0)
    with pytest.raises(InvalidInput, match="over its limit of 1,000: give a shorter stop time"):
        reference(torque)
    allowed = reference(torque, max_steps=2000)
    assert np.array_equal(allowed["theta"], reference(torque, max_steps=10**6)["theta"])


def test_a_long_run_shows_its_progress_and_a_short_one_does_not(monkeypatch, capsys):
    monkeypatch.setattr(_work, "BAR_FROM", 1000)  # the 300-N.m spin for 30 s takes about 2,200
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)  # the bar a terminal shows
    reference(300.0, stop_time=30.0, step_size=1.0)
    bar = capsys.readouterr().err
    assert bar.startswith("\rreference [") and bar.rstrip().endswith("] 30/30 s"), bar
    reference(20.0, stop_time=1.0)  # about 5 steps: no bar
    assert capsys.readouterr().err == ""
