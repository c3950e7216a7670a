"""The FMI 3.0 FMU, built from the same sources as the FMI 2.0 one, driven by fmpy's FMU3Slave and
FMU3Model: same numbers as FMI 2.0, its own model description, states, Jacobians, Model Exchange.
"""

import ctypes
import subprocess
import sys
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Model
from fmpy.fmi3 import FMU3Model
from fmpy.validation import validate_fmu

from fmu_build import MODEL_DESCRIPTION
from pendulum_fmu.cli import main
from pendulum_fmu.fmu._instance import open_fmu
from pendulum_fmu.fmu._parameters import default_parameters, total_inertia
from pendulum_fmu.fmu._simulate import run_schedule, simulate
from pendulum_fmu.oracle._reference import reference, reference_schedule
from pendulum_fmu.signals._torque_schedule import TorqueSchedule, schedule

TORQUE, THETA, OMEGA, ALPHA, MASS, DAMPING = 0, 1, 2, 3, 4, 8
TIME = 10  # the independent variable's value reference in the FMI 3.0 description
P = default_parameters()
I_TOTAL = total_inertia(P)
GRAVITY_MOMENT = P["mass"] * P["gravity"] * P["length"]


def test_fmpy_validation_finds_nothing(fmu3):
    assert validate_fmu(str(fmu3)) == []


def test_description_is_the_fmi2_one_in_fmi3_terms(fmu, fmu3):
    fmi2, fmi3 = read_model_description(str(fmu)), read_model_description(str(fmu3))
    assert fmi3.fmiVersion == "3.0" and fmi3.instantiationToken == fmi2.guid
    variables = {v.name: v for v in fmi3.modelVariables}
    assert (variables["time"].causality, variables["time"].valueReference, variables["time"].unit) == (
        "independent",
        TIME,
        "s",
    )
    for old in fmi2.modelVariables:
        new = variables[old.name]
        assert (new.type, new.valueReference, new.causality, new.variability, new.unit, new.start) == (
            {"Real": "Float64"}.get(old.type, old.type),
            old.valueReference,
            old.causality,
            old.variability,
            old.unit,
            old.start,
        )
    assert variables["omega"].derivative is variables["theta"]
    assert variables["alpha"].derivative is variables["omega"]
    assert [u.variable.name for u in fmi3.outputs] == ["theta", "omega", "alpha"]
    assert [u.variable.name for u in fmi3.derivatives] == ["omega", "alpha"]
    assert {d.name for d in fmi3.derivatives[1].dependencies} == {"torque", "theta", "omega"}
    assert [u.variable.name for u in fmi3.initialUnknowns] == ["alpha"]
    root = ET.fromstring(zipfile.ZipFile(fmu3).read("modelDescription.xml"))
    for interface in ("CoSimulation", "ModelExchange"):
        flags = root.find(interface).attrib
        for flag in (
            "canGetAndSetFMUState",
            "canSerializeFMUState",
            "providesDirectionalDerivatives",
            "providesAdjointDerivatives",
        ):
            assert flags[flag] == "true", (interface, flag)
    flags = root.find("CoSimulation").attrib
    assert (
        flags["maxOutputDerivativeOrder"],
        flags["canHandleVariableCommunicationStepSize"],
        flags["hasEventMode"],
    ) == ("2", "true", "false")


def _exported(binary):
    symbols = subprocess.run(
        ["nm", "-D", "--defined-only", str(binary)], capture_output=True, text=True, check=True
    ).stdout.split()
    return {s for s in symbols if s.startswith("fmi")}, symbols


def test_archive_holds_fmi3_binary_and_build_description(fmu3, tmp_path):
    with zipfile.ZipFile(fmu3) as archive:
        names = set(archive.namelist())
        archive.extractall(tmp_path)
    build = ET.parse(tmp_path / "sources/buildDescription.xml").getroot()
    listed = [f.get("name") for f in build.iter("SourceFile")]
    assert "fmi3_functions.c" in listed and "fmi2_functions.c" not in listed
    assert {f"sources/{name}" for name in listed} <= names
    assert not any(name.startswith("binaries/linux64") for name in names)
    exported, symbols = _exported(tmp_path / "binaries/x86_64-linux/Pendulum.so")
    assert {"fmi3DoStep", "fmi3InstantiateModelExchange", "fmi3GetAdjointDerivative"} <= exported
    assert all(name.startswith("fmi3") for name in exported)
    assert not [s for s in symbols if s.startswith(("instance_", "model_", "dopri5"))]


