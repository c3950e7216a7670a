"""The pendulum under the PID controller FMU: the co-simulation the tutorial closes on.

Both FMUs advance in lock-step: at each communication point the controller reads the
pendulum's theta and omega and the pendulum the controller's torque, all held over the step.
create_closed_loop_fmu() packs the two into one FMU with fmpy's container; sampled_loop_reference()
is the same sampled loop computed with scipy, the oracle for any master that runs it.
"""

from __future__ import annotations

import copy
import math
import numbers
import shutil
import tempfile
from pathlib import Path

import numpy as np
from fmpy import read_model_description
from fmpy.container_fmu.cli import create_container_fmu
from fmpy.container_fmu.config import Component, Configuration, Connection
from fmpy.model_description import CoSimulation, DefaultExperiment, ModelDescription, ModelVariable

from .. import default_fmu
from .._atomic_files import replacing
from .._checkout import ROOT, build_tool, is_source_checkout
from .._errors import InvalidInput
from ..fmu._simulate import resolve_parameters
from ..oracle._reference import model_constants
from ..oracle._taylor import check_tolerances, integrate_piece

# Pendulum output -> controller input, and back.
WIRES = (
    ("pendulum", "theta", "controller", "theta"),
    ("pendulum", "omega", "controller", "omega"),
    ("controller", "torque", "pendulum", "torque"),
)


def controller_fmu() -> Path:
    """The PID controller FMU that closes the loop around the pendulum.

    In a source checkout: dist/PIDController.fmu, rebuilt first when any of its sources is newer.
    In an installed package: the one packaged with it (the wheel builds it for the pendulum's
    platforms).

    Returns
    -------
    Path

    Raises
    ------
    MissingFile
        An installed package without its packaged controller.
    BuildError
        A checkout whose controller is stale and cannot be rebuilt here.
    """
    from .. import CONTROLLER_FMU_FILE, _packaged_file

    if not is_source_checkout():
        return _packaged_file(CONTROLLER_FMU_FILE)
    build = build_tool()
    if build.fmu_is_stale(build.CHECKOUT_CONTROLLER):
        build.build_pid_controller(build.CHECKOUT_CONTROLLER)
    return build.CHECKOUT_CONTROLLER


def controller_defaults() -> dict[str, float]:
    """setpoint, kp, ki, kd as the controller's modelDescription.xml sets them.

    Read from its sources in a checkout, from its packaged FMU in an installed package.

    Raises
    ------
    MissingFile
        An installed package without its packaged controller.
    """
    description = ROOT / "fmu_src" / "pid_controller" / "modelDescription.xml"
    source = description if description.is_file() else controller_fmu()
    variables = read_model_description(str(source)).modelVariables
    return {v.name: float(v.start) for v in variables if v.causality == "parameter"}


def _connector(variable: ModelVariable) -> ModelVariable:
    # fmpy writes an FMI 2 connection's type as "Real", which its container binary rejects; it
    # reads the FMI 3 name.
    connector = copy.copy(variable)
    connector.type = "Float64"
    return connector


def create_closed_loop_fmu(out_file: str | Path, *, step_size: float = 1e-3) -> Path:
    """One FMU (fmpy's container) holding the pendulum and the PID controller, wired together,
    with outputs theta and torque.

    Parameters
    ----------
    out_file : str or Path
        The FMU to write.
    step_size : float, optional
        The container's fixed communication step in s.

    Returns
    -------
    Path
        out_file.

    Raises
    ------
    InvalidInput
        A step size that is not a positive number.
    CannotWrite
        out_file cannot be written.
    MissingFile
        An installed package without its packaged FMUs.
    BuildError
        A checkout whose FMUs are stale and cannot be rebuilt here.

    Examples
    --------
    A step size is checked before anything is built:

    >>> from pendulum_fmu import InvalidInput, create_closed_loop_fmu
    >>> try:
    ...     create_closed_loop_fmu("ClosedLoop.fmu", step_size=0)
    ... except InvalidInput as error:
    ...     print(error)
    step size 0 must be a positive number of seconds

    The FMUs are built when stale (about a minute for every platform), too long for a doctest;
    tests/test_closed_loop.py runs it:

    >>> import tempfile
    >>> from pathlib import Path
    >>> from fmpy import read_model_description
    >>> loop = create_closed_loop_fmu(Path(tempfile.mkdtemp(), "ClosedLoop.fmu"))  # doctest: +SKIP
    >>> [variable.name for variable in read_model_description(loop).modelVariables]  # doctest: +SKIP
    ['time', 'theta', 'torque']
    """
    if not (isinstance(step_size, numbers.Real) and 0 < step_size < math.inf):
        raise InvalidInput(f"step size {step_size!r} must be a positive number of seconds")
    out_file = Path(out_file)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        files = {"pendulum": default_fmu(), "controller": controller_fmu()}
        components, variables = {}, {}
        for name, path in files.items():
            description = read_model_description(str(path))
            components[name] = Component(name=name, filename=path, modelDescription=description)
            variables[name] = {v.name: v for v in description.modelVariables}
        exported = {
            name: ModelVariable(
                type="Real", variability="continuous", causality="output", initial="calculated", name=name
            )
            for name in ("theta", "torque")
        }
        container = ModelDescription(
            fmiVersion="2.0",
            modelName="PendulumClosedLoop",
            instantiationToken="",
            defaultExperiment=DefaultExperiment(stopTime="6", stepSize=str(step_size)),
            coSimulation=CoSimulation(fixedInternalStepSize=step_size),
            modelVariables=[
                ModelVariable(type="Real", variability="continuous", causality="independent", name="time"),
                *exported.values(),
            ],
        )
        configuration = Configuration(
            parallelDoStep=False,
            modelDescription=container,
            components=list(components.values()),
            connections=[
                Connection(
                    components[a], [_connector(variables[a][out])], components[b], [_connector(variables[b][into])]
                )
                for a, out, b, into in WIRES
            ],
            variableMappings={
                exported["theta"]: [(components["pendulum"], variables["pendulum"]["theta"])],
                exported["torque"]: [(components["controller"], variables["controller"]["torque"])],
            },
        )
        work = tmp / "container"
        work.mkdir()
        # fmpy renames its zip to the name given: made here, then copied into place whole (the
        # target may be on another file system than the temporary folder).
        create_container_fmu(configuration, work, tmp / "ClosedLoop.fmu")
        with replacing(out_file, "wb") as file, open(tmp / "ClosedLoop.fmu", "rb") as made:
            shutil.copyfileobj(made, file)
    return out_file


