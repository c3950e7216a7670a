"""A batch of FMI 2.0 co-simulation instances of one FMU, each advanced by one communication step
(or restarted) per call: what a vectorised environment steps.

FmuBatch holds N instances of one loaded FMU (the first made by the package's own instantiation,
the others siblings sharing its loaded library, _instance.sibling) and numpy buffers with a row per
instance: the start values a restart sets, the inputs of the next step, whether each instance
steps, restarts or holds, and the outputs read after. advance() runs every instance through the
native loop's batch (_cs_batch.c) in one call, on a pool of threads made once; without the native
loop, the same calls in the same order in Python (the readable reference, the same numbers bit for
bit).
"""

from __future__ import annotations

import ctypes
import weakref
from collections.abc import Sequence

import numpy as np

from .._errors import InvalidInput
from . import _native_loop as cs_loop
from ._instance import FmuError, FmuInstance, instantiated, sibling
from ._model import FmuModel

# What advance() does to an instance, by its row of FmuBatch.modes (_cs_batch.c's BATCH_ values).
STEP, RESTART, HOLD = 0, 1, 2
# The calls of a restart and a step, by _cs_loop.h's CALL_ values.
(
    _SET_REAL,
    _GET_REAL,
    _DO_STEP,
    _RESET,
    _SETUP_EXPERIMENT,
    _ENTER_INITIALIZATION,
    _SET_START_VALUES,
    _EXIT_INITIALIZATION,
) = (0, 2, 3, 5, 6, 7, 8, 9)


class _CsBatch(ctypes.Structure):
    # CsBatch of _cs_batch.c, field for field.
    _fields_ = [
        ("fmi", ctypes.c_void_p),
        ("components", ctypes.c_void_p),
        ("n_instances", ctypes.c_size_t),
        ("start_references", ctypes.c_void_p),
        ("n_start", ctypes.c_size_t),
        ("start_values", ctypes.c_void_p),
        ("modes", ctypes.c_void_p),
        ("tolerance", ctypes.c_void_p),
        ("start_time", ctypes.c_double),
        ("input_references", ctypes.c_void_p),
        ("n_inputs", ctypes.c_size_t),
        ("inputs", ctypes.c_void_p),
        ("output_references", ctypes.c_void_p),
        ("n_outputs", ctypes.c_size_t),
        ("outputs", ctypes.c_void_p),
        ("steps", ctypes.c_void_p),
        ("step_size", ctypes.c_double),
        ("statuses", ctypes.c_void_p),
        ("failed_calls", ctypes.c_void_p),
    ]


