"""The native co-simulation loop against the Python loop, bit for bit, and against the reference; its
failures and its restarts.
"""

from importlib import import_module

import numpy as np
import pytest

from pendulum_fmu.fmu import _native_loop as cs_loop
from pendulum_fmu.fmu._instance import FmuError, open_fmu
from pendulum_fmu.fmu._parameters import value_reference
from pendulum_fmu.oracle._reference import reference_schedule
from pendulum_fmu.signals._torque_csv import TorqueTable
from pendulum_fmu.signals._torque_schedule import schedule
from pendulum_fmu.sweep import OUTPUTS

# The module; the package's attribute of that name is its function.
simulate = import_module("pendulum_fmu.fmu._simulate")


def test_the_native_loop_is_built():
    assert cs_loop.available(), "build it: pip install -e ."


@pytest.mark.parametrize("ramp", [False, True])
def test_native_loop_matches_the_python_loop_bit_for_bit(fmu, ramp):
    # Uneven steps: a jump at 0.2505 s becomes a communication point between two 1 ms steps.
    table = TorqueTable(time=np.array([0.0, 0.2505, 0.2505, 0.6]), torque=np.array([5.0, 30.0, -8.0, 12.0]))
    plan = schedule(table, step_size=1e-3, ramp=ramp)
    assert len(set(np.round(np.diff(plan.time), 12))) > 1
    runs = []
    for loop in (simulate.run_schedule, simulate.run_schedule_python):
        slave = open_fmu(fmu, parameters={"damping": 1.5}, theta0=0.2)
        try:
            runs.append(loop(slave, plan))
        finally:
            slave.terminate()
            slave.freeInstance()
    native, python = runs
    for name in native.dtype.names:
        assert np.array_equal(native[name], python[name]), name
    # And both are the physics: the oracle of the same schedule.
    oracle = reference_schedule(plan, theta0=0.2, parameters={"damping": 1.5})
    assert np.max(np.abs(native["theta"] - oracle["theta"])) < 1e-9


def test_native_loop_reports_the_failing_step(fmu):
    slave = open_fmu(fmu)
    try:
        plan = schedule(1.0, stop_time=0.01, step_size=1e-3)
        wrong = plan.time + 0.5  # fmi2DoStep refuses a step from where the instance is not
        with pytest.raises(FmuError, match=r"fmi2DoStep at t = 0.5 returned ERROR: .*not where"):
            stepper = cs_loop.Stepper(slave, np.array([0], np.uint32), np.array([1, 2, 3], np.uint32))
            stepper.run(wrong, plan.torque[:, None].copy(), None, np.empty((len(wrong), 3)))
    finally:
        slave.freeInstance()


def test_native_restart_matches_a_fresh_instance_bit_for_bit(fmu):
    """A restart in C (fmi2Reset, initialization with new start values, the torque among them)
    gives what a new instance initialized in Python and fed the torque every step gives.
    """
    plan = schedule(12.0, stop_time=0.2, step_size=1e-3)
    names = ("mass", "damping", "theta", "torque")
    references = np.array([value_reference(n, fmu) for n in names], np.uint32)
    outputs = np.array([value_reference(n, fmu) for n in OUTPUTS], np.uint32)
    slave = open_fmu(fmu)  # initialized with the defaults, then restarted twice
    try:
        stepper = cs_loop.Stepper(slave, np.empty(0, np.uint32), outputs, references)
        for mass in (30.0, 55.0):
            restarted = np.empty((len(plan.time), 3))
            stepper.run(plan.time, None, None, restarted, start_values=np.array([mass, 2.0, 0.4, 12.0]))
            fresh = open_fmu(fmu, parameters={"mass": mass, "damping": 2.0}, theta0=0.4)
            try:
                expected = simulate.run_schedule_python(fresh, plan)
            finally:
                fresh.freeInstance()
            for column, name in enumerate(OUTPUTS):
                assert np.array_equal(restarted[:, column], expected[name]), (mass, name)
        with pytest.raises(FmuError, match=r"initialization failed: .*mass must be > 0"):
            stepper.run(plan.time, None, None, restarted, start_values=np.array([-1.0, 0.0, 0.0, 0.0]))
    finally:
        slave.freeInstance()


def test_a_chunk_in_one_call_matches_case_by_case_and_the_physics_bit_for_bit(fmu):
    """run_cases (a chunk's cases in one call, as a sweep worker runs them) gives, for every case,
    what a restart per call and a fresh instance in Python give, bit for bit; a case the FMU
    refuses in the middle gets its own message and a NaN row, and the cases after it are still
    right (each restart begins with fmi2Reset).
    """
    names = ("mass", "damping", "theta", "torque")
    cases = np.array([[30.0, 2.0, 0.4, 12.0], [-1.0, 0.0, 0.0, 0.0], [55.0, 0.5, -0.2, 7.0], [1.0, 0.0, 0.1, -3.0]])
    references = np.array([value_reference(n, fmu) for n in names], np.uint32)
    outputs = np.array([value_reference(n, fmu) for n in OUTPUTS], np.uint32)
    points = schedule(0.0, stop_time=0.2, step_size=1e-3).time
    slave = open_fmu(fmu)
    try:
        stepper = cs_loop.Stepper(slave, np.empty(0, np.uint32), outputs, references)
        chunk = np.empty((3, len(cases), len(points)))
        messages = stepper.run_cases(points, cases, chunk)
        chunk = chunk.transpose(1, 2, 0)  # (cases, points, outputs), as run() writes a case
        assert messages[0] == messages[2] == messages[3] == ""
        assert messages[1].startswith("initialization failed: ") and "mass must be > 0" in messages[1]
        assert np.isnan(chunk[1]).all()
        with pytest.raises(FmuError) as refused:
            stepper.run(points, None, None, np.empty((len(points), 3)), start_values=cases[1])
        assert messages[1] == str(refused.value)
        for case in (0, 2, 3):
            one_call = np.empty((len(points), 3))
            stepper.run(points, None, None, one_call, start_values=cases[case])
            assert np.array_equal(chunk[case], one_call), case
            mass, damping, theta0, torque = cases[case]
            parameters = {"mass": mass, "damping": damping}
            plan = schedule(torque, stop_time=0.2, step_size=1e-3)
            fresh = open_fmu(fmu, parameters=parameters, theta0=theta0)
            try:
                expected = simulate.run_schedule_python(fresh, plan)
            finally:
                fresh.freeInstance()
            for column, name in enumerate(OUTPUTS):
                assert np.array_equal(chunk[case, :, column], expected[name]), (case, name)
            oracle = reference_schedule(plan, theta0=theta0, parameters=parameters)
            assert np.max(np.abs(chunk[case, :, 0] - oracle["theta"])) < 1e-9, case
    finally:
        slave.freeInstance()