# How a master orders the loop's data exchange, each by the torque it holds over step k
# (t_k to t_(k+1)): the controller's law on which theta and omega, with its error integral to when.
COUPLINGS = {
    "gauss-seidel-pendulum-first": "the pendulum steps first; its theta and omega reach the controller "
    "before the controller's torque is read (theta_k, integral to t_k)",
    "gauss-seidel-controller-first": "the controller steps first on theta_k and its torque, integral "
    "to t_(k+1), drives the pendulum over the same step",
    "jacobi": "both step on what was exchanged at t_k: the torque read after the controller's last "
    "step (theta_(k-1), integral to t_k); the first from the initial exchange",
    "jacobi-first-exchange-missing": "as jacobi, but nothing is exchanged before the first step: the "
    "pendulum's first step holds torque 0",
}


def sampled_loop_reference(
    stop_time: float = 6.0,
    step_size: float = 1e-3,
    *,
    controller: dict | None = None,
    parameters: dict | None = None,
    coupling: str = "gauss-seidel-pendulum-first",
    rtol: float = 1e-12,
) -> np.ndarray:
    """time, theta, omega, torque of the sampled loop under one master's coupling.

    Each step a torque from the PID law (written here in Python, not the controller FMU's code)
    is held while the reference's Taylor series integrates the pendulum; the controller's error integral of a held error
    is exact. Masters differ in when they read the controller's torque, a direct feedthrough of
    theta (see COUPLINGS): fmpy's container is Gauss-Seidel with the pendulum first, libcosim
    Jacobi, fmpy.ssp Jacobi with no exchange before the first step.

    Parameters
    ----------
    stop_time, step_size : float, optional
        The experiment's end and the master's fixed communication step, in s.
    controller : dict, optional
        setpoint, kp, ki, kd over the controller's defaults.
    parameters : dict, optional
        The pendulum's parameters over its defaults.
    coupling : str, optional
        A key of COUPLINGS.
    rtol : float, optional
        The integrator's relative and absolute tolerance a step.

    Returns
    -------
    numpy.ndarray
        Structured array of time, theta, omega and the torque held over the step from that time,
        one row per communication point from 0 to stop_time.

    Raises
    ------
    InvalidInput
        A coupling that is not one of COUPLINGS, parameters the pendulum refuses, or an rtol that
        is not a number of at least 1e-16.

    Examples
    --------
    >>> theta = sampled_loop_reference(3.0, coupling="jacobi", controller={"setpoint": 0.3})["theta"]
    """
    check_tolerances(rtol, rtol)
    if coupling not in COUPLINGS:
        raise InvalidInput(f"coupling {coupling!r} is none of {', '.join(COUPLINGS)}")
    gains = {**controller_defaults(), **(controller or {})}
    model = model_constants(resolve_parameters(parameters))
    n = round(stop_time / step_size)
    out = np.zeros(n + 1, dtype=[("time", "f8"), ("theta", "f8"), ("omega", "f8"), ("torque", "f8")])
    state, integral = (0.0, 0.0), 0.0
    previous = state  # theta, omega at the last communication point, what a Jacobi master last sent

    def law(measured, error_integral):
        return (
            gains["kp"] * (gains["setpoint"] - measured[0]) + gains["ki"] * error_integral - gains["kd"] * measured[1]
        )

    for k in range(n + 1):
        next_integral = integral + step_size * (gains["setpoint"] - state[0])
        if coupling == "gauss-seidel-pendulum-first":
            torque = law(state, integral)
        elif coupling == "gauss-seidel-controller-first":
            torque = law(state, next_integral)
        elif coupling == "jacobi-first-exchange-missing" and k == 0:
            torque = 0.0
        else:
            torque = law(previous, integral)
        out[k] = (k * step_size, state[0], state[1], torque)
        if k == n:
            break
        integral, previous = next_integral, state
        state = integrate_piece(*state, (0.0, step_size), (torque, 0.0), model, (rtol, rtol), [])[2:]
    return out