class FmuBatch:
    """N instances of one FMI 2.0 FMU, each restarted or advanced by one communication step per
    call of advance().

    Parameters
    ----------
    model : FmuModel
        The FMU (FMI 2.0).
    size : int
        The number of instances.
    start_names, input_names, output_names : sequence of str
        The variables a restart sets (in initialization mode), a step sets before it steps, and
        advance() reads after.
    step_size : float
        The communication step, in s.
    tolerance : float, optional
        The relative tolerance each restart hands the FMU; None for the FMU's own.
    threads : int, optional
        The threads advance() runs on, the caller's included.
    native : bool, optional
        Whether to use the native loop; None: where it was compiled.

    Attributes
    ----------
    start_values : numpy.ndarray
        (size, len(start_names)): row i is what instance i's next restart sets.
    inputs : numpy.ndarray
        (size, len(input_names)): row i is what instance i's next step sets.
    modes : numpy.ndarray
        (size,) uint8: what the next advance() does to each instance: STEP (0, the default),
        RESTART at its start values, or HOLD (nothing but read its outputs).
    outputs : numpy.ndarray
        (size, len(output_names)): read after each instance's restart or step.
    steps : numpy.ndarray
        (size,) uint64: each instance's steps since its restart; it stands at time steps * step_size.
    """

    def __init__(
        self,
        model: FmuModel,
        size: int,
        *,
        start_names: Sequence[str],
        input_names: Sequence[str],
        output_names: Sequence[str],
        step_size: float,
        tolerance: float | None = None,
        threads: int = 1,
        native: bool | None = None,
    ):
        if model.fmi_version != 2:
            raise InvalidInput(f"{model.path}: a batch runs FMI 2.0 FMUs, this one is FMI {model.fmi_version}")
        self.size, self.step_size, self.tolerance = size, float(step_size), tolerance
        references = model.value_references
        self._references = [
            np.array([references[n] for n in names], np.uint32) for names in (start_names, input_names, output_names)
        ]
        self.start_values = np.zeros((size, len(start_names)))
        self.inputs = np.zeros((size, len(input_names)))
        self.modes = np.full(size, RESTART, np.uint8)
        self.outputs = np.full((size, len(output_names)), np.nan)
        self.steps = np.zeros(size, np.uint64)
        self._statuses = np.zeros(size, np.intc)
        self._failed_calls = np.zeros(size, np.intc)
        self.instances: list[FmuInstance] = []
        # Every instance freed, the first (which holds the loaded library) last, even when the
        # batch is dropped without close().
        self._finalizer = weakref.finalize(self, _free, self.instances)
        lead = instantiated(model, "env-0")
        self.instances.append(lead)
        self.instances.extend(sibling(lead, f"env-{i}") for i in range(1, size))
        self._native = cs_loop.library() if native is None or native else None
        if native and self._native is None:
            raise InvalidInput("the native loop is not compiled here: reinstall the package (pip install .)")
        if self._native is not None:
            self._bind(self._native, threads)

    def _bind(self, library: ctypes.CDLL, threads: int) -> None:
        self._functions = cs_loop.fmi_functions(self.instances[0])
        self._components = (ctypes.c_void_p * self.size)(*[instance.component for instance in self.instances])
        self._tolerance = ctypes.c_double(self.tolerance if self.tolerance is not None else 0.0)
        start, inputs, outputs = self._references
        self._batch = _CsBatch(
            ctypes.addressof(self._functions),
            ctypes.addressof(self._components),
            self.size,
            start.ctypes.data,
            len(start),
            self.start_values.ctypes.data,
            self.modes.ctypes.data,
            None if self.tolerance is None else ctypes.addressof(self._tolerance),
            0.0,
            inputs.ctypes.data,
            len(inputs),
            self.inputs.ctypes.data,
            outputs.ctypes.data,
            len(outputs),
            self.outputs.ctypes.data,
            self.steps.ctypes.data,
            self.step_size,
            self._statuses.ctypes.data,
            self._failed_calls.ctypes.data,
        )
        self._batch_address = ctypes.addressof(self._batch)
        pool = library.cs_loop_batch_pool_new(threads)
        if not pool:
            raise FmuError(f"the system refused {threads} threads for the batch: ask for fewer")
        self._pool = pool
        self._finalizer.detach()
        self._finalizer = weakref.finalize(self, _free, self.instances, library, pool)

    def advance(self) -> None:
        """Step, restart or hold each instance as `modes` says, then read every instance's
        outputs; `modes` is set back to STEP.

        Raises
        ------
        FmuError
            An FMI call failed; the message names the instance, the call and what the FMU
            logged. The instances before it in its thread's slice have advanced.
        """
        if self._native is not None:
            worst = self._native.cs_loop_batch_advance(self._pool, self._batch_address)
        else:
            worst = self._advance_python()
        self.modes.fill(STEP)
        if worst > 1:
            failed = int(np.flatnonzero(self._statuses > 1)[0])
            call = int(self._failed_calls[failed])
            messages = self.instances[failed].messages
            where = f"instance {failed} of {self.size}: " if self.size > 1 else ""
            if call >= _RESET:
                raise messages.initialization_error(f"{where}{cs_loop.CALLS[call]} failed")
            status = int(self._statuses[failed])
            time = float(self.steps[failed]) * self.step_size
            raise messages.error(status, f"{where}{cs_loop.CALLS[call]} at t = {time:.17g}")

    def _advance_python(self) -> int:
        """advance() through fmpy's calls, in the order of _cs_batch.c; the worst status."""
        start, inputs, outputs = (list(map(int, references)) for references in self._references)
        for i, instance in enumerate(self.instances):
            call = _RESET if self.modes[i] == RESTART else _SET_REAL
            try:
                if self.modes[i] == RESTART:
                    instance.reset()
                    call = _SETUP_EXPERIMENT
                    instance.setupExperiment(tolerance=self.tolerance, startTime=0.0)
                    call = _ENTER_INITIALIZATION
                    instance.enterInitializationMode()
                    call = _SET_START_VALUES
                    instance.setReal(start, list(self.start_values[i]))
                    call = _EXIT_INITIALIZATION
                    instance.exitInitializationMode()
                    self.steps[i] = 0
                elif self.modes[i] == STEP:
                    instance.setReal(inputs, list(self.inputs[i]))
                    call = _DO_STEP
                    time = float(self.steps[i]) * self.step_size
                    instance.doStep(currentCommunicationPoint=time, communicationStepSize=self.step_size)
                    self.steps[i] += 1
                call = _GET_REAL
                self.outputs[i] = instance.getReal(outputs)
            except Exception as error:  # fmpy's, for a status above fmi2Warning
                self._statuses[i], self._failed_calls[i] = getattr(error, "status", 3), call
                return int(self._statuses[i])
            self._statuses[i] = 0
        return 0

    def close(self) -> None:
        """Free every instance (and the threads); the batch is unusable after."""
        self._finalizer()


def _free(instances: list[FmuInstance], library=None, pool=None) -> None:
    if pool is not None:
        library.cs_loop_batch_pool_free(pool)
    for instance in reversed(instances[1:]):
        instance.fmi2FreeInstance(instance.component)
    if instances:
        instances[0].freeInstance()
    instances.clear()
