"""compare's run walked a window of the schedule at a time, in memory bounded by the window.

Each window, the reference (the judge) is integrated from the state the window before left it in,
and every tool hands over its rows of that window: a tool that carries its state across windows
(Tool.windowed: the FMU's binaries) runs it now; any other tool ran the whole schedule before the
walk, and its run is cut into the same windows. Every window's rows then go to one Tally, which
writes them to trajectories.csv, adds them to the differences and keeps those a figure draws, so
that a run is tallied the same way, number for number, however its tools ran.
"""

from __future__ import annotations

import collections
import csv
import itertools
import math
import time as clock
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from .._atomic_files import replacing
from .._drawn_points import DrawnRows
from ..fmu import _results as results
from ..signals._torque_schedule import TorqueSchedule
from ._compare_tools import Tool

REFERENCE = "reference"
# The outputs whose extremes, and whose differences' extremes, a figure of a long run keeps.
DRAWN = ("theta", "omega")
TEXT_ROWS = 4096


def trajectory_block(blocks: dict[str, np.ndarray]) -> np.ndarray:
    """The rows of trajectories.csv for the same rows of every tool: time (the first tool's),
    then each field after time of each tool, named FIELD_LABEL (torque_fmu, theta_fmu, ...).

    Parameters
    ----------
    blocks : dict of str to numpy.ndarray
        Result arrays of the same communication points, by the tools' labels, the judge first.

    Returns
    -------
    numpy.ndarray
        A structured array of float64 fields.
    """
    first = next(iter(blocks.values()))
    names = {"time": first["time"]}
    for label, block in blocks.items():
        for name in results.fields(block)[1:]:
            names[f"{name}_{label}"] = block[name]
    out = np.empty(len(first), dtype=[(name, "f8") for name in names])
    for name, values in names.items():
        out[name] = values
    return out


def write_trajectory_rows(file, block: np.ndarray, header: bool = False) -> None:
    """Append trajectory rows to trajectories.csv as it has always been written: every number as
    Python's repr (the shortest text that reads back to the same double), comma-separated, each
    line ended by CRLF (the csv module's), so that a run written a window at a time reads the
    same, byte for byte, as written whole.

    Parameters
    ----------
    file : text file
        Open for writing with newline="".
    block : numpy.ndarray
        Rows from trajectory_block.
    header : bool, optional
        Write the line of column names first.
    """
    if header:
        csv.writer(file).writerow(results.fields(block))
    numbers = block.view(np.float64).reshape(len(block), -1)
    # A few thousand rows at a time: their text and its copies stay a few MB.
    for start in range(0, len(numbers), TEXT_ROWS):
        # str() of a list of lists is every float's repr in one call: twice as fast as the csv
        # module's writer, and the same text (no repr of a double needs quoting).
        rows = str(numbers[start : start + TEXT_ROWS].tolist())
        file.write(rows[2:-2].replace("], [", "\r\n").replace(", ", ",") + "\r\n")


