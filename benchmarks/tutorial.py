"""The case every part runs: OpenSim's pendulum tutorial, and the scipy oracle for it."""

from __future__ import annotations

import numpy as np

from pendulum_fmu.reference import reference

TORQUE = 20.0     # N.m, held from t = 0 with the pendulum at rest at theta = 0, gravity on
STOP_TIME = 3.0   # s
STEP = 1e-3       # s
STEPS = round(STOP_TIME / STEP)
ORACLE_TOLERANCE = 1e-13


def oracle_theta(step_size: float = STEP, tolerance: float = ORACLE_TOLERANCE) -> np.ndarray:
    """theta at t = 0, h, ..., STOP_TIME from scipy's DOP853 at rtol = atol = tolerance."""
    return reference(TORQUE, stop_time=STOP_TIME, step_size=step_size, rtol=tolerance,
                     atol=tolerance)["theta"]


def max_theta_error(theta: np.ndarray, step_size: float = STEP) -> float:
    return float(np.max(np.abs(theta - oracle_theta(step_size))))
