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
from scipy.integrate import solve_ivp

from .atomic_files import replacing
from ._checkout import ROOT, build_tool
from .errors import InvalidInput
from .parameters import total_inertia
from .simulate import resolve_parameters

# Pendulum output -> controller input, and back.
WIRES = (("pendulum", "theta", "controller", "theta"),
         ("pendulum", "omega", "controller", "omega"),
         ("controller", "torque", "pendulum", "torque"))


def controller_defaults() -> dict[str, float]:
    """setpoint, kp, ki, kd as the controller's modelDescription.xml sets them."""
    variables = read_model_description(str(ROOT / "fmu_src" / "pid_controller" / "modelDescription.xml")).modelVariables
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
    BuildError
        The pendulum or the controller cannot be built here.
    """
    if not (isinstance(step_size, numbers.Real) and 0 < step_size < math.inf):
        raise InvalidInput(f"step size {step_size!r} must be a positive number of seconds")
    out_file = Path(out_file)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        build = build_tool()
        files = {"pendulum": build.build_fmu(tmp / "Pendulum.fmu"),
                 "controller": build.build_pid_controller(tmp / "PIDController.fmu")}
        components, variables = {}, {}
        for name, path in files.items():
            description = read_model_description(str(path))
            components[name] = Component(name=name, filename=path, modelDescription=description)
            variables[name] = {v.name: v for v in description.modelVariables}
        exported = {name: ModelVariable(type="Real", variability="continuous", causality="output",
                                        initial="calculated", name=name) for name in ("theta", "torque")}
        container = ModelDescription(
            fmiVersion="2.0", modelName="PendulumClosedLoop", instantiationToken="",
            defaultExperiment=DefaultExperiment(stopTime="6", stepSize=str(step_size)),
            coSimulation=CoSimulation(fixedInternalStepSize=step_size),
            modelVariables=[ModelVariable(type="Real", variability="continuous",
                                          causality="independent", name="time"), *exported.values()])
        configuration = Configuration(
            parallelDoStep=False, modelDescription=container, components=list(components.values()),
            connections=[Connection(components[a], [_connector(variables[a][out])],
                                    components[b], [_connector(variables[b][into])])
                         for a, out, b, into in WIRES],
            variableMappings={exported["theta"]: [(components["pendulum"], variables["pendulum"]["theta"])],
                              exported["torque"]: [(components["controller"], variables["controller"]["torque"])]})
        work = tmp / "container"
        work.mkdir()
        # fmpy renames its zip to the name given: made here, then copied into place whole (the
        # target may be on another file system than the temporary folder).
        create_container_fmu(configuration, work, tmp / "ClosedLoop.fmu")
        with replacing(out_file, "wb") as file, open(tmp / "ClosedLoop.fmu", "rb") as made:
            shutil.copyfileobj(made, file)
    return out_file


def sampled_loop_reference(stop_time: float = 6.0, step_size: float = 1e-3, *,
                           controller: dict | None = None, parameters: dict | None = None,
                           feedthrough_delay: bool = False, rtol: float = 1e-12) -> np.ndarray:
    """time, theta, omega, torque of the sampled loop: each step a torque from the controller is
    held while scipy integrates the pendulum; the controller's error integral of a held error is
    exact.

    Masters differ in when they read the controller's torque, a direct feedthrough of theta:
    fmpy's container sets the controller's new inputs first, so the torque for step k comes from
    theta_k (feedthrough_delay=False). libcosim reads each slave's outputs right after its step,
    before the new inputs reach it, so the torque for step k comes from theta_(k-1) and the
    integral at t_k (feedthrough_delay=True).
    """
    gains = {**controller_defaults(), **(controller or {})}
    p = resolve_parameters(parameters)
    inverse_inertia = 1.0 / total_inertia(p)
    gravity_moment = p["mass"] * p["gravity"] * p["length"]
    n = int(round(stop_time / step_size))
    out = np.zeros(n + 1, dtype=[("time", "f8"), ("theta", "f8"), ("omega", "f8"), ("torque", "f8")])
    state, integral = np.zeros(2), 0.0
    measured = state  # what the controller's inputs hold when its torque is read
    for k in range(n + 1):
        if not feedthrough_delay:
            measured = state
        torque = (gains["kp"] * (gains["setpoint"] - measured[0]) + gains["ki"] * integral
                  - gains["kd"] * measured[1])
        out[k] = (k * step_size, state[0], state[1], torque)
        if k == n:
            break
        rhs = lambda t, y, u=torque: (y[1], (u - gravity_moment * np.sin(y[0])  # noqa: E731
                                              - p["damping"] * y[1]) * inverse_inertia)
        integral += step_size * (gains["setpoint"] - state[0])
        measured = state
        state = solve_ivp(rhs, (0.0, step_size), state, method="DOP853", rtol=rtol, atol=rtol).y[:, -1]
    return out
