"""OpenSim as a compare tool: the torque-driven pendulum of the OpenSim tutorial.

The model follows the OpenSim pendulum tutorial (torque application): ground,
a welded base, a pin joint ``head_to_base`` with coordinate ``theta`` and a
``CoordinateActuator`` named ``torque`` (optimal force 1, so the actuation is
the torque in N.m) whose value is set through ``setOverrideActuation``.
Visual geometry is left out. OpenSim is an optional dependency, imported only when a run needs
it. mode "accurate" sets the Manager's integrator (Runge-Kutta-Merson) to an accuracy of 1e-12;
"default" keeps its own accuracy.
"""

from __future__ import annotations

import os

import numpy as np

from .._errors import InvalidInput, MissingDependency
from ..fmu import _results as results
from ..signals._torque_schedule import TorqueSchedule
from . import runner


def _import_opensim():
    # Importing opensim otherwise drops an opensim.log into the working directory.
    os.environ.setdefault("OPENSIM_DISABLE_LOG_FILE", "1")
    try:
        import opensim
    except ImportError as error:
        raise MissingDependency(
            "opensim_simulate needs the OpenSim Python package; install the extra: pip install '.[opensim]'"
        ) from error
    return opensim


def _build_pendulum_model(osim, mass, length, inertia, gravity, damping):
    """Return (model, coordinate, actuator) for the tutorial pendulum."""
    model = osim.Model()
    model.setName("Pendulum")
    model.setGravity(osim.Vec3(0, -gravity, 0))

    base = osim.Body("pendulum_base", 1.0, osim.Vec3(0), osim.Inertia(0, 0, 0))
    model.addBody(base)
    model.addJoint(
        osim.WeldJoint(
            "base_to_ground",
            model.getGround(),
            osim.Vec3(0, 1.2 * length, 0),
            osim.Vec3(0),
            base,
            osim.Vec3(0),
            osim.Vec3(0),
        )
    )

    # Inertia is about the head's centre of mass; the pin sits `length` above it.
    head = osim.Body("pendulum_head", mass, osim.Vec3(0), osim.Inertia(0, 0, inertia))
    model.addBody(head)
    pin = osim.PinJoint(
        "head_to_base",
        base,
        osim.Vec3(0),
        osim.Vec3(0),
        head,
        osim.Vec3(0, length, 0),
        osim.Vec3(0),
    )
    model.addJoint(pin)

    coordinate = pin.getCoordinate()
    coordinate.setName("theta")

    actuator = osim.CoordinateActuator()
    actuator.setName("torque")
    actuator.setCoordinate(coordinate)
    actuator.setOptimalForce(1)
    actuator.setMinControl(-1e6)
    actuator.setMaxControl(1e6)
    model.addForce(actuator)

    if damping > 0:
        # Generalized force -stiffness*(theta - rest) - viscosity*omega; with
        # zero stiffness it is a pure viscous damper, -damping*omega.
        damper = osim.SpringGeneralizedForce("theta")
        damper.setName("damping")
        damper.setStiffness(0.0)
        damper.setRestLength(0.0)
        damper.setViscosity(damping)
        model.addForce(damper)

    model.finalizeConnections()
    return model, coordinate, actuator


