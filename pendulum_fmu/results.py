"""The one result format: a numpy structured array with a row per communication point.

Row k holds theta and omega at time[k], the torque applied from time[k] on (the step's start
value), and alpha, the acceleration just after time[k] under that torque. The last row repeats
the last step's torque at its end. Fields are SI: s, N.m, rad, rad/s, rad/s2.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .atomic_files import replacing

FIELDS = ("time", "torque", "theta", "omega", "alpha")
UNITS = {"time": "s", "torque": "N.m", "theta": "rad", "omega": "rad/s", "alpha": "rad/s2"}
DTYPE = np.dtype([(name, "f8") for name in FIELDS])


def empty(n_points: int) -> np.ndarray:
    return np.zeros(n_points, dtype=DTYPE)



def write_csv(run: np.ndarray, path: str | os.PathLike) -> Path:
    """Write a result as CSV: a header of the fields, then a row per communication point with 17
    significant digits, so the numbers read back as the same doubles.

    Parameters
    ----------
    run : numpy.ndarray
        A result array (see the module's doc).
    path : str or os.PathLike
        The file to write; it appears whole or not at all.

    Returns
    -------
    Path
        path.

    Raises
    ------
    CannotWrite
        path cannot be written.
    """
    with replacing(path) as file:
        np.savetxt(file, run.view(np.float64).reshape(len(run), -1), delimiter=",",
                   header=",".join(FIELDS), comments="", fmt="%.17g")
    return Path(path)