@pytest.mark.build
def test_build_command_writes_the_fmi3_fmu(tmp_path, capsys):
    assert main(["build", "--fmi-version", "3", "--output", str(tmp_path / "P3.fmu")]) == 0
    assert read_model_description(str(tmp_path / "P3.fmu")).fmiVersion == "3.0"
    assert (
        subprocess.run(
            [sys.executable, "build_fmu.py", "--fmi-version", "3", "--output", str(tmp_path / "B3.fmu")],
            cwd=MODEL_DESCRIPTION.parent,
        ).returncode
        == 0
    )
    assert read_model_description(str(tmp_path / "B3.fmu")).fmiVersion == "3.0"


@pytest.mark.parametrize("gravity", [0.0, 9.81])
def test_co_simulation_gives_exactly_the_fmi2_numbers(fmu, fmu3, gravity):
    """The seed's case (3 s of 1 ms steps) and a step-wise torque, held at the same points."""
    for torque in (20.0, lambda t: 20.0 if t < 1.0 else (-10.0 if t < 2.0 else 35.0)):
        ours = simulate(torque, stop_time=3.0, parameters={"gravity": gravity}, fmu_path=fmu3)
        theirs = simulate(torque, stop_time=3.0, parameters={"gravity": gravity}, fmu_path=fmu)
        assert np.array_equal(ours, theirs)
    assert (
        np.max(np.abs(ours["theta"] - reference(torque, stop_time=3.0, parameters={"gravity": gravity})["theta"]))
        < 1e-10
    )


def test_variable_steps_match_fmi2_and_the_reference(fmu, fmu3):
    steps = np.tile([1e-3, 7e-3, 0.05, 2.5e-4, 0.1], 12)
    time = np.concatenate([[0.0], np.cumsum(steps)])
    plan = TorqueSchedule(time=time, torque=30.0 * np.sin(3.0 * time[:-1]), torque_rate=np.zeros(len(steps)))
    runs = {}
    for path in (fmu, fmu3):
        slave = open_fmu(path)
        try:
            runs[path] = run_schedule(slave, plan)
        finally:
            slave.terminate()
            slave.freeInstance()
    assert np.array_equal(runs[fmu], runs[fmu3])
    assert np.max(np.abs(runs[fmu3]["theta"] - reference_schedule(plan)["theta"])) < 1e-9


def test_ramp_is_refused_with_one_line(fmu3):
    with pytest.raises(ValueError, match=r"FMI 3\.0 has no input derivatives"):
        simulate(lambda t: 10 * t, stop_time=0.1, ramp=True, fmu_path=fmu3)


def test_fmu_state_get_set_and_serialize(fmu3):
    slave = open_fmu(fmu3, theta0=0.3)
    try:
        slave.setFloat64([TORQUE], [15.0])
        slave.doStep(0.0, 0.25)
        state = slave.getFMUState()
        blob = slave.serializeFMUState(state)
        slave.doStep(0.25, 0.5)
        first = slave.getFloat64([THETA, OMEGA, ALPHA, TIME])
        slave.setFMUState(state)
        assert slave.getFloat64([TIME]) == [0.25]
        slave.doStep(0.25, 0.5)
        assert slave.getFloat64([THETA, OMEGA, ALPHA, TIME]) == first
        slave.freeFMUState(state)
        other = open_fmu(fmu3, instance_name="other")
        try:
            other.setFMUState(other.deserializeFMUState(blob))
            other.doStep(0.25, 0.5)
            assert other.getFloat64([THETA, OMEGA, ALPHA, TIME]) == first
        finally:
            other.terminate()
            other.freeInstance()
    finally:
        slave.terminate()
        slave.freeInstance()


def test_output_derivatives_follow_the_equation(fmu3):
    slave = open_fmu(fmu3, parameters={"damping": 2.0}, theta0=0.4, omega0=-0.3)
    try:
        slave.setFloat64([TORQUE], [12.0])
        slave.doStep(0.0, 0.05)
        theta, omega, alpha = slave.getFloat64([THETA, OMEGA, ALPHA])
        derivatives = slave.getOutputDerivatives([THETA, THETA, OMEGA, OMEGA], [1, 2, 1, 2])
    finally:
        slave.terminate()
        slave.freeInstance()
    # alpha = (u - m g L sin(theta) - c omega) / I; held u, so d alpha/dt = (-m g L cos(theta) omega - c alpha) / I.
    jerk = (-GRAVITY_MOMENT * np.cos(theta) * omega - 2.0 * alpha) / I_TOTAL
    assert np.allclose(derivatives, [omega, alpha, alpha, jerk], rtol=1e-14, atol=0)