class Differences:
    """The differences of every tool against the judge and of every pair of other tools, added up
    a block of rows at a time: max |d| and the sum of d^2 of each output (every field after time
    and torque), and max |torque difference|.

    Parameters
    ----------
    labels : sequence of str
        The tools' labels, the judge (REFERENCE) among them.
    """

    def __init__(self, labels):
        others = [label for label in labels if label != REFERENCE]
        self.pairs = [(label, REFERENCE) for label in others] + list(itertools.combinations(others, 2))
        self._largest: dict[tuple, dict[str, float]] = {pair: {} for pair in self.pairs}
        self._squares: dict[tuple, dict[str, float]] = {pair: {} for pair in self.pairs}
        self.rows = 0

    def add(self, blocks: dict[str, np.ndarray]) -> None:
        """Add the same rows of every tool, by label."""
        self.rows += len(blocks[REFERENCE])
        # A tool whose numbers run past the largest double (a --map factor of 1e308) differs by
        # inf: that is its verdict, and numpy's overflow warnings on the way say nothing more.
        with np.errstate(over="ignore", invalid="ignore"):
            for a, b in self.pairs:
                largest, squares = self._largest[a, b], self._squares[a, b]
                for name in results.fields(blocks[a])[1:]:
                    difference = np.abs(blocks[a][name] - blocks[b][name])
                    # np.maximum and + carry a NaN on, as np.max and np.sum over the whole run do.
                    largest[name] = float(np.maximum(largest.get(name, 0.0), np.max(difference)))
                    if name != "torque":
                        squares[name] = squares.get(name, 0.0) + float(np.sum(difference**2))

    def table(self, seconds: dict[str, float]) -> list[dict]:
        """The rows of differences.csv: tool, against, NAME_max and NAME_rms of each output,
        torque_max and seconds_per_step (a tool's own against the judge, None for a pair).
        """
        rows = []
        for a, b in self.pairs:
            largest, squares = self._largest[a, b], self._squares[a, b]
            row: dict = {"tool": a, "against": b}
            for name, total in squares.items():
                row[f"{name}_max"] = largest[name]
                row[f"{name}_rms"] = math.sqrt(total / self.rows)
            row["torque_max"] = largest["torque"]
            row["seconds_per_step"] = seconds.get(a) if b == REFERENCE else None
            rows.append(row)
        return rows


class Tally:
    """Every window's rows of a comparison, taken in as they come: written to trajectories.csv,
    added to the differences, the rows a figure draws kept (every extreme of theta, omega and
    their differences against the judge, in each of the run's columns of time), and the whole
    runs kept too when asked (keep_whole).

    Parameters
    ----------
    file : text file
        trajectories.csv, open for writing with newline="".
    span : (float, float)
        The run's first and last time (s).
    keep_whole : bool
        Keep every row of every tool (runs): for a comparison whose tools held theirs anyway.
    """

    def __init__(self, file, span: tuple[float, float], keep_whole: bool):
        self.file, self.span = file, span
        self.differences: Differences | None = None
        self.drawn: DrawnRows | None = None
        self.largest_torque = 0.0
        self._whole: dict[str, list[np.ndarray]] | None = {} if keep_whole else None
        self._fields: dict[str, tuple[str, ...]] = {}

    def add(self, blocks: dict[str, np.ndarray]) -> None:
        """Take in the next rows of every tool, by label, the judge first."""
        block = trajectory_block(blocks)
        if self.differences is None or self.drawn is None:
            self.differences = Differences(blocks)
            self._fields = {label: results.fields(run) for label, run in blocks.items()}
            others = [label for label in blocks if label != REFERENCE]
            names = [f"{name}_{label}" for label in blocks for name in DRAWN]
            self.drawn = DrawnRows([*names, *(_apart(name, label) for label in others for name in DRAWN)], self.span)
        write_trajectory_rows(self.file, block, header=self.differences.rows == 0)
        self.differences.add(blocks)
        self.largest_torque = max(self.largest_torque, float(np.max(np.abs(blocks[REFERENCE]["torque"]))))
        self.drawn.add(_with_differences(block, blocks))
        if self._whole is not None:
            for label, run in blocks.items():
                self._whole.setdefault(label, []).append(run)

    def runs(self) -> dict[str, np.ndarray]:
        """Each tool's rows by label, the judge first: every row where keep_whole, else those a
        figure draws (every row of a short run).
        """
        if self._whole is not None:
            return {label: np.concatenate(parts) for label, parts in self._whole.items()}
        assert self.drawn is not None, "a comparison has rows"
        drawn = self.drawn.rows
        runs = {}
        for label, names in self._fields.items():
            run = results.empty(len(drawn), names[1:])
            run["time"] = drawn["time"]
            for name in names[1:]:
                run[name] = drawn[f"{name}_{label}"]
            runs[label] = run
        return runs


def _apart(name: str, label: str) -> str:
    """The drawn rows' field of |name of label - the judge's|: a space keeps it from any column."""
    return f"|d{name}| {label}"


