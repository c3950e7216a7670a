"""The native co-simulation loop (`_cs_loop.c`), loaded with ctypes when it was compiled.

It drives any FMI 2.0 co-simulation instance that fmpy instantiated, through the FMU's own
exported FMI functions, for a whole case in one call: optionally a restart (fmi2Reset and
initialization with new start values, as _instance.initialize does), then every step of a
schedule (fmi2SetReal, fmi2SetRealInputDerivatives, fmi2GetReal, fmi2DoStep), writing into the
caller's numpy buffers; or a chunk of restarted cases in one call (Stepper.run_cases). `pip install` (or
`pip install -e .` in a checkout) compiles it; without it `available()` is
False and callers use the Python loop in _simulate.py, which gives the same numbers bit for bit.
"""

from __future__ import annotations

import ctypes
import importlib.machinery
from collections.abc import Sequence
from functools import lru_cache
from pathlib import Path

import numpy as np

# The call that failed, by the index _cs_loop.h's CALL_ values give it: _AT_END the read after the last step,
# from _RESTART on the restart's.
CALLS = (
    "fmi2SetReal",
    "fmi2SetRealInputDerivatives",
    "fmi2GetReal",
    "fmi2DoStep",
    "fmi2GetReal",
    "fmi2Reset",
    "fmi2SetupExperiment",
    "fmi2EnterInitializationMode",
    "fmi2SetReal of the start values",
    "fmi2ExitInitializationMode",
)
_AT_END, _RESTART = 4, 5
# In the order of CsFunctions in _cs_loop.c.
_FMI_FUNCTIONS = (
    "fmi2Reset",
    "fmi2SetupExperiment",
    "fmi2EnterInitializationMode",
    "fmi2ExitInitializationMode",
    "fmi2SetReal",
    "fmi2SetRealInputDerivatives",
    "fmi2GetReal",
    "fmi2DoStep",
)


# What _cs_loop.c's cs_loop_interface() returns for the arguments this module passes.
INTERFACE = 7


def opened(interface_function: str, interface: int) -> ctypes.CDLL | None:
    """The compiled library (_cs_loop), or None when it was not built or interface_function()
    does not return interface (a build of other sources): the check of each of its parts, the
    loop's here and the oracle's Taylor stepping (oracle/_taylor_native.py).
    """
    # setup.py gives it the platform's plain extension name (_cs_loop.so, _cs_loop.pyd).
    path = Path(__file__).resolve().parent / f"_cs_loop{importlib.machinery.EXTENSION_SUFFIXES[-1]}"
    if not path.is_file():
        return None
    loaded = ctypes.CDLL(str(path))
    if not hasattr(loaded, interface_function) or getattr(loaded, interface_function)() != interface:
        return None
    return loaded


@lru_cache(maxsize=1)
def library() -> ctypes.CDLL | None:
    """The compiled loop (_cs_loop.c, _cs_batch.c) with its functions' argument types set, or None
    when it was not built (or is a stale build).
    """
    loaded = opened("cs_loop_interface", INTERFACE)
    if loaded is None:
        return None
    pointer, size = ctypes.c_void_p, ctypes.c_size_t
    signatures = {
        "cs_loop_run": (
            [pointer] * 3 + [size] + [pointer] * 3 + [size, pointer, size, size] + [pointer] * 7,
            ctypes.c_int,
        ),
        "cs_loop_run_cases": ([pointer] * 3 + [size] + [pointer] * 3 + [size] * 4 + [pointer] * 6, ctypes.c_int),
        "cs_loop_batch_pool_new": ([size], pointer),
        "cs_loop_batch_pool_free": ([pointer], None),
        "cs_loop_batch_advance": ([pointer, pointer], ctypes.c_int),
    }
    for name, (argtypes, restype) in signatures.items():
        function = getattr(loaded, name)
        function.argtypes, function.restype = argtypes, restype
    return loaded


def available() -> bool:
    """Whether the native loop (the compiled _cs_loop library) could be loaded here."""
    return library() is not None


