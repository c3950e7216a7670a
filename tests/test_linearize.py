"""linearize: the FMU's own directional derivatives against the analytic Jacobian, against a
finite difference of the FMU's own steps, as python-control's StateSpace, and its refusals.
"""

import math
import sys
import zipfile

import numpy as np
import pytest
from scipy.linalg import expm

from pendulum_fmu import (
    FmuFileError,
    InvalidInput,
    Linearization,
    MissingDependency,
    default_fmu,
    fmu_model,
    linearize,
    simulate,
)

# (theta, omega, torque): hanging, upright, and points far from any equilibrium.
OPERATING_POINTS = [(0.0, 0.0, 0.0), (math.pi, 0.0, 0.0), (0.7, -1.3, 5.0), (-2.5, 3.0, -40.0), (12.0, 0.2, 1.0)]
PARAMETER_SETS = [
    {},
    {"damping": 2.5},
    # Gymnasium's Pendulum-v1: a uniform 1 kg, 1 m rod at g = 10, here with damping.
    {"mass": 1.0, "length": 0.5, "inertia": 1 / 12, "gravity": 10.0, "damping": 0.3},
    {"gravity": 0.0},
    {"mass": 3.0, "length": 2.0, "inertia": 0.0, "damping": 0.1, "gravity": 1.62},
]


def analytic(theta, parameters):
    """A, B, C, D of I alpha = torque - m g L sin(theta) - d omega, I = inertia + m L^2."""
    p = {**fmu_model().default_parameters, **parameters}
    inertia = p["inertia"] + p["mass"] * p["length"] ** 2
    d_alpha = [-p["mass"] * p["gravity"] * p["length"] * math.cos(theta) / inertia, -p["damping"] / inertia]
    A = np.array([[0.0, 1.0], d_alpha])
    B = np.array([[0.0], [1 / inertia]])
    C = np.array([[1.0, 0.0], [0.0, 1.0], d_alpha])
    D = np.array([[0.0], [0.0], [1 / inertia]])
    return A, B, C, D


@pytest.mark.parametrize("parameters", PARAMETER_SETS)
@pytest.mark.parametrize("point", OPERATING_POINTS)
def test_the_fmus_partial_derivatives_are_the_analytic_jacobian(point, parameters):
    theta, omega, torque = point
    linear = linearize(theta=theta, omega=omega, torque=torque, parameters=parameters)
    for got, want in zip(linear, analytic(theta, parameters), strict=True):
        assert got.dtype == np.float64 and got.shape == want.shape
        np.testing.assert_allclose(got, want, rtol=1e-14, atol=1e-15)
    assert linear.operating_point == {"theta": theta, "omega": omega, "torque": torque}
    assert linear.parameters == {**fmu_model().default_parameters, **parameters}


@pytest.mark.parametrize("parameters", PARAMETER_SETS[:3])
@pytest.mark.parametrize("theta", [0.0, math.pi, 0.5])
def test_at_an_equilibrium_a_step_of_the_fmu_moves_as_the_exponential_of_the_linearisation(theta, parameters):
    """d(theta, omega after h) / d(theta, omega, torque) by central differences of the FMU's own
    steps from the equilibrium where torque holds theta, against expm([[A, B], [0, 0]] h).
    """
    p = {**fmu_model().default_parameters, **parameters}
    held = p["mass"] * p["gravity"] * p["length"] * math.sin(theta)
    A, B, _, _ = linearize(theta=theta, torque=held, parameters=parameters)
    h, epsilon = 0.01, 1e-4

    def stepped(theta0, omega0, torque):
        run = simulate(torque, stop_time=h, step_size=h, theta0=theta0, omega0=omega0, parameters=parameters)
        return np.array([run["theta"][-1], run["omega"][-1]])

    point = np.array([theta, 0.0, held])
    columns = []
    for known in range(3):
        delta = np.zeros(3)
        delta[known] = epsilon
        columns.append((stepped(*(point + delta)) - stepped(*(point - delta))) / (2 * epsilon))
    finite_difference = np.array(columns).T
    exact = expm(np.block([[A, B], [np.zeros((1, 3))]]) * h)[:2]
    # The differences agree to 2.5e-10 (the FMU's tolerance); 1e-8 resolves A and B: a gravity
    # moment 1 % off moves d(omega after h)/d(theta), about h A[1, 0], by 5.7e-4 or more here.
    np.testing.assert_allclose(finite_difference, exact, rtol=0, atol=1e-8)


