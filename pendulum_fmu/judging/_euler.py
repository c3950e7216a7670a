"""Integration error's stepping: the equation of motion stepped once per communication step,
holding each step's start torque, by explicit Euler or semi-implicit Euler (the new omega moves
theta), as a tool with a fixed-step integrator steps it.

euler_steps runs in C (`_euler_native.c`, compiled into the native loop's library, loaded with
ctypes) where it was built, else in Python (`_python_steps`, the readable definition); the two give
the same numbers bit for bit (tests/test_euler.py).
"""

from __future__ import annotations

import ctypes
import math
from functools import lru_cache

import numpy as np

from ..fmu._native_loop import opened

# What _euler_native.c's cs_loop_euler_interface() returns for the arguments this module passes.
INTERFACE = 1


@lru_cache(maxsize=1)
def library() -> ctypes.CDLL | None:
    """The compiled library holding _euler_native.c, its function's argument types set, or None."""
    loaded = opened("cs_loop_euler_interface", INTERFACE)
    if loaded is None:
        return None
    pointer = ctypes.c_void_p
    loaded.cs_loop_euler_steps.argtypes = [pointer] * 3 + [ctypes.c_size_t, pointer, ctypes.c_int, pointer, pointer]
    loaded.cs_loop_euler_steps.restype = None
    return loaded


def euler_steps(
    state: tuple[float, float],
    step_sizes: np.ndarray,
    torques: np.ndarray,
    model: tuple[float, float, float],
    semi_implicit: bool,
) -> tuple[np.ndarray, np.ndarray]:
    """Theta and omega at each step's start and at the last step's end.

    Parameters
    ----------
    state : (float, float)
        theta (rad) and omega (rad/s) at the first step's start.
    step_sizes, torques : numpy.ndarray
        Each step's length (s) and the torque it holds (N.m).
    model : (float, float, float)
        mass*gravity*length (N.m), damping (N.m.s/rad) and 1/total inertia (1/(kg.m^2)).
    semi_implicit : bool
        Semi-implicit Euler (omega first, then theta with the new omega), else explicit.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        theta and omega, len(step_sizes) + 1 values each.
    """
    step_sizes = np.ascontiguousarray(step_sizes, dtype=np.float64)
    torques = np.ascontiguousarray(torques, dtype=np.float64)
    if len(step_sizes) != len(torques):
        raise ValueError(f"{len(step_sizes)} step sizes need as many torques, not {len(torques)}")
    loaded = library()
    if loaded is None:
        return _python_steps(state, step_sizes, torques, model, semi_implicit)
    carried = np.array(state, dtype=np.float64)
    constants = np.array(model, dtype=np.float64)
    thetas, omegas = np.empty(len(step_sizes) + 1), np.empty(len(step_sizes) + 1)
    loaded.cs_loop_euler_steps(
        carried.ctypes.data,
        step_sizes.ctypes.data,
        torques.ctypes.data,
        len(step_sizes),
        constants.ctypes.data,
        int(semi_implicit),
        thetas.ctypes.data,
        omegas.ctypes.data,
    )
    return thetas, omegas


def _python_steps(
    state: tuple[float, float],
    step_sizes: np.ndarray,
    torques: np.ndarray,
    model: tuple[float, float, float],
    semi_implicit: bool,
) -> tuple[np.ndarray, np.ndarray]:
    """euler_steps in Python: the equation written out with math.sin (a step through numpy's
    scalars costs three times as much).
    """
    theta, omega = state
    gravity_moment, damping, inverse_inertia = model
    thetas, omegas = np.empty(len(step_sizes) + 1), np.empty(len(step_sizes) + 1)
    k = 0
    for h, u in zip(step_sizes.tolist(), torques.tolist(), strict=True):
        thetas[k], omegas[k] = theta, omega
        alpha = (u - gravity_moment * math.sin(theta) - damping * omega) * inverse_inertia
        if semi_implicit:
            omega += h * alpha
            theta += h * omega
        else:
            theta, omega = theta + h * omega, omega + h * alpha
        k += 1
    thetas[k], omegas[k] = theta, omega
    return thetas, omegas
