"""The pendulum linearised at an operating point from the FMU's own partial derivatives.

linearize() opens an instance at the operating point and asks it for d(theta, omega, alpha) /
d(theta, omega, torque) with fmi2GetDirectionalDerivative (fmi3GetDirectionalDerivative for an
FMI 3.0 FMU), one known at a time; A, B, C, D are blocks of that one Jacobian, since omega and
alpha are the states' derivatives (modelDescription.xml's derivative attributes).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import numpy as np
from fmpy.fmi1 import FMICallException

from .._errors import MissingDependency
from ._instance import FmuError, open_fmu
from ._model import FmuFileError, FmuModel, fmu_model
from ._parameters import merged_with, start_value
from ._simulate import resolve_parameters

# x, u and y of the state-space model; the derivatives of the states are the outputs after theta.
STATES = ("theta", "omega")
INPUTS = ("torque",)
OUTPUTS = ("theta", "omega", "alpha")
KNOWNS = STATES + INPUTS


@dataclass(frozen=True)
class Linearization:
    """The pendulum's linear model at an operating point: dx = A dx + B du, dy = C dx + D du.

    x = (theta, omega), u = (torque,), y = (theta, omega, alpha), in the FMU's SI units (theta
    from the downward vertical). Unpacks as ``A, B, C, D = linearize(...)``.

    Attributes
    ----------
    A : numpy.ndarray
        (2, 2) float64: d(omega, alpha) / d(theta, omega).
    B : numpy.ndarray
        (2, 1) float64: d(omega, alpha) / d(torque).
    C : numpy.ndarray
        (3, 2) float64: d(theta, omega, alpha) / d(theta, omega).
    D : numpy.ndarray
        (3, 1) float64: d(theta, omega, alpha) / d(torque).
    operating_point : dict of str to float
        theta (rad), omega (rad/s) and torque (N.m) where it was linearised.
    parameters : dict of str to float
        The FMU's parameters it was linearised with (its defaults with the overrides).
    states, inputs, outputs : tuple of str
        The names of x, u and y, in the matrices' order.

    Examples
    --------
    >>> from pendulum_fmu import linearize
    >>> A, B, C, D = linearize(theta=0.0)
    >>> A.tolist(), B.tolist()
    ([[0.0, 1.0], [-6.54, 0.0]], [[0.0], [0.03333333333333333]])
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    operating_point: dict[str, float]
    parameters: dict[str, float]
    states: ClassVar[tuple[str, ...]] = STATES
    inputs: ClassVar[tuple[str, ...]] = INPUTS
    outputs: ClassVar[tuple[str, ...]] = OUTPUTS

    def __iter__(self):
        return iter((self.A, self.B, self.C, self.D))

    def to_statespace(self):
        """The linear model as python-control's StateSpace, its signals named.

        Returns
        -------
        control.StateSpace
            A, B, C, D with states theta, omega, input torque, outputs theta, omega, alpha.

        Raises
        ------
        MissingDependency
            python-control is not installed.

        Examples
        --------
        >>> from pendulum_fmu import linearize
        >>> system = linearize(theta=0.0).to_statespace()
        >>> system.state_labels, system.input_labels, system.output_labels
        (['theta', 'omega'], ['torque'], ['theta', 'omega', 'alpha'])
        """
        try:
            import control
        except ImportError:
            raise MissingDependency(
                "a StateSpace needs python-control: pip install control (or pip install 'pendulum-fmu[control]')"
            ) from None
        return control.ss(
            self.A,
            self.B,
            self.C,
            self.D,
            states=list(STATES),
            inputs=list(INPUTS),
            outputs=list(OUTPUTS),
            name="pendulum",
        )


