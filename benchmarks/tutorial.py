"""The case every part runs: OpenSim's pendulum tutorial, and the scipy oracle for it."""

from __future__ import annotations

import numpy as np

from pendulum_fmu.oracle._reference import reference

TORQUE = 20.0  # N.m, held from t = 0 with the pendulum at rest at theta = 0, gravity on
STOP_TIME = 3.0  # s
STEP = 1e-3  # s
STEPS = round(STOP_TIME / STEP)
# The oracle: scipy's DOP853 at about the tightest tolerance solve_ivp accepts (100 machine
# epsilons), its steps bounded too, which takes it from about 6e-14 rad off (the tolerance alone)
# to within about 1e-15 rad of Radau's (accuracy_cost.oracle_error).
ORACLE_TOLERANCE = 3e-14
ORACLE_MAX_STEP = 1e-3  # s


def oracle_theta(step_size: float = STEP, method: str = "DOP853") -> np.ndarray:
    """Theta at t = 0, h, ..., STOP_TIME from scipy's solve_ivp (method) at rtol = atol =
    ORACLE_TOLERANCE and steps of at most ORACLE_MAX_STEP.
    """
    return reference(
        TORQUE,
        stop_time=STOP_TIME,
        step_size=step_size,
        rtol=ORACLE_TOLERANCE,
        atol=ORACLE_TOLERANCE,
        method=method,
        max_step=ORACLE_MAX_STEP,
    )["theta"]


def max_theta_error(theta: np.ndarray, step_size: float = STEP) -> float:
    return float(np.max(np.abs(theta - oracle_theta(step_size))))
