"""The one result format: a numpy structured array with a row per communication point.

Row k holds theta and omega at time[k], the torque applied from time[k] on (the step's start
value), and alpha, the acceleration just after time[k] under that torque. The last row repeats
the last step's torque at its end. Fields are SI: s, N.m, rad, rad/s, rad/s2.
"""

from __future__ import annotations

import numpy as np

FIELDS = ("time", "torque", "theta", "omega", "alpha")
UNITS = {"time": "s", "torque": "N.m", "theta": "rad", "omega": "rad/s", "alpha": "rad/s2"}
DTYPE = np.dtype([(name, "f8") for name in FIELDS])


def empty(n_points: int) -> np.ndarray:
    return np.zeros(n_points, dtype=DTYPE)

