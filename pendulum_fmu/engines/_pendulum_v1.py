"""What Gymnasium's and EnvPool's Pendulum-v1 share as compare tools: the FMU's parameters mapped
onto Pendulum-v1's rod, the angle from the top, the result from its states, the clips reported.

Pendulum-v1 is a uniform rod of mass m and length l hinged at one end, theta measured from the
upward vertical, stepped by semi-implicit Euler:

    omega' = omega + (3 g / (2 l) sin(theta) + 3 u / (m l^2)) dt,  then clipped to +-max_speed
    theta' = theta + omega' dt

the torque u clipped to +-max_torque first (2 N.m and 8 rad/s). The FMU's equation,
I_total alpha = u - mass gravity length sin(theta_fmu) - damping omega, is that rod's when
theta = theta_fmu - pi and

    m = mass,  l = sqrt(3 I_total / mass),  g = 2 gravity length / l

(the rod of the head's mass with the same moment of inertia about the pivot, and the gravity that
gives it the same gravity moment: 3 / (m l^2) = 1 / I_total, 3 g / (2 l) = mass gravity length /
I_total). A uniform 1 kg, 1 m rod (FMU mass 1, length 0.5, inertia 1/12) under gravity 10 maps to
m = l = 1, g = 10: Pendulum-v1's own. The torque passes unchanged. Damping has no counterpart.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable

import numpy as np

from .._errors import Clipped, InvalidInput
from ..fmu._parameters import total_inertia
from ..signals._torque_schedule import TorqueSchedule
from . import held_results, runner

# Pendulum-v1's clips, in Gymnasium (max_torque, max_speed) and EnvPool (kMaxTorque, kMaxSpeed).
MAX_TORQUE, MAX_SPEED = 2.0, 8.0


class NotRepresentable(InvalidInput):
    """A run Pendulum-v1 cannot represent: damping, or for EnvPool, whose physics, step and start
    are fixed, other parameters, another step or another start.
    """


def rod(parameters: dict, tool: str) -> tuple[float, float, float]:
    """Pendulum-v1's (g, m, l) for the FMU's (resolved) parameters: the same equation of motion
    (see the module's docstring); NotRepresentable for damping, which it has no term for.
    """
    if parameters["damping"] != 0:
        raise NotRepresentable(
            f"{tool}: Pendulum-v1 has no damping, so damping {parameters['damping']!r} N.m.s/rad "
            f"cannot be represented: set damping 0, or leave {tool} out of --tools"
        )
    length = math.sqrt(3.0 * total_inertia(parameters) / parameters["mass"])
    return 2.0 * parameters["gravity"] * parameters["length"] / length, parameters["mass"], length


def pendulum_v1_results(plan: TorqueSchedule, theta: np.ndarray, omega: np.ndarray, torque: np.ndarray) -> np.ndarray:
    """The result array of _results.py from Pendulum-v1's N + 2 states (theta from the top, the
    last one a step past the run's end under the last torque) and the N + 1 torques it used.

    alpha is the change of speed each step made, over the step: the acceleration its Euler step
    applied (after the speed clip, when it bites); the extra state gives the last row's.
    """
    out = held_results(plan)
    out["torque"] = torque
    out["theta"] = theta[:-1] + math.pi
    out["omega"] = omega[:-1]
    out["alpha"] = np.diff(omega) / np.r_[plan.step_size, plan.step_size[-1]]
    return out


def warn_clipped(tool: str, plan: TorqueSchedule, torque_clipped: np.ndarray, speed_clipped: np.ndarray) -> None:
    """Say in one line (errors.Clipped) in how many of the run's steps Pendulum-v1 clipped the
    torque or the speed, and from when; nothing when neither bit.
    """
    bites = [
        f"the {what} to +-{limit:g} {unit} in {int(np.sum(clipped)):,} of {len(plan.step_size):,} steps "
        f"(first from t = {plan.time[int(np.argmax(clipped))]:.6g} s)"
        for what, limit, unit, clipped in (
            ("torque", MAX_TORQUE, "N.m", torque_clipped),
            ("speed", MAX_SPEED, "rad/s", speed_clipped),
        )
        if np.any(clipped)
    ]
    if bites:
        warnings.warn(
            f"{tool}: Pendulum-v1 clipped {' and '.join(bites)}: its result is the clipped run's",
            Clipped,
            stacklevel=4,  # the caller of the tool's run()
        )


def pendulum_v1_runner(tool: str, simulate: Callable[..., np.ndarray]) -> Callable[..., np.ndarray]:
    """The run() of a Pendulum-v1 tool from its simulate(plan, parameters, theta0, omega0): one
    mode, Pendulum-v1's own (accurate), the torque held over each step.
    """
    return runner(
        tool,
        lambda plan, parameters, theta0, omega0, setup: simulate(plan, parameters, theta0, omega0),
        {"accurate": None},
    )