def opensim_simulate(
    time,
    torque,
    *,
    mass=40.0,
    length=0.5,
    inertia=20.0,
    gravity=9.81,
    damping=0.0,
    theta0=0.0,
    omega0=0.0,
    accuracy=1e-12,
):
    """Simulate the pendulum in OpenSim with a torque held constant per step.

    Parameters
    ----------
    time : array_like
        The N+1 communication points t_0 < ... < t_N in s (the steps may differ in size).
    torque : array_like
        N values in N.m; torque[k] acts on [t_k, t_k+1].
    mass, length, inertia, gravity, damping : float, optional
        The pendulum (kg, m, kg.m2 about the head's centre, m/s2, N.m.s/rad).
    theta0, omega0 : float, optional
        Start angle in rad and rate in rad/s.
    accuracy : float, optional
        The Manager's integrator accuracy; None keeps its own default.

    Returns
    -------
    dict of numpy.ndarray
        'time', 'torque' (last value repeated), 'theta', 'omega' and 'alpha', each of length
        N+1, where alpha at t_k is the angular acceleration under the torque of the step that
        starts at t_k (torque[N-1] at t_N).

    Raises
    ------
    MissingDependency
        OpenSim is not installed.
    InvalidInput
        time and torque that are not N+1 increasing points and N values.
    """
    osim = _import_opensim()

    time = np.asarray(time, dtype=float)
    torque = np.asarray(torque, dtype=float)
    if time.ndim != 1 or time.size < 2:
        raise InvalidInput("time must be a 1-D array of at least two points")
    if torque.shape != (time.size - 1,):
        raise InvalidInput("torque must hold one value per step: len(time) - 1")
    if np.any(np.diff(time) <= 0):
        raise InvalidInput("time must be strictly increasing")

    model, coordinate, actuator = _build_pendulum_model(osim, mass, length, inertia, gravity, damping)
    coordinate.setDefaultValue(theta0)
    coordinate.setDefaultSpeedValue(omega0)
    state = model.initSystem()
    actuator.overrideActuation(state, True)

    manager = osim.Manager(model)
    manager.setWriteToStorage(False)
    manager.setPerformAnalyses(False)
    if accuracy is not None:  # None: the Manager's own default
        manager.setIntegratorAccuracy(accuracy)

    n_points = time.size
    held_torque = np.append(torque, torque[-1])
    theta = np.empty(n_points)
    omega = np.empty(n_points)
    alpha = np.empty(n_points)

    # Manager.integrate() logs ten info lines per call. The level is left at Warn afterwards:
    # setting it back to Info makes OpenSim log that it did, once per call.
    if osim.Logger.getLevel() < osim.Logger.Level_Warn:
        osim.Logger.setLevel(osim.Logger.Level_Warn)
    for k in range(n_points):
        state.setTime(time[k])
        actuator.setOverrideActuation(state, held_torque[k])
        model.realizeAcceleration(state)
        theta[k] = coordinate.getValue(state)
        omega[k] = coordinate.getSpeedValue(state)
        alpha[k] = coordinate.getAccelerationValue(state)
        if k == n_points - 1:
            break
        # Fix for the tutorial loop, which fails on OpenSim 4.6 at its
        # second step: integrate() returns a reference to the Manager's own
        # integrator State, and setOverrideActuation() changes a discrete
        # variable that invalidates Stage::Time, so that State drops to
        # Stage::Instance behind the integrator's back and Simbody refuses
        # the next step. The 4.6 Manager requires initialize() after any
        # change to the State; it restarts the integrator at the torque
        # jump. Passing the Manager's own State is fine (Simbody skips
        # self-assignment) and is ~3x faster than copying it first.
        manager.initialize(state)
        state = manager.integrate(time[k + 1])

    return {
        "time": time.copy(),
        "torque": held_torque,
        "theta": theta,
        "omega": omega,
        "alpha": alpha,
    }


def simulate(
    plan: TorqueSchedule, parameters: dict[str, float], theta0: float, omega0: float, accuracy: float | None
) -> np.ndarray:
    """The schedule through OpenSim at the Manager's accuracy (None: its own), as a results array."""
    run = opensim_simulate(plan.time, plan.torque, theta0=theta0, omega0=omega0, accuracy=accuracy, **parameters)
    out = results.empty(len(plan.time))  # an output OpenSim does not compute stays NaN
    for name, values in run.items():
        out[name] = values
    return out


# The Manager's integrator accuracy per mode; None keeps its own.
SETUPS = {"accurate": 1e-12, "default": None}
run = runner("opensim", simulate, SETUPS)
