"""EnvPool's Pendulum-v1 as a compare tool.

EnvPool's Pendulum-v1 (C++, envpool/classic_control/pendulum.h) fixes everything but the
torque: no setting of its config (num_envs, seed, max_episode_steps, version, ...) changes its
physics (g = 10, m = l = 1), its step (0.05 s) or its start, which reset draws from its seed
(theta uniform in [-pi, pi), omega in [-1, 1]). So the tool runs EnvPool itself only where that
is the run asked for, and refuses any other in one line (_pendulum_v1.NotRepresentable): the
FMU's parameters must give Pendulum-v1's rod (_pendulum_v1.rod), every communication step must
be 0.05 s, and theta0, omega0 must be where EnvPool starts with seed SEED (start() gives it, the
refusal says it).

It differs from Gymnasium's where the speed clip bites: its theta moves by the new speed before
the clip (theta += new_theta_dot * dt, in version 1 as in 0), Gymnasium's by the clipped one.
What it reports is its float32 observation: cos and sin of theta (theta read back by atan2,
wrapped into [-pi, pi), so unwrapped here onto the start's turn) and omega; the torque it used is
the action as it takes it, a float32, clipped to +-2 N.m as its source does (it does not report it).
"""

from __future__ import annotations

import math
import warnings

import envpool
import numpy as np

from ..fmu._parameters import total_inertia
from ..signals._torque_schedule import TorqueSchedule
from ._pendulum_v1 import (
    MAX_SPEED,
    MAX_TORQUE,
    NotRepresentable,
    pendulum_v1_results,
    pendulum_v1_runner,
    rod,
    warn_clipped,
)

# The seed the tool gives EnvPool: its start is this seed's draw.
SEED = 0
# Its step (kDt), and its rod: I = m l^2 / 3 about the pivot, and m g l / 2 the gravity moment.
STEP = 0.05
INERTIA, GRAVITY_MOMENT = 1.0 / 3.0, 5.0
# How far theta0 and omega0 may be from its start: its float32 observation's rounding is 1e-7.
START_TOLERANCE = 1e-6


def _episode(torques: np.ndarray) -> np.ndarray:
    """The states (theta from the top in [-pi, pi], omega) EnvPool's Pendulum-v1 observes from its
    reset on, one row per step of these torques after the reset's.
    """
    with warnings.catch_warnings():
        # Gymnasium's note, on reset, that EnvPool's float64 bounds make float32 spaces: not the run's.
        warnings.filterwarnings("ignore", message=".*precision lowered by casting to float32", category=UserWarning)
        env = envpool.make(
            "Pendulum-v1", env_type="gymnasium", num_envs=1, seed=SEED, max_episode_steps=max(len(torques), 1)
        )
        observations = [env.reset()[0]]
        observations += [env.step(np.array([[u]], dtype=np.float32))[0] for u in torques.tolist()]
        env.close()
    cos, sin, omega = np.concatenate(observations).astype(float).T
    return np.column_stack([np.arctan2(sin, cos), omega])


def start() -> tuple[float, float]:
    """Where EnvPool's Pendulum-v1 starts with seed SEED, in the FMU's convention.

    Returns
    -------
    tuple of float
        theta0 (rad, from the downward vertical, in (0, 2 pi]) and omega0 (rad/s), as its float32
        observation gives them (to about 1e-7).

    Examples
    --------
    >>> theta0, omega0 = start()
    >>> f"{theta0:.4f} rad, {omega0:.4f} rad/s"
    '3.7250 rad, 0.6885 rad/s'
    """
    theta, omega = _episode(np.empty(0))[0].tolist()
    return theta + math.pi, omega


def _check_run(plan: TorqueSchedule, parameters: dict, theta0: float, omega0: float) -> tuple[float, float]:
    """NotRepresentable unless the run is EnvPool's fixed one (the module's docstring); its start."""
    rod(parameters, "envpool")  # damping refused as for Gymnasium
    inertia = total_inertia(parameters)
    moment = parameters["mass"] * parameters["gravity"] * parameters["length"]
    if not (math.isclose(inertia, INERTIA, rel_tol=1e-9) and math.isclose(moment, GRAVITY_MOMENT, rel_tol=1e-9)):
        raise NotRepresentable(
            f"envpool: EnvPool's Pendulum-v1 is a fixed 1 kg, 1 m rod under g = 10 (I = 1/3 kg.m2 about "
            f"the pivot, mass*gravity*length = 5 N.m); these parameters give {inertia:.6g} kg.m2 and "
            f"{moment:.6g} N.m: set mass 1, length 0.5, inertia 0.08333333333333333 and gravity 10 "
            "(--set), or leave envpool out of --tools"
        )
    if not np.allclose(plan.step_size, STEP, rtol=1e-9, atol=0):
        raise NotRepresentable(
            f"envpool: EnvPool's Pendulum-v1 steps {STEP:g} s, fixed; this run's steps are "
            f"{float(plan.step_size[np.argmax(np.abs(plan.step_size - STEP))]):.6g} s: give --step-size "
            f"{STEP:g} and a signal that changes on its grid, or leave envpool out of --tools"
        )
    theta, omega = start()
    off_by = abs(math.remainder(theta0 - theta, 2 * math.pi))
    if off_by > START_TOLERANCE or abs(omega0 - omega) > START_TOLERANCE:
        raise NotRepresentable(
            f"envpool: EnvPool's Pendulum-v1 cannot be put in a state; it starts where its reset draws "
            f"(seed {SEED}): theta0 {theta!r} rad, omega0 {omega!r} rad/s in the FMU's convention; give "
            f"--theta0 {theta!r} --omega0 {omega!r}, or leave envpool out of --tools"
        )
    return theta, omega


def simulate(plan: TorqueSchedule, parameters: dict, theta0: float, omega0: float) -> np.ndarray:
    """The schedule through EnvPool's Pendulum-v1; the result array of _results.py."""
    _check_run(plan, parameters, theta0, omega0)
    # One step past the run's end, under the last torque, gives the last row's alpha.
    torques = np.r_[plan.torque, plan.torque[-1]]
    top, omega = _episode(torques).T
    # Onto theta0's turn, then each step's change taken as the shortest (a step moves theta less than pi).
    top[0] += 2 * math.pi * round((theta0 - math.pi - top[0]) / (2 * math.pi))
    theta = np.unwrap(top)
    action = torques.astype(np.float32).astype(float)
    torque = np.clip(action, -MAX_TORQUE, MAX_TORQUE)
    warn_clipped("envpool", plan, np.abs(action[:-1]) > MAX_TORQUE, np.abs(omega[1:-1]) >= MAX_SPEED)
    return pendulum_v1_results(plan, theta, omega, torque)


run = pendulum_v1_runner("envpool", simulate)
