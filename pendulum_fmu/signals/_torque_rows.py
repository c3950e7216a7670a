"""A torque table's rows, a stretch at a time: from a CSV never held whole (TorqueCsv), or from a
table in memory (HeldRows).

A TorqueCsv is checked once, a block at a time (scan_torque_csv: every refusal of
read_torque_csv, in its words), and read again a block at a time as its rows are asked for: each
reader (rows()) reads forward, holding the rows near the stretch last asked for; one asked for
before them reads the file again from its start. A file changed or replaced since it was checked
is refused, never read as a mix of two files. Both kinds answer alike:

- blocks(): the rows in order, a block of them at a time;
- rows().near(t0, t1): the rows from two before the first at or after t0 to two after the last
  at or before t1, which answer for any time from t0 to t1 as the whole table does.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from .._received_files import ReadAgain
from . import _torque_csv
from ._time_grid import WINDOW_STEPS
from ._torque_csv import TorqueFileError, TorqueTable, parse_block, read_torque_csv, scan_torque_csv

# Rows of a table in memory a block holds (HeldRows.blocks).
BLOCK_ROWS = WINDOW_STEPS
# Rows either side of a stretch beyond its times: the segment a time at its edge falls in, and
# the row a snapped neighbour may move onto.
_EXTRA_ROWS = 2


def _bounds(time: np.ndarray, t0: float, t1: float) -> tuple[int, int]:
    """The indices of near(t0, t1)'s rows in the sorted times."""
    lo = max(int(np.searchsorted(time, t0, "left")) - _EXTRA_ROWS, 0)
    return lo, int(np.searchsorted(time, t1, "right")) + _EXTRA_ROWS


class HeldRows:
    """A table in memory (a TorqueTable given, or a CSV read whole from a pipe), as TorqueCsv
    answers; it is its own reader.
    """

    def __init__(self, table: TorqueTable):
        self.table, self.last = table, float(table.time[-1])

    def blocks(self) -> Iterator[TorqueTable]:
        table = self.table
        for begin in range(0, len(table.time), BLOCK_ROWS):
            yield TorqueTable(table.time[begin : begin + BLOCK_ROWS], table.torque[begin : begin + BLOCK_ROWS])

    def rows(self) -> HeldRows:
        return self

    def near(self, t0: float, t1: float) -> TorqueTable:
        lo, hi = _bounds(self.table.time, t0, t1)
        return TorqueTable(self.table.time[lo:hi], self.table.torque[lo:hi])


def torque_rows(path: str | Path) -> TorqueCsv | HeldRows:
    """A torque CSV's rows: a TorqueCsv, or for a file that cannot be read twice (a pipe), the
    table read whole.

    Raises
    ------
    TorqueFileError
        As read_torque_csv() raises it.
    """
    path = Path(path)
    try:
        regular = os.path.isfile(path)
    except (OSError, ValueError):
        regular = False
    return TorqueCsv(path) if regular else HeldRows(read_torque_csv(path))


class TorqueCsv:
    """A torque CSV checked once and read again a block at a time (see the module's docstring).

    Attributes
    ----------
    path : Path
    last : float
        The last row's time (s).
    """

    def __init__(self, path: Path):
        self.path = path
        try:
            self._file = ReadAgain(path, TorqueFileError, "use it once it is written")
        except OSError as error:
            raise TorqueFileError(f"{path}: cannot read: {error.strerror}") from None
        self.layout = scan_torque_csv(path)
        self.last = self.layout.last
        # A file changed between the stat above and the check is refused at its first block.

    def blocks(self) -> Iterator[TorqueTable]:
        offset = 0
        while True:
            block, offset = self._block(offset)
            if block is None:
                return
            yield block

    def rows(self) -> CsvReader:
        return CsvReader(self)

    def _block(self, offset: int) -> tuple[TorqueTable | None, int]:
        """The rows of the block of whole lines at offset (None at the end) and the next offset."""
        raw = self._file.block(offset, _torque_csv.BLOCK_BYTES)
        if not raw:
            return None, offset
        layout = self.layout
        names = [f"c{i}" for i in range(layout.width)]
        if offset == 0:
            first = raw[3:] if raw.startswith(b"\xef\xbb\xbf") else raw
        else:
            first = layout.header + (b"\n" if not layout.header.endswith((b"\n", b"\r")) else b"") + raw
        data = parse_block(first, names, layout.columns, small=offset == 0)
        if data is None:  # checked whole before: only a file changed since parses otherwise
            raise TorqueFileError(f"{self.path}: the file changed while it was read; use it once it is written")
        return TorqueTable(*data), offset + len(raw)


class CsvReader:
    """One reader of a TorqueCsv's rows, forward (near())."""

    def __init__(self, csv: TorqueCsv):
        self.csv = csv
        self._rewind()

    def _rewind(self) -> None:
        self._offset, self._end, self._dropped = 0, False, False
        self._time, self._torque = np.empty(0), np.empty(0)

    def near(self, t0: float, t1: float) -> TorqueTable:
        time = self._time
        if self._dropped and np.count_nonzero(time[: _EXTRA_ROWS + 1] < t0) < _EXTRA_ROWS:
            self._rewind()
        while not self._end and len(self._time) - int(np.searchsorted(self._time, t1, "right")) < _EXTRA_ROWS:
            block, self._offset = self.csv._block(self._offset)
            if block is None:
                self._end = True
            else:
                self._time = np.concatenate([self._time, block.time])
                self._torque = np.concatenate([self._torque, block.torque])
        lo, hi = _bounds(self._time, t0, t1)
        rows = TorqueTable(self._time[lo:hi], self._torque[lo:hi])
        # The rows before the stretch are let go: later stretches start later.
        self._time, self._torque = self._time[lo:], self._torque[lo:]
        self._dropped |= lo > 0
        return rows