def linearize(
    *,
    theta: float = 0.0,
    omega: float = 0.0,
    torque: float = 0.0,
    parameters: dict | None = None,
    fmu_path: str | Path | FmuModel | None = None,
) -> Linearization:
    """Linearise the pendulum FMU at an operating point from its own directional derivatives.

    An instance of the FMU is opened at theta and omega with the parameters, given the torque,
    and asked for the partial derivatives of its outputs theta, omega (the derivative of theta)
    and alpha (the derivative of omega) with respect to the states theta, omega and the input
    torque (fmi2GetDirectionalDerivative, or fmi3GetDirectionalDerivative for an FMI 3.0 FMU).
    The operating point need not be an equilibrium.

    Parameters
    ----------
    theta : float, optional
        Angle from the downward vertical, in rad (pi: upright).
    omega : float, optional
        Rate in rad/s.
    torque : float, optional
        Torque at the pivot in N.m.
    parameters : dict, optional
        Overrides of the FMU's parameters (mass, length, inertia, gravity, damping).
    fmu_path : str, Path or FmuModel, optional
        The FMU (default: pendulum_fmu.default_fmu()); its own parameters apply.

    Returns
    -------
    Linearization
        A (2x2), B (2x1), C (3x2), D (3x1) as float64 arrays, which unpack as ``A, B, C, D``;
        ``.to_statespace()`` gives python-control's StateSpace.

    Raises
    ------
    InvalidInput
        An operating point that is not finite, or a parameter the package or the FMU refuses.
    FmuFileError
        No pendulum FMU this machine runs, or an FMI 2.0 FMU that provides no directional
        derivatives.
    FmuError
        The FMU refused a call; the message carries what it logged.
    MissingFile
        No FMU at fmu_path.

    Examples
    --------
    Upright (theta = pi) the default pendulum (30 kg.m^2 about the pivot, a gravity moment of
    196.2 N.m) falls away at sqrt(196.2 / 30) rad/s:

    >>> import math
    >>> import numpy as np
    >>> from pendulum_fmu import linearize
    >>> A, B, C, D = linearize(theta=math.pi)
    >>> A.round(6).tolist(), B.round(6).tolist()
    ([[0.0, 1.0], [6.54, 0.0]], [[0.0], [0.033333]])
    >>> C.round(6).tolist(), D.round(6).tolist()
    ([[1.0, 0.0], [0.0, 1.0], [6.54, 0.0]], [[0.0], [0.0], [0.033333]])
    >>> float(np.linalg.eigvals(A).max().round(6))
    2.557342
    """
    point = {
        "theta": start_value("theta", theta, "rad"),
        "omega": start_value("omega", omega, "rad/s"),
        "torque": start_value("torque", torque, "N.m"),
    }
    model = fmu_model(fmu_path)
    _ = model.pendulum_variables  # FmuFileError for an FMU that is no pendulum, before the flag
    # fmpy reads this flag from FMI 2.0 descriptions only (it leaves out FMI 3.0's
    # providesDirectionalDerivatives): an FMI 3.0 FMU without them says so when it is called.
    if model.fmi_version == 2 and not model.description.coSimulation.providesDirectionalDerivative:
        raise FmuFileError(
            f"{model.path} provides no directional derivatives (providesDirectionalDerivative in "
            "its CoSimulation element), which linearize asks it for: give an FMU that provides them"
        )
    merged = merged_with(model.default_parameters, parameters)
    jacobian = _jacobian(model, point, parameters)
    return Linearization(
        A=jacobian[1:, :2].copy(),
        B=jacobian[1:, 2:].copy(),
        C=jacobian[:, :2].copy(),
        D=jacobian[:, 2:].copy(),
        operating_point=point,
        parameters=merged,
    )


def _jacobian(model: FmuModel, point: dict[str, float], parameters: dict | None) -> np.ndarray:
    """d(theta, omega, alpha) / d(theta, omega, torque) of the FMU at point, a row per output."""
    try:
        instance = open_fmu(model, parameters=parameters, theta0=point["theta"], omega0=point["omega"])
    except FmuError:
        resolve_parameters(parameters, model)  # refused in the words every other tool uses
        raise
    references = model.value_references
    unknowns = [references[name] for name in OUTPUTS]
    set_torque = instance.setFloat64 if instance.fmi_version == 3 else instance.setReal
    try:
        set_torque([references["torque"]], [point["torque"]])
        # One known at a time, seeded with 1: each call gives one column.
        columns = [instance.getDirectionalDerivative(unknowns, [references[known]], [1.0]) for known in KNOWNS]
        instance.terminate()
    except FMICallException as error:
        raise instance.messages.error(error.status, error.function) from None
    finally:
        instance.freeInstance()
    return np.array(columns, dtype=np.float64).T
