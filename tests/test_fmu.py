"""The FMU driven by fmpy, against analytic solutions and the reference."""

import ctypes
import subprocess
import zipfile

import numpy as np
import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

from pendulum_fmu.fmu._instance import FmuError, open_fmu
from pendulum_fmu.fmu._parameters import default_parameters, total_inertia
from pendulum_fmu.fmu._simulate import run_schedule, simulate
from pendulum_fmu.oracle._reference import reference
from pendulum_fmu.signals._torque_schedule import schedule

I_TOTAL = 20.0 + 40.0 * 0.5**2  # the tutorial's pendulum about its pivot
THETA, OMEGA, ALPHA, TORQUE = 1, 2, 3, 0


def test_fmpy_validation_finds_nothing(fmu):
    assert validate_fmu(str(fmu)) == []


def test_every_variable_has_unit_and_description(fmu):
    description = read_model_description(str(fmu))
    for variable in description.modelVariables:
        assert variable.description, variable.name
        # callRecordFile, a file name, is the one String and has no unit.
        assert variable.unit or variable.type == "String", variable.name
    experiment = description.defaultExperiment
    assert (float(experiment.startTime), float(experiment.stopTime), float(experiment.stepSize)) == (0, 3, 1e-3)
    assert {u.name for u in description.unitDefinitions} >= {
        "rad",
        "rad/s",
        "rad/s2",
        "N.m",
        "kg",
        "m",
        "kg.m2",
        "m/s2",
    }


