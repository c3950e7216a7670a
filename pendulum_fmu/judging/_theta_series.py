"""theta of the reference and of a result at the result's times, kept for a second pass.

The regression tools (_regression_tools.py) need the whole series twice: csv-compare's tube is
as high as the reference's whole range, and the FMI cross-check's band is the reference resampled
over the whole run, both known only once the last row is read. The judge reads a long result once,
a window at a time, and spills each window's rows here: into an unnamed temporary file (24 bytes
a row, on disk, gone when it is closed or the process ends, however it ends), read back a block
at a time. Memory holds a block and an index of one entry per block.
"""

from __future__ import annotations

import math
import tempfile
from collections.abc import Iterator
from typing import IO

import numpy as np

# Doubles a row: time, the reference's theta, the result's.
_WIDTH = 3


class ThetaSeries:
    """Rows of (time, reference theta, result theta), in increasing time, appended a block at a
    time and read back a block at a time. Use it as a context manager: the file is closed after.

    Attributes
    ----------
    rows : int
        The rows appended.
    first_time, last_time : float
        The first and last row's times (s).
    lowest, highest : float
        The reference's least and greatest theta (rad).
    """

    def __init__(self):
        self._file: IO[bytes] | None = None
        self._starts: list[int] = []  # each block's first row
        self._times: list[float] = []  # and its time
        self.rows = 0
        self.first_time = self.last_time = math.nan
        self.lowest, self.highest = math.inf, -math.inf

    def __enter__(self) -> ThetaSeries:
        return self

    def __exit__(self, *exc) -> None:
        if self._file is not None:
            self._file.close()

    def append(self, time: np.ndarray, reference: np.ndarray, result: np.ndarray) -> None:
        """Add the rows of one block (time increasing, and not before the rows already added)."""
        if not len(time):
            return
        if self._file is None:
            self._file = tempfile.TemporaryFile(prefix="pendulum-fmu-judge-")
            self.first_time = float(time[0])
        rows = np.empty((len(time), _WIDTH))
        rows[:, 0], rows[:, 1], rows[:, 2] = time, reference, result
        self._file.seek(self.rows * _WIDTH * 8)
        rows.tofile(self._file)
        self._starts.append(self.rows)
        self._times.append(float(time[0]))
        self.rows += len(time)
        self.last_time = float(time[-1])
        self.lowest = min(self.lowest, float(np.min(reference)))
        self.highest = max(self.highest, float(np.max(reference)))

    def _read(self, begin: int, end: int) -> np.ndarray:
        assert self._file is not None, "rows are read only once some were appended"
        self._file.seek(begin * _WIDTH * 8)
        return np.fromfile(self._file, count=(end - begin) * _WIDTH).reshape(-1, _WIDTH)

    def blocks(self) -> Iterator[tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """(time, reference theta, result theta) of each block, in order."""
        for begin, end in zip(self._starts, [*self._starts[1:], self.rows], strict=True):
            rows = self._read(begin, end)
            yield rows[:, 0], rows[:, 1], rows[:, 2]

    def reference_between(self, earliest: float, latest: float) -> tuple[np.ndarray, np.ndarray]:
        """The reference's (time, theta) from the last row at or before `earliest` (or the first
        row) to the first at or after `latest` (or the last): every row inside, and one either
        side for the line's value at the ends.
        """
        first_block = max(int(np.searchsorted(self._times, earliest, side="right")) - 1, 0)
        last_block = int(np.searchsorted(self._times, latest, side="right"))
        end = self._starts[last_block] if last_block < len(self._starts) else self.rows
        rows = self._read(self._starts[first_block], end)
        time = rows[:, 0]
        # The reach may end in the next block: its first row is the one after.
        if end < self.rows and (not len(time) or time[-1] < latest):
            rows = np.vstack([rows, self._read(end, end + 1)])
            time = rows[:, 0]
        begin = max(int(np.searchsorted(time, earliest, side="right")) - 1, 0)
        stop = min(int(np.searchsorted(time, latest, side="left")) + 1, len(time))
        return time[begin:stop], rows[begin:stop, 1]


def series_of(time: np.ndarray, reference: np.ndarray, result: np.ndarray, block: int = 1 << 16) -> ThetaSeries:
    """A ThetaSeries of whole arrays (a result at hand), appended a block at a time."""
    series = ThetaSeries()
    for begin in range(0, len(time), block):
        part = slice(begin, begin + block)
        series.append(time[part], reference[part], result[part])
    return series


__all__ = ["ThetaSeries", "series_of"]
