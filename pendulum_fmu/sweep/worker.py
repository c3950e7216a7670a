"""What a dask worker does with a chunk of cases: simulate each, write the chunk's two parts.

A worker thread steps its cases through its thread's FMU instance (simulate.simulator),
restarted between cases, the whole chunk in one call into the native loop (_native_loop.py), into one
preallocated (outputs, cases, points) array, whose series are the trajectories table's columns as
they are; the FMI 3.0 FMU, or a machine without the native
loop, runs each case through fmpy's calls.
"""

from __future__ import annotations

import logging
import threading
import time
from dataclasses import dataclass

import numpy as np

from ..fmu import _native_loop as cs_loop
from ..fmu._instance import FmuError, initialize
from ..fmu._model import START_VALUES
from ..fmu._parameters import value_reference
from ..fmu._simulate import run_schedule_python, simulator
from ..signals._time_grid import communication_points
from ..signals._torque_schedule import TorqueSchedule
from .store import SUMMARIES, Store

# A dask worker's log: what a worker woken after its run ended did with its chunk.
_log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Task:
    """What every chunk of a study shares; shipped to the workers with each chunk."""

    fmu: str
    store: Store
    stop_time: float
    step_size: float
    outputs: tuple[str, ...]
    stride: int  # keep every stride-th communication point (and the last)
    run: str  # the token of the run: the parts are staged under it (see store.py)

    def tables(self) -> tuple[str, ...]:
        """The tables a chunk writes a part of, in the order they are committed."""
        return ("trajectories", "cases") if self.outputs else ("cases",)


class Runner:
    """Cases through this thread's Simulator of the FMU (simulate.simulator), whose instance is
    restarted (reset and initialized again) for each: instantiating costs about a hundred times
    what a restart costs.

    A case is the start values of a restart: the parameters, theta and omega, and the torque,
    which then stays as it was set, so the native loop sets no input per step.
    """

    def __init__(self, fmu_simulator):
        self.simulator, fmu = fmu_simulator, fmu_simulator.slave.model
        # What it records of every case: the FMU's outputs, which a Study of it chooses among.
        self.outputs = fmu.outputs
        self.defaults = {**fmu_simulator.defaults, "theta": 0.0, "omega": 0.0, "torque": 0.0}
        start_references = np.array([value_reference(n, fmu) for n in self.defaults], np.uint32)
        outputs = np.array([value_reference(name, fmu) for name in self.outputs], np.uint32)
        self.stepper = (
            cs_loop.Stepper(fmu_simulator.slave, np.empty(0, np.uint32), outputs, start_references)
            if fmu_simulator.stepper is not None
            else None
        )

    def start_values(self, values: dict[str, np.ndarray], count: int) -> np.ndarray:
        """(count, start values) of the cases given as {name: column}, the defaults elsewhere."""
        given = {START_VALUES.get(name, name): column for name, column in values.items()}
        return np.column_stack(
            [np.broadcast_to(given.get(name, default), count) for name, default in self.defaults.items()]
        ).astype(float)

    def run_cases(self, start_values: np.ndarray, points: np.ndarray, outputs: np.ndarray) -> list[str]:
        """The FMU's outputs (self.outputs) of each case (a row of start_values) at every
        communication point into outputs (outputs x cases x points). Returns per case "" or why
        the FMU refused it (its values then NaN); the next case's restart starts from fmi2Reset,
        whatever state the refusal left.
        """
        if self.stepper is not None:
            return self.stepper.run_cases(points, start_values, outputs)
        messages = [""] * len(start_values)
        for case, values in enumerate(start_values.tolist()):
            self.simulator.slave.messages.lines.clear()
            try:
                self._run_python(dict(zip(self.defaults, values, strict=False)), points, outputs[:, case])
            except FmuError as error:
                messages[case] = str(error)
                outputs[:, case] = np.nan
        return messages

    def _run_python(self, start: dict[str, float], points: np.ndarray, outputs: np.ndarray) -> None:
        """The same case through fmpy's calls: FMI 3.0 FMUs, or no native loop."""
        torque, theta0, omega0 = start.pop("torque"), start.pop("theta"), start.pop("omega")
        slave = self.simulator.slave
        slave.reset()
        initialize(slave, parameters=start, theta0=theta0, omega0=omega0, start_time=float(points[0]))
        plan = TorqueSchedule(
            time=points, torque=np.full(len(points) - 1, torque), torque_rate=np.zeros(len(points) - 1)
        )
        run = run_schedule_python(slave, plan)
        outputs[:] = [run[name] for name in self.outputs]


_runners = threading.local()


def _runner(fmu: str) -> Runner:
    """The runner of this thread for the FMU file, over its Simulator (new when the file changed)."""
    fmu_simulator = simulator(fmu)
    current = getattr(_runners, "runner", None)
    if current is None or current.simulator is not fmu_simulator:
        current = _runners.runner = Runner(fmu_simulator)
    return current


