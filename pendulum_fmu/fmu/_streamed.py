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
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._atomic_files import replacing
from .._drawn_points import DrawnRows
from ..signals._time_grid import WINDOW_STEPS
from ..signals._torque_schedule import TorqueSignal, schedule_windows
from . import _results as results
from ._simulate import simulate_windows


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
    drawn : DrawnRows or None
        The rows a figure of the run draws, where they were asked for.
    """

    path: Path
    fields: tuple[str, ...] = ()
    steps: int = -1
    last: np.ndarray = field(default_factory=lambda: np.empty(0))
    largest: dict[str, float] = field(default_factory=dict)
    drawn: DrawnRows | None = None

    def add(self, block: np.ndarray) -> None:
        """Count a block of the run's rows in."""
        self.fields, self.steps, self.last = results.fields(block), self.steps + len(block), block[-1:]
        if self.drawn is not None:
            self.drawn.add(block)
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
    drawn: tuple[str, ...] = (),
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
    drawn : tuple of str, optional
        Fields whose rows a figure draws are kept (StreamedRun.drawn): few, with every extreme.
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
    run = StreamedRun(Path(path), drawn=DrawnRows(drawn, (windows.start_time, windows.stop_time)) if drawn else None)
    with replacing(path) as file:
        for block in simulate_windows(itertools.chain((first,), windows), **options):
            results.write_rows(file, block, header=not run.fields)
            run.add(block)
    return run
