"""The case every part runs: OpenSim's pendulum tutorial, and the oracle for it."""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

from pendulum_fmu.oracle._reference import reference

TORQUE = 20.0  # N.m, held from t = 0 with the pendulum at rest at theta = 0, gravity on
STOP_TIME = 3.0  # s
STEP = 1e-3  # s
STEPS = round(STOP_TIME / STEP)
# The oracle: the package's reference (the pendulum's Taylor series) at a tolerance a step below
# a double's resolution of theta; how far it is from another method is oracle_error().
ORACLE_TOLERANCE = 1e-16
# The second opinion: scipy's DOP853 at about the tightest tolerance solve_ivp accepts (100
# machine epsilons), its steps bounded too.
SCIPY_TOLERANCE, SCIPY_MAX_STEP = 3e-14, 1e-3


def oracle_theta(step_size: float = STEP) -> np.ndarray:
    """Theta at t = 0, h, ..., STOP_TIME from the reference at rtol = atol = ORACLE_TOLERANCE."""
    run = reference(TORQUE, stop_time=STOP_TIME, step_size=step_size, rtol=ORACLE_TOLERANCE, atol=ORACLE_TOLERANCE)
    return run["theta"]


def oracle_error(step_size: float = STEP) -> float:
    """How far the oracle is from scipy's DOP853 on the same case (SCIPY_TOLERANCE, steps of at
    most SCIPY_MAX_STEP), max |theta difference| in rad: errors below it are not resolved.
    """
    parameters = (40.0 * 9.81 * 0.5, 20.0 + 40.0 * 0.5**2)  # the tutorial's m g l and I + m l^2

    def motion(t, y):
        return (y[1], (TORQUE - parameters[0] * np.sin(y[0])) / parameters[1])

    times = np.linspace(0.0, STOP_TIME, round(STOP_TIME / step_size) + 1)
    tolerance = SCIPY_TOLERANCE
    scipy_theta = solve_ivp(
        motion, (0.0, STOP_TIME), (0.0, 0.0), "DOP853", times, rtol=tolerance, atol=tolerance, max_step=SCIPY_MAX_STEP
    ).y[0]
    return float(np.max(np.abs(oracle_theta(step_size) - scipy_theta)))


def max_theta_error(theta: np.ndarray, step_size: float = STEP) -> float:
    return float(np.max(np.abs(theta - oracle_theta(step_size))))
