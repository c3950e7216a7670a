"""The same FMU through its Model Exchange interface."""

import ctypes

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Model

from pendulum_fmu.fmu._parameters import default_parameters, total_inertia
from pendulum_fmu.fmu._simulate import simulate

THETA, OMEGA, ALPHA, TORQUE, DAMPING = 1, 2, 3, 0, 8


def _states(*values):
    return (ctypes.c_double * len(values))(*values)


@pytest.mark.parametrize("gravity", [0.0, 9.81])
def test_cvode_agrees_with_co_simulation(fmu, gravity):
    torque = np.array([(0.0, 20.0), (3.0, 20.0)], dtype=[("time", "f8"), ("torque", "f8")])
    me = simulate_fmu(
        str(fmu),
        fmi_type="ModelExchange",
        solver="CVode",
        relative_tolerance=1e-10,
        stop_time=3.0,
        output_interval=1e-3,
        start_values={"gravity": gravity},
        input=torque,
        output=["theta", "omega"],
    )
    cs = simulate(20.0, parameters={"gravity": gravity}, fmu_path=fmu)
    assert np.allclose(me["time"], cs["time"], rtol=0, atol=1e-12)
    assert np.max(np.abs(me["theta"] - cs["theta"])) < 1e-8


@pytest.fixture
def model(fmu, tmp_path):
    description = read_model_description(str(fmu))
    model = FMU2Model(
        guid=description.guid,
        unzipDirectory=extract(str(fmu), unzipdir=tmp_path),
        modelIdentifier="Pendulum",
        instanceName="me",
    )
    model.instantiate()
    model.setupExperiment(startTime=0.0)
    model.enterInitializationMode()
    model.setReal([DAMPING], [1.5])
    model.exitInitializationMode()
    model.newDiscreteStates()
    model.enterContinuousTimeMode()
    yield model
    model.terminate()
    model.freeInstance()


def test_state_jacobian_from_directional_derivatives(model):
    model.setReal([TORQUE], [7.0])
    model.setContinuousStates(_states(0.3, -0.2), 2)
    # Derivatives are omega (der theta) and alpha (der omega); states theta, omega.
    columns = [model.getDirectionalDerivative([OMEGA, ALPHA], [known], [1.0]) for known in (THETA, OMEGA)]
    jacobian = np.array(columns).T
    p = {**default_parameters(), "damping": 1.5}
    inertia = total_inertia(p)
    expected = [[0.0, 1.0], [-p["mass"] * p["gravity"] * p["length"] * np.cos(0.3) / inertia, -1.5 / inertia]]
    assert np.allclose(jacobian, expected, rtol=1e-14, atol=0)
    (d_alpha_d_torque,) = model.getDirectionalDerivative([ALPHA], [TORQUE], [1.0])
    assert d_alpha_d_torque == pytest.approx(1 / inertia, rel=1e-15)


def test_derivatives_follow_the_equation(model):
    model.setReal([TORQUE], [12.0])
    model.setContinuousStates(_states(1.1, 0.4), 2)
    derivatives = _states(0.0, 0.0)
    model.getDerivatives(derivatives, 2)
    p = {**default_parameters(), "damping": 1.5}
    alpha = (12.0 - p["mass"] * p["gravity"] * p["length"] * np.sin(1.1) - 1.5 * 0.4) / total_inertia(p)
    assert np.allclose(list(derivatives), [0.4, alpha], rtol=1e-15, atol=0)
    assert model.getReal([ALPHA])[0] == pytest.approx(alpha, rel=1e-15)


def test_state_get_set_and_serialize(model):
    model.setContinuousStates(_states(0.5, 0.25), 2)
    blob = model.serializeFMUstate(model.getFMUstate())
    model.setContinuousStates(_states(-2.0, 3.0), 2)
    model.setFMUstate(model.deSerializeFMUstate(blob))
    states = _states(0.0, 0.0)
    model.getContinuousStates(states, 2)
    assert list(states) == [0.5, 0.25]