def drives(slave) -> bool:
    """Whether the native loop can step this fmpy slave: it was compiled, and the FMU is FMI 2.0."""
    return available() and slave.fmi_version == 2


def fmi_functions(slave) -> ctypes.Array:
    """The addresses of the FMI functions of an fmpy slave's library, as CsFunctions (_cs_loop.h)
    lays them out.
    """
    return (ctypes.c_void_p * len(_FMI_FUNCTIONS))(
        *[ctypes.cast(slave.dll[name], ctypes.c_void_p) for name in _FMI_FUNCTIONS]
    )


def _checked(array: np.ndarray, shape: tuple[int, ...], dtype, what: str) -> np.ndarray:
    """array, when it is C-contiguous of that shape and type (the C code's layout); else ValueError."""
    if array.shape != shape or array.dtype != dtype or not array.flags.c_contiguous:
        raise ValueError(
            f"{what} must be a C-contiguous {np.dtype(dtype)} array of shape {shape}, got {array.dtype} {array.shape}"
        )
    return array


def _address(array: np.ndarray | None, shape: tuple[int, ...], dtype, what: str) -> int | None:
    return None if array is None else _checked(array, shape, dtype, what).ctypes.data


class Stepper:
    """The native loop bound to an fmpy FMU2Slave, its input and output value references (uint32
    arrays) and the value references of the start values a restart sets (start_references);
    run() steps it through a schedule. Binding once keeps a run's Python cost to a few
    microseconds.
    """

    def __init__(
        self,
        slave,
        input_references: np.ndarray,
        output_references: np.ndarray,
        start_references: np.ndarray | None = None,
    ):
        self.inputs, self.outputs = len(input_references), len(output_references)
        self.messages = slave.messages
        if start_references is None:
            start_references = np.empty(0, np.uint32)
        self.starts = len(start_references)
        # Kept alive for the addresses.
        self._references = input_references, output_references, start_references
        self._functions = fmi_functions(slave)
        self._first_order = np.ones(self.inputs, np.int32)  # fmi2Integer is int
        self._failed_step, self._failed_call = ctypes.c_size_t(), ctypes.c_int()
        self._tolerance = ctypes.c_double()
        self._fmu = (ctypes.addressof(self._functions), slave.component)
        self._input_references = _address(input_references, (self.inputs,), np.uint32, "input_references"), self.inputs
        self._output_references = (
            _address(output_references, (self.outputs,), np.uint32, "output_references"),
            self.outputs,
        )
        self._start_references = (
            _address(start_references, (self.starts,), np.uint32, "start_references"),
            self.starts,
        )
        # A restart's start values are copied here, whose address is bound once.
        self._start_values = np.empty(self.starts)
        self._start_values_address = self._start_values.ctypes.data
        self._failed_case = ctypes.c_size_t()
        self._case_outputs = np.empty((0, self.outputs))  # run_cases' room for one case, kept
        self._reports = ctypes.byref(self._failed_step), ctypes.byref(self._failed_call)
        loaded = library()
        if loaded is None:
            raise ValueError("the native loop is not compiled here")
        self._run, self._run_cases = loaded.cs_loop_run, loaded.cs_loop_run_cases

    def run(
        self,
        time: np.ndarray,
        inputs: np.ndarray | None,
        input_rates: np.ndarray | None,
        outputs: np.ndarray,
        start_values: Sequence[float] | None = None,
        tolerance: float | None = None,
    ) -> None:
        """time: the communication points (N + 1). inputs, input_rates: (N, inputs) values and
        first derivatives of the inputs over each step (input_rates None: held,
        fmi2SetRealInputDerivatives is not called; inputs None when there are no inputs).
        outputs: (N + 1, outputs), filled with the outputs at every point, read after the step's
        inputs were set.
        start_values: a value per start reference: restart the instance first (reset, and initialize at
        time[0] with these start values and the relative tolerance, None for the FMU's own), or
        None when it is initialized already. A failing call raises the slave's MessageLog error,
        with the FMU's messages and the time of the failing step, or FmuError("initialization
        failed: ...") as _instance.initialize does.
        """
        steps = len(time) - 1
        if inputs is None and self.inputs:
            raise ValueError(f"inputs must be given: the stepper has {self.inputs}")
        if start_values is not None:
            if len(start_values) != self.starts:
                raise ValueError(f"start_values must be {self.starts} values, got {len(start_values)}")
            self._start_values[:] = start_values
        if tolerance is not None:
            self._tolerance.value = tolerance
        status = self._run(
            *self._fmu,
            *self._start_references,
            None if start_values is None else self._start_values_address,
            None if tolerance is None else ctypes.addressof(self._tolerance),
            *self._input_references,
            *self._output_references,
            steps,
            _address(time, (steps + 1,), np.float64, "time"),
            _address(inputs, (steps, self.inputs), np.float64, "inputs"),
            None if input_rates is None else self._first_order.ctypes.data,
            _address(input_rates, (steps, self.inputs), np.float64, "input_rates"),
            _address(outputs, (steps + 1, self.outputs), np.float64, "outputs"),
            *self._reports,
        )
        if status > 1:
            raise self._error(status, time)

    def run_cases(
        self, time: np.ndarray, start_values: np.ndarray, outputs: np.ndarray, tolerance: float | None = None
    ) -> list[str]:
        """Run cases, each a restart with its own start values and no input set, in one call
        into the native loop (one more after each case the FMU refuses).

        Parameters
        ----------
        time : numpy.ndarray
            The communication points (N + 1), shared by every case.
        start_values : numpy.ndarray
            (cases, start references), C-contiguous float64: a row per case.
        outputs : numpy.ndarray
            (outputs, cases, N + 1), C-contiguous float64, filled with each case's outputs at
            every point: outputs[j] is output j of every case, one contiguous series (a table
            column without a copy); a refused case's values are NaN.
        tolerance : float, optional
            The relative tolerance of every restart; None for the FMU's own.

        Returns
        -------
        list of str
            Per case "" when it ran, else why the FMU refused it: the message run() raises for
            the same case.

        Examples
        --------
        >>> messages = stepper.run_cases(points, start_values, outputs)  # doctest: +SKIP
        """
        cases, points = len(start_values), len(time)
        start_values = _checked(start_values, (cases, self.starts), np.float64, "start_values")
        outputs = _checked(outputs, (self.outputs, cases, points), np.float64, "outputs")
        if self._case_outputs.shape != (points, self.outputs):
            self._case_outputs = np.empty((points, self.outputs))
        if tolerance is not None:
            self._tolerance.value = tolerance
        messages, first = [""] * cases, 0
        while first < cases:
            self.messages.lines.clear()  # so that a refusal's message is its case's own
            status = self._run_cases(
                *self._fmu,
                *self._start_references,
                start_values.ctypes.data,
                None if tolerance is None else ctypes.addressof(self._tolerance),
                *self._output_references,
                cases,
                first,
                points - 1,
                _address(time, (points,), np.float64, "time"),
                self._case_outputs.ctypes.data,
                outputs.ctypes.data,
                ctypes.byref(self._failed_case),
                *self._reports,
            )
            if status <= 1:
                break
            refused = self._failed_case.value
            messages[refused] = str(self._error(status, time))
            outputs[:, refused] = np.nan
            first = refused + 1
        self.messages.lines.clear()
        return messages

    def _error(self, status: int, time: np.ndarray) -> Exception:
        """The error of a run that failed with status: the slave's MessageLog error with the FMU's
        messages, the failing call and the time of its step, or FmuError("initialization failed:
        ...") for a restart's call, as _instance.initialize raises.
        """
        call = self._failed_call.value
        if call >= _RESTART:
            return self.messages.initialization_error(f"{CALLS[call]} failed")
        where = "at the end" if call == _AT_END else f"at t = {time[self._failed_step.value]:.17g}"
        return self.messages.error(status, f"{CALLS[call]} {where}")
