"""The native co-simulation loop (`_cs_loop.c`), loaded with ctypes when it was compiled.

It drives any FMI 2.0 co-simulation instance that fmpy instantiated, through the FMU's own
exported fmi2SetReal, fmi2SetRealInputDerivatives, fmi2GetReal and fmi2DoStep, for a whole
schedule in one call, writing into the caller's numpy buffers. `pip install` (or
`python setup.py build_ext --inplace` in a checkout) compiles it; without it `available()` is
False and callers use the Python loop in simulate.py, which gives the same numbers bit for bit.
"""

from __future__ import annotations

import ctypes
import importlib.machinery
from functools import lru_cache
from pathlib import Path

import numpy as np

# The call that failed, by the index _cs_loop.c reports.
_CALLS = ("fmi2SetReal", "fmi2SetRealInputDerivatives", "fmi2GetReal", "fmi2DoStep",
          "fmi2GetReal of the inputs", "fmi2GetReal")
_FMI_FUNCTIONS = ("fmi2SetReal", "fmi2SetRealInputDerivatives", "fmi2GetReal", "fmi2DoStep")


@lru_cache(maxsize=1)
def _library():
    """The compiled loop's run function, or None when it was not built."""
    here = Path(__file__).resolve().parent
    for suffix in importlib.machinery.EXTENSION_SUFFIXES:
        path = here / f"_cs_loop{suffix}"
        if path.is_file():
            run = ctypes.CDLL(str(path)).cs_loop_run
            pointer, size = ctypes.c_void_p, ctypes.c_size_t
            run.argtypes = [pointer] * 5 + [pointer, size, pointer, size, size] + [pointer] * 8
            run.restype = ctypes.c_int
            return run
    return None


def available() -> bool:
    return _library() is not None


def _address(array: np.ndarray | None, shape: tuple[int, ...], dtype, what: str) -> int | None:
    if array is None:
        return None
    if array.shape != shape or array.dtype != dtype or not array.flags.c_contiguous:
        raise ValueError(f"{what} must be a C-contiguous {np.dtype(dtype)} array of shape {shape}, "
                         f"got {array.dtype} {array.shape}")
    return array.ctypes.data


def run(slave, input_references: np.ndarray, output_references: np.ndarray, time: np.ndarray,
        inputs: np.ndarray, input_rates: np.ndarray | None, outputs: np.ndarray,
        final_inputs: np.ndarray | None = None) -> None:
    """Step an initialized fmpy FMU2Slave through the communication points `time` (N + 1).

    inputs, input_rates: (N, inputs) values and first derivatives of the inputs over each step
    (input_rates None: held, fmi2SetRealInputDerivatives is not called). outputs: (N + 1,
    outputs), filled with the outputs at every point, read after the step's inputs were set.
    final_inputs: (inputs,) the inputs read back after the last step. References are uint32
    arrays. A failing call raises the error of slave.messages (simulate.MessageLog), with the
    FMU's messages and the time of the failing step.
    """
    steps = len(time) - 1
    n_in, n_out = len(input_references), len(output_references)
    dll = slave.dll
    functions = [ctypes.cast(dll[name], ctypes.c_void_p) for name in _FMI_FUNCTIONS]
    failed_step, failed_call = ctypes.c_size_t(), ctypes.c_int()
    first_order = None if input_rates is None else np.ones(n_in, np.int32)  # fmi2Integer is int
    status = _library()(
        *functions, slave.component,
        _address(input_references, (n_in,), np.uint32, "input_references"), n_in,
        _address(output_references, (n_out,), np.uint32, "output_references"), n_out,
        steps, _address(time, (steps + 1,), np.float64, "time"),
        _address(inputs, (steps, n_in), np.float64, "inputs"),
        _address(first_order, (n_in,), np.int32, "input orders"),
        _address(input_rates, (steps, n_in), np.float64, "input_rates"),
        _address(outputs, (steps + 1, n_out), np.float64, "outputs"),
        _address(final_inputs, (n_in,), np.float64, "final_inputs"),
        ctypes.byref(failed_step), ctypes.byref(failed_call))
    if status > 1:
        call = _CALLS[failed_call.value]
        where = "at the end" if failed_call.value >= 4 else f"at t = {time[failed_step.value]:.17g}"
        raise slave.messages.error(status, f"{call} {where}")