def test_archive_holds_binary_sources_and_documentation(fmu, tmp_path):
    description = read_model_description(str(fmu))
    listed = description.buildConfigurations[0].sourceFileSets[0].sourceFiles
    with zipfile.ZipFile(fmu) as archive:
        names = set(archive.namelist())
        archive.extract("binaries/linux64/Pendulum.so", tmp_path)
    assert "documentation/index.html" in names
    assert {f"sources/{name}" for name in listed} <= names
    symbols = subprocess.run(
        ["nm", "-D", "--defined-only", str(tmp_path / "binaries/linux64/Pendulum.so")],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split()
    exported = [s for s in symbols if s.startswith(("fmi", "_")) or (s.isidentifier() and len(s) > 1)]
    names_exported = {s for s in exported if not set(s) <= set("0123456789abcdef")}
    assert names_exported and all(name.startswith("fmi2") for name in names_exported), names_exported


def test_gravity_off_is_the_exact_parabola(fmu):
    result = simulate(20.0, stop_time=3.0, step_size=1e-3, parameters={"gravity": 0}, fmu_path=fmu)
    t = result["time"]
    assert len(t) == 3001
    assert np.max(np.abs(result["theta"] - 0.5 * 20.0 / I_TOTAL * t**2)) < 1e-12
    assert np.max(np.abs(result["omega"] - 20.0 / I_TOTAL * t)) < 1e-12
    assert np.max(np.abs(result["alpha"] - 20.0 / I_TOTAL)) < 1e-14


def test_gravity_on_matches_the_reference(fmu):
    result = simulate(20.0, fmu_path=fmu)
    expected = reference(20.0)
    assert np.max(np.abs(result["theta"] - expected["theta"])) < 1e-10
    assert np.max(np.abs(result["omega"] - expected["omega"])) < 1e-10
    assert np.max(np.abs(result["alpha"] - expected["alpha"])) < 1e-9


def test_stepwise_torque_with_variable_steps(fmu, tmp_path):
    # Steps of 1, 2.5 and 7 ms, and torque jumps that fall between the regular points.
    csv = tmp_path / "torque.csv"
    csv.write_text("time,torque\n0,20\n0.4,20\n0.4,-15\n1.2345,-15\n1.2345,40\n2,40\n2,0\n3,0\n")
    for step_size in (1e-3, 2.5e-3, 7e-3):
        result = simulate(csv, step_size=step_size, fmu_path=fmu)
        expected = reference(csv, step_size=step_size)
        assert 1.2345 in result["time"]
        assert np.max(np.abs(result["theta"] - expected["theta"])) < 1e-10
        assert np.max(np.abs(result["omega"] - expected["omega"])) < 1e-10


def test_torque_held_per_step_from_a_callable(fmu):
    def signal(t):
        return 30 * np.sin(4 * t)

    result = simulate(signal, step_size=0.01, fmu_path=fmu)
    expected = reference(signal, step_size=0.01)
    assert np.array_equal(result["torque"][:-1], 30 * np.sin(4 * result["time"][:-1]))
    assert np.max(np.abs(result["theta"] - expected["theta"])) < 1e-10


def test_ramped_torque_is_the_exact_cubic(fmu):
    # Gravity off, torque ramping u(t) = 5 + 10 t: theta = (5 t^2 / 2 + 10 t^3 / 6) / I_total.
    result = simulate(lambda t: 5 + 10 * t, step_size=0.05, ramp=True, parameters={"gravity": 0}, fmu_path=fmu)
    t = result["time"]
    assert np.max(np.abs(result["theta"] - (2.5 * t**2 + 10 * t**3 / 6) / I_TOTAL)) < 1e-12
    assert np.max(np.abs(result["torque"] - (5 + 10 * t))) < 1e-12


def test_ramped_torque_with_gravity_matches_the_reference(fmu):
    # 20 ms steps at the default 1e-10 drift by ~3e-13 a step; ask for what the test checks.
    def signal(t):
        return 40 * np.cos(3 * t)

    result = simulate(signal, step_size=0.02, ramp=True, tolerance=1e-12, fmu_path=fmu)
    expected = reference(signal, step_size=0.02, ramp=True)
    assert np.max(np.abs(result["theta"] - expected["theta"])) < 1e-10


def test_start_values(fmu):
    result = simulate(20.0, theta0=0.3, omega0=-1.5, parameters={"gravity": 0}, fmu_path=fmu)
    t = result["time"]
    assert np.max(np.abs(result["theta"] - (0.3 - 1.5 * t + 0.5 * 20 / I_TOTAL * t**2))) < 1e-12
    with_gravity = simulate(20.0, theta0=2.0, omega0=1.0, fmu_path=fmu)
    expected = reference(20.0, theta0=2.0, omega0=1.0)
    assert np.max(np.abs(with_gravity["theta"] - expected["theta"])) < 1e-10


def test_changed_parameters(fmu):
    parameters = {"mass": 3.0, "length": 1.2, "inertia": 0.1, "gravity": 1.62}
    result = simulate(2.0, parameters=parameters, fmu_path=fmu)
    expected = reference(2.0, parameters=parameters)
    assert np.max(np.abs(result["theta"] - expected["theta"])) < 1e-10
    assert abs(result["alpha"][0] - 2.0 / (0.1 + 3.0 * 1.2**2)) < 1e-14


def test_damping_against_the_analytic_solution(fmu):
    # Gravity off: omega = (u/c)(1 - exp(-c t/I)), theta = (u/c)(t - (I/c)(1 - exp(-c t/I))).
    c, u = 12.0, 20.0
    result = simulate(u, parameters={"gravity": 0, "damping": c}, fmu_path=fmu)
    t = result["time"]
    decay = 1 - np.exp(-c * t / I_TOTAL)
    assert np.max(np.abs(result["omega"] - u / c * decay)) < 1e-10
    assert np.max(np.abs(result["theta"] - u / c * (t - I_TOTAL / c * decay))) < 1e-10
    with_gravity = simulate(u, parameters={"damping": c}, fmu_path=fmu)
    assert np.max(np.abs(with_gravity["theta"] - reference(u, parameters={"damping": c})["theta"])) < 1e-10


def test_setup_experiment_tolerance_is_used(fmu):
    expected = reference(60.0, step_size=0.1)
    loose = simulate(60.0, step_size=0.1, tolerance=1e-4, fmu_path=fmu)
    tight = simulate(60.0, step_size=0.1, tolerance=1e-12, fmu_path=fmu)
    loose_error = np.max(np.abs(loose["theta"] - expected["theta"]))
    tight_error = np.max(np.abs(tight["theta"] - expected["theta"]))
    assert tight_error < 1e-10 < loose_error < 1e-3


def test_a_step_the_taylor_method_gives_up_on_is_taken_by_dopri5(fmu):
    # Spinning at 1e30 rad/s, sin(theta) turns some 1e26 times in the step: its Taylor series converges
    # only over steps far below the 1e-12 of the step the Taylor method allows itself, so it gives
    # up; DOPRI5 takes the step, as omega's change (at most 6.5e-3 rad/s) is far below rounding.
    slave = open_fmu(fmu, omega0=1e30)
    slave.doStep(0.0, 1e-3)
    assert slave.getReal([THETA, OMEGA]) == [1e30 * 1e-3, 1e30]  # theta = omega*t, rounded
    slave.terminate()
    slave.freeInstance()


def _stepper(fmu, **kwargs):
    slave = open_fmu(fmu, **kwargs)

    def run(t0, n, h=1e-3, torque=20.0):
        out = []
        for k in range(n):
            slave.setReal([TORQUE], [torque])
            slave.doStep(t0 + k * h, h)
            out.append(slave.getReal([THETA, OMEGA, ALPHA]))
        return np.array(out)

    return slave, run


def test_rollback_restores_results_bit_for_bit(fmu):
    slave, run = _stepper(fmu)
    run(0.0, 1000)
    state = slave.getFMUstate()
    first = run(1.0, 1000, torque=-35.0)
    slave.setFMUstate(state)
    second = run(1.0, 1000, torque=-35.0)
    assert np.array_equal(first, second)
    slave.freeFMUstate(state)
    slave.terminate()
    slave.freeInstance()


def test_serialized_state_restores_in_another_instance(fmu):
    a, run_a = _stepper(fmu, instance_name="a")
    run_a(0.0, 1500)
    blob = a.serializeFMUstate(a.getFMUstate())
    b, run_b = _stepper(fmu, instance_name="b", parameters={"mass": 1.0})
    b.setFMUstate(b.deSerializeFMUstate(blob))
    assert np.array_equal(run_a(1.5, 500), run_b(1.5, 500))
    for slave in (a, b):
        slave.terminate()
        slave.freeInstance()


def test_two_instances_are_independent(fmu):
    _a, run_a = _stepper(fmu, instance_name="a")
    _b, run_b = _stepper(fmu, instance_name="b", parameters={"damping": 3.0})
    interleaved_a, interleaved_b = [], []
    for k in range(3000):
        interleaved_a.append(run_a(k * 1e-3, 1, torque=20.0)[0])
        interleaved_b.append(run_b(k * 1e-3, 1, torque=-50.0)[0])
    _, alone_a = _stepper(fmu, instance_name="a alone")
    _, alone_b = _stepper(fmu, instance_name="b alone", parameters={"damping": 3.0})
    assert np.array_equal(
        np.array(interleaved_a), np.array([alone_a(k * 1e-3, 1, torque=20.0)[0] for k in range(3000)])
    )
    assert np.array_equal(
        np.array(interleaved_b), np.array([alone_b(k * 1e-3, 1, torque=-50.0)[0] for k in range(3000)])
    )
    assert not np.array_equal(np.array(interleaved_a), np.array(interleaved_b))


def test_reset_starts_over(fmu):
    slave, run = _stepper(fmu)
    first = run(0.0, 500)
    slave.reset()
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    assert np.array_equal(run(0.0, 500), first)


def test_output_derivatives(fmu):
    slave = open_fmu(fmu, theta0=0.7, omega0=-0.4)
    slave.setReal([TORQUE], [15.0])
    slave.setRealInputDerivatives([TORQUE], [1], [4.0])
    slave.doStep(0.0, 0.1)
    theta, omega, alpha = slave.getReal([THETA, OMEGA, ALPHA])
    first = slave.getRealOutputDerivatives([THETA, OMEGA, ALPHA], [1, 1, 1])
    second = slave.getRealOutputDerivatives([THETA, OMEGA, ALPHA], [2, 2, 2])
    p = default_parameters()
    mgl = p["mass"] * p["gravity"] * p["length"]
    jerk = (4.0 - mgl * np.cos(theta) * omega) / I_TOTAL
    snap = mgl * (np.sin(theta) * omega**2 - np.cos(theta) * alpha) / I_TOTAL
    assert np.allclose(first, [omega, alpha, jerk], rtol=1e-14, atol=0)
    assert np.allclose(second, [alpha, jerk, snap], rtol=1e-14, atol=0)


def test_directional_derivative_of_alpha_by_torque(fmu):
    slave = open_fmu(fmu, parameters={"mass": 2.0, "length": 1.5, "inertia": 0.5})
    slave.doStep(0.0, 0.01)
    (d_alpha,) = slave.getDirectionalDerivative([ALPHA], [TORQUE], [1.0])
    assert d_alpha == pytest.approx(1.0 / total_inertia({"mass": 2.0, "length": 1.5, "inertia": 0.5}), rel=1e-15)


def test_invalid_parameters_are_refused_at_initialization(fmu):
    with pytest.raises(FmuError, match="mass must be > 0"):
        open_fmu(fmu, parameters={"mass": 0.0})


def test_run_schedule_reports_fmu_errors(fmu):
    slave = open_fmu(fmu)
    plan = schedule(20.0, stop_time=0.01, step_size=1e-3)
    plan.torque[3] = np.nan
    with pytest.raises(FmuError, match="torque = nan refused"):
        run_schedule(slave, plan)
    assert ctypes  # ctypes is used through fmpy's loaded library