def test_fmi3_gives_the_fmi2_numbers():
    point = dict(theta=2.0, omega=-0.5, torque=3.0, parameters={"damping": 1.5})
    for fmi2, fmi3 in zip(linearize(**point), linearize(**point, fmu_path=default_fmu(3)), strict=True):
        np.testing.assert_array_equal(fmi3, fmi2)


def test_the_statespace_is_the_linearisation_and_has_the_pendulums_poles_and_gain():
    control = pytest.importorskip("control", reason="python-control not installed: pip install control")
    parameters = {"damping": 4.0}
    linear = linearize(parameters=parameters)
    system = linear.to_statespace()
    assert isinstance(system, control.StateSpace) and isinstance(linear, Linearization)
    for got, want in zip((system.A, system.B, system.C, system.D), linear, strict=True):
        np.testing.assert_array_equal(got, want)
    assert (system.state_labels, system.input_labels, system.output_labels) == (
        ["theta", "omega"],
        ["torque"],
        ["theta", "omega", "alpha"],
    )
    # Hanging, damped: I s^2 + d s + m g L = 0, and a held torque u holds theta = u / (m g L).
    p = {**fmu_model().default_parameters, **parameters}
    inertia, stiffness = p["inertia"] + p["mass"] * p["length"] ** 2, p["mass"] * p["gravity"] * p["length"]
    poles = np.sort_complex(control.poles(system))
    np.testing.assert_allclose(poles, np.sort_complex(np.roots([inertia, p["damping"], stiffness])), rtol=1e-12)
    np.testing.assert_allclose(control.dcgain(system)[:, 0], [1 / stiffness, 0.0, 0.0], rtol=1e-12, atol=1e-15)


def test_a_statespace_without_python_control_says_what_to_install(monkeypatch):
    monkeypatch.setitem(sys.modules, "control", None)  # import control raises ImportError
    with pytest.raises(MissingDependency, match=r"^a StateSpace needs python-control: pip install control"):
        linearize().to_statespace()


@pytest.mark.parametrize(
    ("point", "message"),
    [
        ({"theta": float("nan")}, "theta = nan must be a finite number of rad"),
        ({"omega": float("inf")}, "omega = inf must be a finite number of rad/s"),
        ({"torque": "1"}, "torque = '1' must be a finite number of N.m"),
        ({"parameters": {"mass": 0.0}}, "the FMU refuses the parameters: mass must be > 0"),
        ({"parameters": {"spring": 1.0}}, "unknown parameter 'spring'"),
    ],
)
def test_a_bad_operating_point_or_parameter_is_refused_in_one_line(point, message):
    with pytest.raises(InvalidInput) as refused:
        linearize(**point)
    assert str(refused.value).startswith(message) and "\n" not in str(refused.value)


def test_an_fmu_that_provides_no_directional_derivatives_is_refused(tmp_path):
    without = tmp_path / "NoDerivatives.fmu"
    with zipfile.ZipFile(default_fmu()) as source, zipfile.ZipFile(without, "w") as copy:
        for item in source.infolist():
            data = source.read(item)
            if item.filename == "modelDescription.xml":
                data = data.replace(b'providesDirectionalDerivative="true"', b'providesDirectionalDerivative="false"')
            copy.writestr(item, data)
    with pytest.raises(FmuFileError, match=r"NoDerivatives\.fmu provides no directional derivatives"):
        linearize(fmu_path=without)
