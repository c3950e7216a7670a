"""The oracle's Taylor stepping in C (`_taylor_native.c`), loaded with ctypes when it was compiled.

integrate_runs integrates a window's runs of linear torque (what integrate_window loops over) a
budget of Taylor steps per call, carrying theta and omega across, as _taylor.integrate_piece does one run
at a time in Python, and gives the same numbers bit for bit: the C code is that function
transcribed, operation for operation, built without FMA contraction. With a torque that changes
every communication step a run is one step of a millisecond, and a Python call per run was most
of a judge's time. The C file is compiled into the native loop's library (pendulum_fmu/fmu/_cs_loop,
built by `pip install`, or `pip install -e .` in a checkout) but shares no code with it or with
the FMU's integrator (fmu_src/); without it `available()` is False and integrate_window calls
integrate_piece, which stays the readable reference (tests/test_taylor_native.py holds the two
to the same bits; monkeypatching `available` to return False forces the Python path).
"""

from __future__ import annotations

import ctypes
from collections.abc import Callable
from functools import lru_cache

import numpy as np

from ..fmu._native_loop import opened
from ._taylor import Diverged, order_limit

# What _taylor_native.c's cs_loop_taylor_interface() returns for the arguments this module passes.
INTERFACE = 2
# Taylor steps per call, about 0.1 s of them: the progress bar advances and Ctrl-C is heard
# between calls, within a run too (a held torque is one run, up to the oracle's 10,000,000 steps).
STEPS_PER_CALL = 1 << 17
# _taylor_native.c's TAYLOR_PAUSED: the steps of a call taken, the window not yet done.
_PAUSED = 4
# _taylor_native.c's TAYLOR_ codes, as integrate_piece words them; the underflow's takes the time.
_FAILURES = {
    1: "a Taylor coefficient is not finite",
    2: "the step needed underflows at t = {time:g} s",
    3: "the state is not finite",
}


class RunDiverged(Diverged):
    """Diverged, in the run that starts at `start` (s)."""

    def __init__(self, message: str, start: float):
        super().__init__(message)
        self.start = start


@lru_cache(maxsize=1)
def library() -> ctypes.CDLL | None:
    """The compiled library holding _taylor_native.c, its function's argument types set, or None
    when it was not built (or is a build of older sources).
    """
    # The native loop's library, which this file joins.
    loaded = opened("cs_loop_taylor_interface", INTERFACE)
    if loaded is None:
        return None
    pointer, size = ctypes.c_void_p, ctypes.c_size_t
    window = loaded.cs_loop_taylor_window
    window.argtypes = [pointer, pointer, size, *[pointer] * 7, ctypes.c_int, ctypes.c_long, pointer, pointer, pointer]
    window.restype = ctypes.c_int
    return loaded


def available() -> bool:
    """Whether the native Taylor stepping could be loaded here."""
    return library() is not None


def integrate_runs(
    runs: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    bounds: np.ndarray,
    reports: np.ndarray,
    state: tuple[float, float],
    model: tuple[float, float, float],
    tolerance: tuple[float, float],
    on_step: Callable[[float], None] | None = None,
) -> tuple[np.ndarray, np.ndarray, float, float]:
    """Theta and omega at each report, and at the last run's end, integrating the runs one after
    another from state; integrate_piece's numbers, run by run.

    Parameters
    ----------
    runs : (numpy.ndarray, numpy.ndarray, numpy.ndarray, numpy.ndarray)
        Each run's start and end (s), torque at its start (N.m) and rate (N.m/s).
    bounds : numpy.ndarray
        len(runs) + 1 indices into reports: run r's are reports[bounds[r]:bounds[r + 1]].
    reports : numpy.ndarray
        The times to report, sorted; each is clipped into its run's span.
    state : (float, float)
        theta and omega at the first run's start.
    model, tolerance
        As integrate_piece takes them.
    on_step : callable, optional
        Called with the time reached after each call's STEPS_PER_CALL steps, and at the end
        (a progress bar's).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray, float, float)
        theta and omega at each report; theta and omega at the last run's end.

    Raises
    ------
    RunDiverged
        As integrate_piece raises Diverged, with the start of the run it failed in.
    """
    loaded = library()
    if loaded is None:
        raise ValueError("the native Taylor stepping is not compiled here")
    starts, ends, u0s, rates = (np.ascontiguousarray(column, dtype=np.float64) for column in runs)
    bounds = np.ascontiguousarray(bounds, dtype=np.int64)
    reports = np.ascontiguousarray(reports, dtype=np.float64)
    count = len(starts)
    if not (len(ends) == len(u0s) == len(rates) == count and len(bounds) == count + 1):
        raise ValueError(f"{count} runs need as many ends, torques and rates and {count + 1} bounds")
    if count and not (bounds[0] == 0 and bounds[-1] == len(reports) and np.all(bounds[1:] >= bounds[:-1])):
        raise ValueError("bounds must rise from 0 to the number of reports")
    rtol, atol = tolerance
    constants = np.array([*model, rtol, atol], dtype=np.float64)
    # theta, omega and the time they hold at; the run and report the integration stands at.
    carried = np.array([*state, starts[0] if count else 0.0], dtype=np.float64)
    position = np.zeros(2, dtype=np.int64)
    thetas, omegas = np.empty(len(reports)), np.empty(len(reports))
    failed_time = ctypes.c_double()
    addresses = [array.ctypes.data for array in (starts, ends, u0s, rates, bounds, reports, constants)]
    status = _PAUSED
    while count and status == _PAUSED:
        status = loaded.cs_loop_taylor_window(
            carried.ctypes.data,
            position.ctypes.data,
            count,
            *addresses,
            order_limit(min(rtol, atol)),
            STEPS_PER_CALL,
            thetas.ctypes.data,
            omegas.ctypes.data,
            ctypes.byref(failed_time),
        )
        if status not in (0, _PAUSED):
            raise RunDiverged(_FAILURES[status].format(time=failed_time.value), float(starts[position[0]]))
        if on_step is not None:
            on_step(float(carried[2]))
    return thetas, omegas, float(carried[0]), float(carried[1])