def _with_differences(block: np.ndarray, blocks: dict[str, np.ndarray]) -> np.ndarray:
    """The block with |theta| and |omega| apart from the judge of every other tool, as the figure
    draws them, so that the drawn rows keep their extremes too.
    """
    apart = {
        _apart(name, label): np.abs(run[name] - blocks[REFERENCE][name])
        for label, run in blocks.items()
        if label != REFERENCE
        for name in DRAWN
    }
    out = np.empty(len(block), dtype=block.dtype.descr + [(name, "f8") for name in apart])
    for name in results.fields(block):
        out[name] = block[name]
    with np.errstate(over="ignore", invalid="ignore"):
        for name, values in apart.items():
            out[name] = values
    return out


class WholeRun:
    """A tool that ran the whole schedule before the walk: its rows handed over a window at a time."""

    def __init__(self, run: np.ndarray):
        self.run, self._start = run, 0

    def take(self, rows: int) -> np.ndarray:
        """The next `rows` rows."""
        block = self.run[self._start : self._start + rows]
        self._start += rows
        return block


class WindowedRun:
    """A tool that runs a window at a time (Tool.windowed), timed as it runs."""

    def __init__(self, blocks: Iterator[np.ndarray]):
        self._blocks, self.seconds = blocks, 0.0

    def take(self, rows: int) -> np.ndarray:
        """The next window's rows (`rows` of them)."""
        started = clock.perf_counter()
        block = next(self._blocks)
        self.seconds += clock.perf_counter() - started
        return block


def _shared(windows: Iterator[TorqueSchedule], count: int) -> list[Iterator[TorqueSchedule]]:
    """Iterators (count of them) over the same windows, each window let go once all took it.

    itertools.tee would do, but it holds its items in links of 57, each freed only once every
    iterator has passed the whole link: 57 windows, the whole of a run of 3.7 million steps.
    """
    waiting: list[collections.deque[TorqueSchedule]] = [collections.deque() for _ in range(count)]

    def taker(mine: collections.deque[TorqueSchedule]) -> Iterator[TorqueSchedule]:
        while True:
            if not mine:
                window = next(windows, None)
                if window is None:
                    return
                for queue in waiting:
                    queue.append(window)
            yield mine.popleft()

    return [taker(queue) for queue in waiting]


def walk(windows, oracle, tools: list[Tool], runs: dict, path: Path, options: dict):
    """Walk the run a window at a time: every window's reference and tools' rows into a Tally.

    Parameters
    ----------
    windows : ScheduleWindows
        The schedule's windows (schedule_windows), none taken yet.
    oracle : ReferenceWindows
        The judge, split into the same windows (reference_windows), not entered yet.
    tools : list of Tool
        The tools other than the judge, in order.
    runs : dict of str to numpy.ndarray
        The whole runs of the tools without a windowed runner, by label.
    path : Path
        trajectories.csv, written as the walk goes, whole or not at all.
    options : dict
        The tools' parameters, theta0 and omega0.

    Returns
    -------
    (Tally, dict)
        What was taken in, and each windowed tool's seconds of running.
    """
    copies = _shared(windows, 1 + sum(tool.label not in runs for tool in tools))
    ours, theirs = copies[0], iter(copies[1:])
    sources = {
        tool.label: WholeRun(runs[tool.label])
        if tool.label in runs
        else WindowedRun(tool.run_windows(next(theirs), **options))
        for tool in tools
    }
    with oracle, replacing(path, newline="") as file:
        tally = Tally(file, (windows.start_time, windows.stop_time), keep_whole=bool(runs))
        for j, window in enumerate(ours):
            # Consecutive windows share their boundary point, whose row is the later window's.
            rows = len(window.time) - (j < windows.windows - 1)
            blocks = {REFERENCE: oracle.next(window.time)[:rows]}
            blocks.update((label, source.take(rows)) for label, source in sources.items())
            tally.add(blocks)
    seconds = {label: source.seconds for label, source in sources.items() if isinstance(source, WindowedRun)}
    return tally, seconds
