"""Gymnasium's Pendulum-v1 conventions over the FMU's variables, for one environment or a batch.

Pendulum-v1 measures theta from the upright (0 up), the FMU from the downward vertical (0
down), both counter-clockwise with the torque: theta_gym = theta_fmu - pi, the same omega and
torque. Its observation is [cos theta_gym, sin theta_gym, omega], its reward
-(angle_normalize(theta_gym)^2 + 0.1 omega^2 + 0.001 u^2) of the state before the step and the
clipped torque u, and a reset draws theta_gym in [-x_init, x_init] and omega in [-y_init, y_init]
(pi and 1 unless the reset's options say). The vector environment calls these functions on
arrays; the single one on floats where a function has a scalar twin (observation, checked_torque),
because numpy's call costs more than the arithmetic on one value (a step costs 10 us, not 20).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._errors import InvalidInput

# Pendulum-v1's physics as the FMU's parameters: a uniform rod of 1 kg and 1 m about one end is a
# mass of 1 kg whose centre is 0.5 m from the pivot, with its own inertia m l^2 / 12 about that
# centre (so inertia + mass*length^2 = m l^2 / 3, Pendulum-v1's 1/3); gravity 10 m/s^2.
PENDULUM_V1_PARAMETERS = {"mass": 1.0, "length": 0.5, "inertia": 1.0 / 12.0, "gravity": 10.0, "damping": 0.0}
# Pendulum-v1's torque limit (N.m), communication step (s) and episode length (steps).
MAX_TORQUE, DT, MAX_EPISODE_STEPS = 2.0, 0.05, 200
# The half-widths of Pendulum-v1's reset draw: theta_gym (rad) and omega (rad/s).
RESET_BOUNDS = (math.pi, 1.0)


def fmu_angle(theta: np.ndarray | float) -> np.ndarray | float:
    """The FMU's theta (0 down) of Gymnasium's theta (0 up)."""
    return theta + math.pi


def observations(theta_fmu: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """(n, 3) float64 [cos theta_gym, sin theta_gym, omega] of the FMU's theta and omega."""
    theta = theta_fmu - math.pi
    return np.stack((np.cos(theta), np.sin(theta), omega), axis=-1)


def observation(theta_fmu: float, omega: float) -> np.ndarray:
    """observations() of one environment: (3,) float64."""
    theta = theta_fmu - math.pi
    return np.array((math.cos(theta), math.sin(theta), omega))


def rewards(theta_fmu, omega, torque):
    """Pendulum-v1's reward of a step from (theta_fmu, omega) with the clipped torque: of floats
    or of arrays alike (only the operators, which round alike on both).
    """
    # angle_normalize(theta_fmu - pi) = ((theta_fmu - pi + pi) mod 2 pi) - pi
    upright_error = theta_fmu % (2 * math.pi) - math.pi
    return -(upright_error * upright_error + 0.1 * omega * omega + 0.001 * torque * torque)


def reset_bounds(options: dict[str, Any] | None) -> np.ndarray:
    """The half-widths of a reset's draw: Pendulum-v1's, or its options' x_init and y_init."""
    bounds = list(RESET_BOUNDS)
    for index, key in enumerate(("x_init", "y_init")):
        if options and key in options:
            value = options[key]
            try:
                bounds[index] = float(value)
            except (TypeError, ValueError):
                raise InvalidInput(f"reset option {key} = {value!r} is not a number") from None
            if not math.isfinite(bounds[index]):
                raise InvalidInput(f"reset option {key} = {value} must be finite")
    return np.array(bounds)


def draw_state(rng: np.random.Generator, bounds: np.ndarray) -> np.ndarray:
    """(theta_gym, omega) drawn as Pendulum-v1's reset draws them from its generator."""
    return rng.uniform(low=-bounds, high=bounds)


def checked_torque(action, max_torque: float) -> float:
    """checked_actions() of one environment's action (shape (1,)): its clipped torque."""
    if type(action) is np.ndarray and action.shape == (1,) and action.dtype.kind == "f":
        torque = float(action[0])  # the usual action, read without numpy's calls
        if math.isfinite(torque):
            return min(max(torque, -max_torque), max_torque)
    return float(checked_actions(action, (1,), max_torque)[0])


def checked_actions(actions, shape: tuple[int, ...], max_torque: float) -> np.ndarray:
    """The torques of actions of the given shape, clipped to +-max_torque, as float64.

    Raises
    ------
    InvalidInput
        An action of another shape, not numbers, or not finite: nothing is stepped.
    """
    try:
        torques = np.asarray(actions, dtype=np.float64)
    except (TypeError, ValueError):
        raise InvalidInput(f"action {actions!r} is not numbers: give a float array of shape {shape}") from None
    if torques.shape != shape:
        raise InvalidInput(f"action of shape {torques.shape}: the action space's shape is {shape}")
    if not np.isfinite(torques).all():
        raise InvalidInput(f"action {actions!r} is not finite: every torque must be a finite number of N.m")
    return np.clip(torques, -max_torque, max_torque)
