"""A run written to its CSV as it goes: the memory it takes is a block's, however long it runs.

simulate() returns the whole run as one array, which a run of tens of millions of steps cannot
afford (about 100 bytes a step, with its schedule). simulate_to_csv runs the same schedule in
windows of steps through one FMU instance that carries its state from one window into the next
(Simulator.run_windows: no restart between them), and appends each window's rows to the file,
which appears whole, and byte for byte as write_csv(simulate(...)) writes it, when the run ends.
"""

from __future__ import annotations

import itertools
import os
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._atomic_files import replacing
from ..signals._torque_schedule import TorqueSchedule, TorqueSignal, schedule
from . import _results as results
from ._simulate import simulate_windows

# Steps a window holds: its schedule, recorded outputs and result rows take about 100 bytes a
# step (6 MB), and the calls a window costs (tens of microseconds) are lost in its 65,536 steps.
WINDOW_STEPS = 2**16


def schedule_windows(
    torque: TorqueSignal,
    *,
    start_time: float = 0.0,
    stop_time: float | None = None,
    step_size: float = 1e-3,
    ramp: bool = False,
    max_steps: int | None = None,
    window_steps: int = WINDOW_STEPS,
) -> Iterator[TorqueSchedule]:
    """Consecutive windows of schedule(...)'s schedule, sharing their boundary points.

    STAND-IN, to be replaced by signals._torque_schedule.schedule_windows (branch windowed-oracle),
    which makes each window on its own: this one slices the whole schedule, so its memory still
    grows with the run (24 bytes a step), though the run's results no longer do.
    """
    plan = schedule(
        torque, start_time=start_time, stop_time=stop_time, step_size=step_size, ramp=ramp, max_steps=max_steps
    )
    steps = len(plan.torque)
    for k0 in range(0, steps, window_steps):
        k1 = min(k0 + window_steps, steps)
        yield TorqueSchedule(
            time=plan.time[k0 : k1 + 1], torque=plan.torque[k0:k1], torque_rate=plan.torque_rate[k0:k1]
        )


@dataclass
class StreamedRun:
    """What a run written as it went leaves besides its file: the summary its command prints.

    Attributes
    ----------
    path : Path
        The CSV written.
    fields : tuple of str
        Its columns: time, then what the FMU records.
    steps : int
        Communication steps (the file has steps + 1 rows).
    last : numpy.ndarray
        The last row, a result array of one row.
    largest : dict
        max |value| of each field over the run (NaN where a value was).
    """

    path: Path
    fields: tuple[str, ...] = ()
    steps: int = -1
    last: np.ndarray | None = None
    largest: dict[str, float] = field(default_factory=dict)

    def add(self, block: np.ndarray) -> None:
        """Count a block of the run's rows in."""
        self.fields, self.steps, self.last = results.fields(block), self.steps + len(block), block[-1:]
        for name in self.fields:
            largest = np.max(np.abs(block[name]))
            # np.max propagates a NaN, as it does over a whole run.
            self.largest[name] = float(np.max([self.largest.get(name, 0.0), largest]))


def simulate_to_csv(
    path: str | os.PathLike,
    torque: TorqueSignal = 20.0,
    *,
    start_time: float = 0.0,
    stop_time: float | None = None,
    step_size: float = 1e-3,
    ramp: bool = False,
    max_steps: int | None = None,
    window_steps: int = WINDOW_STEPS,
    each_block: Callable[[np.ndarray], object] | None = None,
    **options,
) -> StreamedRun:
    """simulate(), written to a CSV as it runs, in memory bounded by a window, not by the run.

    The file holds what write_csv(simulate(...), path) writes, byte for byte; it is written to a
    temporary beside path and renamed into place when the run ends, so an error or Ctrl-C leaves
    the file that was there, or none.

    Parameters
    ----------
    path : str or os.PathLike
        The CSV to write (replaced if it is there).
    torque, start_time, stop_time, step_size, ramp, max_steps
        The signal and its schedule, as simulate takes them.
    window_steps : int, optional
        Grid steps run and written at a time (a window with a CSV's jumps between grid points
        holds a few more communication points).
    each_block : callable, optional
        Called with each block of consecutive result rows as it is written (a result array).
    **options
        simulate's parameters, theta0, omega0, tolerance, fmu_path and platform.

    Returns
    -------
    StreamedRun
        The file, the number of steps, the last row and each field's largest magnitude.

    Raises
    ------
    InvalidInput, TorqueFileError, FmuError, MissingFile, MissingDependency
        As simulate raises them.
    CannotWrite
        path cannot be written.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> run = simulate_to_csv(Path(tempfile.mkdtemp(), "run.csv"), 20.0, stop_time=1.0, window_steps=300)
    >>> run.steps, round(float(run.last["theta"][0]), 6)
    (1000, 0.187205)
    """
    windows = schedule_windows(
        torque,
        start_time=start_time,
        stop_time=stop_time,
        step_size=step_size,
        ramp=ramp,
        max_steps=max_steps,
        window_steps=window_steps,
    )
    # The first window made before anything else, so that a signal or time the package refuses
    # is refused first, as simulate() refuses it, and before a temporary is made.
    first = next(windows)
    run = StreamedRun(Path(path))
    with replacing(path) as file:
        for block in simulate_windows(itertools.chain((first,), windows), **options):
            results.write_rows(file, block, header=run.last is None)
            run.add(block)
            if each_block is not None:
                each_block(block)
    return run