def _model(fmu_path, version, tmp_path):
    description = read_model_description(str(fmu_path))
    kind = FMU3Model if version == 3 else FMU2Model
    model = kind(
        guid=description.guid,
        unzipDirectory=extract(str(fmu_path), unzipdir=tmp_path),
        modelIdentifier="Pendulum",
        instanceName="jacobian",
    )
    model.instantiate()
    if version == 3:
        model.enterInitializationMode()
        model.set, model.derivatives = model.setFloat64, model.getContinuousStateDerivatives
        update = model.updateDiscreteStates
    else:
        model.setupExperiment(startTime=0.0)
        model.enterInitializationMode()
        model.set, model.derivatives = model.setReal, model.getDerivatives
        update = model.newDiscreteStates
    model.set([DAMPING], [1.5])
    model.exitInitializationMode()
    update()
    model.enterContinuousTimeMode()
    return model


@pytest.mark.parametrize("version", [2, 3])
def test_directional_derivatives_match_finite_differences(fmu, fmu3, tmp_path, version):
    model = _model(fmu3 if version == 3 else fmu, version, tmp_path)
    point = {THETA: 0.7, OMEGA: -0.4, TORQUE: 9.0}
    unknowns, knowns = [OMEGA, ALPHA], [THETA, OMEGA, TORQUE]

    def f(values):
        """The state derivatives (der(theta) = omega, der(omega) = alpha) at values."""
        states = (ctypes.c_double * 2)(values[THETA], values[OMEGA])
        model.setContinuousStates(states, 2)
        model.set([TORQUE], [values[TORQUE]])
        derivatives = (ctypes.c_double * 2)()
        model.derivatives(derivatives, 2)
        return np.array(derivatives)

    h = 1e-6
    finite = np.array([(f({**point, k: point[k] + h}) - f({**point, k: point[k] - h})) / (2 * h) for k in knowns]).T
    f(point)
    analytic = np.array([model.getDirectionalDerivative(unknowns, knowns, list(seed)) for seed in np.eye(3)]).T
    assert np.allclose(analytic, finite, rtol=1e-8, atol=1e-9)
    # A seed that mixes all knowns gives J @ seed.
    seed = np.array([0.3, -1.2, 2.5])
    assert np.allclose(
        model.getDirectionalDerivative(unknowns, knowns, list(seed)), analytic @ seed, rtol=1e-15, atol=1e-15
    )
    if version == 3:
        for weights in np.eye(2):
            adjoint = model.getAdjointDerivative(unknowns, knowns, list(weights), nSensitivity=3)
            assert np.allclose(adjoint, weights @ analytic, rtol=1e-15, atol=1e-15)
    model.terminate()
    model.freeInstance()


@pytest.mark.parametrize("gravity", [0.0, 9.81])
def test_model_exchange_cvode_at_default_tolerance_within_1e6_of_the_reference(fmu3, gravity):
    torque = np.array([(0.0, 20.0), (3.0, 20.0)], dtype=[("time", "f8"), ("torque", "f8")])
    result = simulate_fmu(
        str(fmu3),
        fmi_type="ModelExchange",
        stop_time=3.0,
        output_interval=1e-3,
        start_values={"gravity": gravity},
        input=torque,
        output=["theta"],
    )
    expected = reference(20.0, stop_time=3.0, parameters={"gravity": gravity})
    assert np.allclose(result["time"], expected["time"], rtol=0, atol=1e-12)
    assert np.max(np.abs(result["theta"] - expected["theta"])) < 1e-6


def test_fmpy_validate_on_the_command_line(fmu3):
    """Fmpy simulate on the command line: tests/test_fmu.py runs it on both FMUs."""
    validated = subprocess.run([sys.executable, "-m", "fmpy", "validate", str(fmu3)], capture_output=True, text=True)
    assert validated.returncode == 0, validated.stdout + validated.stderr
    assert "No problems found" in validated.stdout, validated.stdout


def test_compare_and_sweep_take_the_fmi3_fmu(fmu, fmu3, tmp_path):
    import pyarrow.parquet as pq

    from pendulum_fmu.comparing._compare import run_tools
    from pendulum_fmu.sweep import Study, run_sweep

    plan = schedule(lambda t: 20.0 if t < 0.5 else -5.0, stop_time=1.0)
    runs = run_tools(plan, ("fmu", "reference"), fmu_path=fmu3)
    assert np.array_equal(runs["fmu"], run_tools(plan, ("fmu",), fmu_path=fmu)["fmu"])
    assert np.max(np.abs(runs["fmu"]["theta"] - runs["reference"]["theta"])) < 1e-10
    cases = [{"torque": 10.0, "gravity": 0.0}, {"torque": 40.0, "gravity": 9.81}]
    tables = [
        pq.read_table(
            run_sweep(
                Study(cases, stop_time=1.0, fmu_path=path), output_dir=tmp_path / name, workers=1, progress=False
            ).trajectories
        ).sort_by("case")
        for name, path in (("fmi3", fmu3), ("fmi2", fmu))
    ]
    assert tables[0].equals(tables[1]) and tables[0].num_rows == 2 * 1001
