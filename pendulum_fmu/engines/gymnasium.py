"""Gymnasium's Pendulum-v1 as a compare tool.

The environment itself, gymnasium.make("Pendulum-v1", g=...), set up as the FMU's pendulum
(_pendulum_v1.py maps the parameters onto its rod: g through make's own argument, m and l as the
attributes of env.unwrapped): its dt set to each communication step before the step, its state
(theta from the top) set after reset, each step fed the step's torque. theta and omega are read
from env.unwrapped.state (doubles; the observation is float32 cos, sin and omega), the torque it
used from env.unwrapped.last_u (after its clip to +-2 N.m). Its clips stay: a run in which they
bite is Pendulum-v1's clipped run, said in one line (errors.Clipped).
"""

from __future__ import annotations

import math
from typing import cast

import gymnasium
import numpy as np
from gymnasium.envs.classic_control.pendulum import PendulumEnv

from ..signals._torque_schedule import TorqueSchedule
from ._pendulum_v1 import MAX_SPEED, pendulum_v1_results, pendulum_v1_runner, rod, warn_clipped


def simulate(plan: TorqueSchedule, parameters: dict, theta0: float, omega0: float) -> np.ndarray:
    """The schedule through Gymnasium's Pendulum-v1; the result array of _results.py."""
    gravity, mass, length = rod(parameters, "gymnasium")
    n = len(plan.step_size)
    # One step past the run's end, under the last torque, gives the last row's alpha.
    steps, torques = np.r_[plan.step_size, plan.step_size[-1]], np.r_[plan.torque, plan.torque[-1]]
    env = gymnasium.make("Pendulum-v1", g=gravity, max_episode_steps=n + 1)
    env.reset(seed=0)
    pendulum = cast(PendulumEnv, env.unwrapped)
    pendulum.m, pendulum.l = mass, length
    pendulum.state = np.array([theta0 - math.pi, omega0])
    theta, omega, torque = np.empty(n + 2), np.empty(n + 2), np.empty(n + 1)
    theta[0], omega[0] = pendulum.state
    for k, (h, u) in enumerate(zip(steps.tolist(), torques.tolist(), strict=True)):
        pendulum.dt = h
        env.step(np.array([u]))
        torque[k] = pendulum.last_u
        theta[k + 1], omega[k + 1] = pendulum.state
    env.close()
    warn_clipped("gymnasium", plan, torque[:-1] != plan.torque, np.abs(omega[1:-1]) >= MAX_SPEED)
    return pendulum_v1_results(plan, theta, omega, torque)


run = pendulum_v1_runner("gymnasium", simulate)