def kept_points(points: int, stride: int) -> np.ndarray:
    """Indices of the communication points written: every stride-th, and the last."""
    every = np.arange(0, points, stride)
    return every if every[-1] == points - 1 else np.append(every, points - 1)


def run_chunk(index: int, first: int, values: dict[str, np.ndarray], task: Task) -> tuple:
    """Simulate a chunk of cases on a worker and write its parts, staged for the run's client to
    commit.

    values: the chunk's cases, one array per name; first: the number of its first case.
    Returns (index, cases, failed, bytes written, CPU seconds of this thread, of which stepping).
    """
    cpu = time.thread_time()
    points = communication_points(0.0, task.stop_time, task.step_size)
    count = len(next(iter(values.values())))
    runner = _runner(task.fmu)
    recorded = _scratch("recorded", (len(runner.outputs), count, len(points)), np.float64)
    start_values = runner.start_values(values, count)
    stepping = time.thread_time()
    messages = runner.run_cases(start_values, points, recorded)
    stepping = time.thread_time() - stepping
    ok = np.array([not message for message in messages], bool)
    numbers = first + np.arange(count)
    written = 0
    try:
        if task.outputs:
            keep = kept_points(len(points), task.stride)
            kept = recorded if ok.all() else recorded[:, ok]  # a copy only when a case failed
            if len(keep) < len(points):
                kept = kept[:, :, keep]
            # Each output's series of the chunk is contiguous: pyarrow takes its buffer as it is.
            written += task.store.write_table(
                "trajectories",
                index,
                {
                    "case": _repeated(numbers[ok], len(keep)),
                    "time": _tiled(points[keep], int(ok.sum())),
                    **{name: kept[runner.outputs.index(name)].reshape(-1) for name in task.outputs},
                },
                task.run,
                series=("time", *task.outputs),
            )
        # The summaries by name; NaN (never zeros) for a variable the FMU does not output.
        not_output = np.full((count, 1), np.nan)
        theta, omega, alpha = (
            recorded[runner.outputs.index(name)] if name in runner.outputs else not_output
            for name in ("theta", "omega", "alpha")
        )
        # max |theta| as |max(max, -min)|: two passes and no temporary the size of the chunk (the
        # outer abs only for theta all -0.0, where abs first gives 0.0).
        summaries = [
            theta[:, -1],
            omega[:, -1],
            alpha[:, -1],
            np.abs(np.maximum(theta.max(axis=1), -theta.min(axis=1))),
        ]
        written += task.store.write_table(
            "cases",
            index,
            {
                "case": numbers,
                **values,
                **dict(zip(SUMMARIES, summaries, strict=False)),
                "status": np.where(ok, "ok", "failed").tolist(),
                "message": messages,
            },
            task.run,
        )
    except FileNotFoundError:  # no folder to stage into: a study written apart, moved since
        if task.store.is_live(task.run):
            raise
    if not task.store.is_live(task.run):
        # Woken after its run ended (stopped, cut off): the run has removed, or will never see,
        # what the worker staged, so the worker removes it (store.py says why nothing stays).
        task.store.discard_staged(index, task.run, task.tables())
        _log.warning("chunk %d of run %s not kept: the run ended while it ran", index, task.run)
        written = 0
    return index, count, count - int(ok.sum()), written, time.thread_time() - cpu, stepping


_scratch_arrays = threading.local()


def _scratch(name: str, shape: tuple[int, ...], dtype) -> np.ndarray:
    """An uninitialized array for this chunk, kept per thread and name for the next chunks (the
    largest asked so far). A new chunk-sized array would come from fresh pages, which the kernel
    zeroes on first touch: about 5 % of a dask worker's CPU (perf, 256 3-s cases a chunk). Its
    contents are used only until the chunk's parts are written, before run_chunk returns.
    """
    arrays = _scratch_arrays.__dict__
    size = int(np.prod(shape))
    kept = arrays.get(name)
    if kept is None or kept.size < size or kept.dtype != dtype:
        kept = arrays[name] = np.empty(size, dtype)
    return kept[:size].reshape(shape)


def _repeated(numbers: np.ndarray, times: int) -> np.ndarray:
    """The case column of a chunk: each case number `times` times (np.repeat, into scratch)."""
    column = _scratch("case", (len(numbers), times), numbers.dtype)
    column[:] = numbers[:, None]
    return column.reshape(-1)


_tiled_times = threading.local()


def _tiled(times: np.ndarray, cases: int) -> np.ndarray:
    """The time column of a chunk of cases: times once per case. Kept per thread for the last
    shape asked, as a study's chunks all have one (but its last), so it is built once per study.
    """
    last = getattr(_tiled_times, "column", None)
    if last is None or len(last) != len(times) * cases or not np.array_equal(last[: len(times)], times):
        last = _tiled_times.column = np.tile(times, cases)
        last.flags.writeable = False
    return last
