"""A torque CSV read as a signal: a TorqueTable, piecewise linear with a jump where a time repeats.

The numbers are parsed in C by pyarrow in one pass, those of a small file of plain numbers in
Python (quicker than importing pyarrow); a file that is no signal is refused with
TorqueFileError, naming the file, the line and the problem (docs/signals.md).
"""

from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np

from .._errors import InvalidInput
from .._received_files import MAX_TORQUE_CSV_BYTES, bounded_read, check_lines, shortened
from ._time_grid import event_tolerance, nearest

# A file up to this size whose numbers are all plain is read in Python, in a few ms: importing
# pyarrow takes ~30 ms of the start-up of a judge or a simulate given a short signal. A larger file,
# or one with anything else in it, is pyarrow's to read, to accept or to refuse.
SMALL_FILE_BYTES = 2**16
# A cell pyarrow and Python's float both read, to the same double (both round correctly): an
# optional minus, ASCII digits with a point, an exponent. Each takes forms the other refuses
# (pyarrow: +1, inf, spaces around; Python: 1_0, other scripts' digits): those go to pyarrow.
PLAIN_NUMBER = re.compile(r"-?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")


class TorqueFileError(InvalidInput):
    r"""A torque CSV that cannot be read; the message names the file, line and problem.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from pendulum_fmu import TorqueFileError, schedule
    >>> table = Path(tempfile.mkdtemp(), "torque.csv")
    >>> _ = table.write_text("time,torque\n0,1\n1,x\n")
    >>> try:
    ...     schedule(table)
    ... except TorqueFileError as error:
    ...     print(str(error).replace(str(table), "torque.csv"))
    torque.csv:3: torque 'x' is not a number
    """


@dataclass(frozen=True)
class TorqueTable:
    """Rows of a torque CSV: piecewise linear, with a jump where a time repeats."""

    time: np.ndarray
    torque: np.ndarray

    def value_after(self, t: np.ndarray) -> np.ndarray:
        """The torque just after each t: at a jump, the value after it."""
        return self._values(np.asarray(t, dtype=float), "right")

    def value_before(self, t: np.ndarray) -> np.ndarray:
        """The torque just before each t: at a jump, the value before it."""
        return self._values(np.asarray(t, dtype=float), "left")

    def _values(self, t: np.ndarray, side: Literal["left", "right"]) -> np.ndarray:
        # np.interp takes the last of equal times, so look the segment up ourselves. Just after
        # t (side "right") the segment is time[i-1] <= t < time[i]; just before it,
        # time[i-1] < t <= time[i]: either way a segment of positive length, never the jump.
        time, torque = self.time, self.torque
        if len(time) == 1:
            return np.full(t.shape, torque[0])
        i = np.clip(np.searchsorted(time, t, side=side), 1, len(time) - 1)
        t0, t1, u0, u1 = time[i - 1], time[i], torque[i - 1], torque[i]
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            inside = u0 + (u1 - u0) * (t - t0) / (t1 - t0)
            # Rows of opposite sign near the largest double (1e308, then -1e308) differ by inf;
            # weighting each row's value instead stays finite (only there: elsewhere it would
            # round differently from the form above, which docs/signals.md states).
            overflowed = ~np.isfinite(inside)
            if overflowed.any():
                share = (t - t0) / (t1 - t0)
                inside = np.where(overflowed, u0 * (1 - share) + u1 * share, inside)
        if side == "right":
            return np.where(t < time[0], torque[0], np.where(t >= time[-1], torque[-1], inside))
        return np.where(t <= time[0], torque[0], np.where(t > time[-1], torque[-1], inside))

    def jumps(self) -> np.ndarray:
        """Times where the torque jumps (a repeated time)."""
        return self.time[1:][np.diff(self.time) == 0]

    def snapped(self, points: np.ndarray, step_size: float) -> TorqueTable:
        """The same table with every row time within event_tolerance of a point moved onto it."""
        closest = nearest(points, self.time)
        close = np.abs(closest - self.time) <= event_tolerance(self.time, step_size)
        return TorqueTable(np.where(close, closest, self.time), self.torque)


def _decode(path: Path, raw: bytes) -> str:
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as error:
        line = raw[: error.start].count(b"\n") + 1
        raise TorqueFileError(
            f"{path}:{line}: byte 0x{raw[error.start]:02x} is not UTF-8; save the "
            "file as UTF-8 (with or without a byte-order mark)"
        ) from None


def _first_bad_row(path: Path, lines: list[str], columns: tuple[int, int]) -> TorqueFileError | None:
    """The one-line error for the first row that is not two finite numbers, or has more
    columns than the header, or None.
    """
    header = len(next(csv.reader([lines[0]])))
    for number, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        cells = next(csv.reader([line]))  # as pyarrow reads it: "1,5" is one quoted cell
        for column, name in zip(columns, ("time", "torque"), strict=False):
            cell = cells[column].strip() if column < len(cells) else ""
            try:
                # Python's float takes 1_0 and fullwidth digits, which pyarrow refuses.
                value = float(cell) if cell.isascii() and "_" not in cell else float("")
            except ValueError:
                return TorqueFileError(f"{path}:{number}: {name} {shortened(repr(cell))} is not a number")
            if not math.isfinite(value):
                return TorqueFileError(f"{path}:{number}: {name} is {shortened(cell)}; values must be finite")
        if len(cells) > header:
            return TorqueFileError(
                f"{path}:{number}: {len(cells)} columns, but the header names {header}; quote a cell holding a comma"
            )
    return None


def _line_of_row(lines: list[str], row: int) -> int:
    """The file line (1-based) of data row `row` (0-based), skipping blank lines."""
    seen = -1
    for number, line in enumerate(lines[1:], start=2):
        if line.strip():
            seen += 1
            if seen == row:
                return number
    return len(lines)


def _parse_plain_numbers(
    raw: bytes, names: list[str], columns: tuple[int, int]
) -> tuple[np.ndarray, np.ndarray] | None:
    """The time and torque columns as float arrays, read in Python to what pyarrow reads: when
    no cell is quoted, every line ends in a newline or a carriage return and a newline, every
    row that is not blank has the header's number of cells, its time and torque plain finite
    numbers (PLAIN_NUMBER); None otherwise (then pyarrow reads the file).
    """
    text = raw.decode("utf-8").replace("\r\n", "\n")
    if '"' in text or "\r" in text:
        return None
    cells: list[str] = []
    for line in text.split("\n")[1:]:
        if not line:  # pyarrow skips a blank line too
            continue
        row = line.split(",")
        if len(row) != len(names) or not all(PLAIN_NUMBER.fullmatch(row[column]) for column in columns):
            return None
        cells.extend(row[column] for column in columns)
    values = np.array([float(cell) for cell in cells]).reshape(-1, 2)
    if not np.all(np.isfinite(values)):  # 1e400: pyarrow's to take, as every other refusal
        return None
    return values[:, 0].copy(), values[:, 1].copy()


def _parse_numbers(raw: bytes, names: list[str], columns: tuple[int, int]) -> tuple[np.ndarray, np.ndarray] | None:
    """The time and torque columns as float arrays, parsed by pyarrow's multi-threaded C
    reader; None when a cell is not a number (the caller then finds the line).
    """
    import pyarrow as pa
    import pyarrow.csv as pa_csv

    # Positional names, so a header with spaces or repeated names still reads.
    positional = [f"c{i}" for i in range(len(names))]
    wanted = [positional[i] for i in columns]
    try:
        table = pa_csv.read_csv(
            pa.py_buffer(raw),
            read_options=pa_csv.ReadOptions(skip_rows=1, column_names=positional),
            convert_options=pa_csv.ConvertOptions(
                include_columns=wanted, column_types={name: pa.float64() for name in wanted}
            ),
        )
    except pa.ArrowInvalid:
        return None
    return tuple(table.column(name).to_numpy() for name in wanted)


def read_torque_csv(path: str | Path) -> TorqueTable:
    """Read a ``time,torque`` CSV (UTF-8, with or without a byte-order mark; other columns are
    ignored). A bad file raises TorqueFileError naming the file, line and problem. The numbers
    are parsed in C in one pass, with no Python object per row.
    """
    path = Path(path)
    try:
        with open(path, "rb") as file:
            raw = bounded_read(file, str(path), MAX_TORQUE_CSV_BYTES, TorqueFileError, "give a CSV of time,torque rows")
    except OSError as error:
        raise TorqueFileError(f"{path}: cannot read: {error.strerror}") from None
    raw = raw[3:] if raw.startswith(b"\xef\xbb\xbf") else raw  # spreadsheets write a byte-order mark
    check_lines(raw, str(path), TorqueFileError, "give a CSV of time,torque rows")
    _decode(path, raw)  # only to refuse another encoding here, with its line
    header_line = raw[: raw.find(b"\n") if b"\n" in raw else len(raw)].decode("utf-8")
    if not header_line.strip():
        if raw.strip():
            raise TorqueFileError(
                f"{path}:1: the line is blank; the header, e.g. time,torque, must be "
                "the first line: remove the blank lines before it"
            )
        raise TorqueFileError(f"{path}: the file is empty; expected a header 'time,torque'")
    header = [name.strip() for name in header_line.split(",")]
    for column in ("time", "torque"):
        if column not in header:
            raise TorqueFileError(
                f"{path}:1: missing column {column!r} (header is {shortened(','.join(header))}); "
                "the first line must name the columns, e.g. time,torque"
            )
    columns = (header.index("time"), header.index("torque"))
    data = _parse_plain_numbers(raw, header, columns) if len(raw) <= SMALL_FILE_BYTES else None
    if data is None:
        data = _parse_numbers(raw, header, columns)
    if data is None or not all(np.all(np.isfinite(column)) for column in data):
        lines = _decode(path, raw).splitlines()
        bad_row = _first_bad_row(path, lines, columns)
        raise bad_row or TorqueFileError(f"{path}: rows must have as many columns as the header ({len(header)})")
    times, torques = data
    if len(times) == 0:
        raise TorqueFileError(f"{path}: no data rows after the header")
    backwards = np.flatnonzero(np.diff(times) < 0)
    triple = np.flatnonzero((times[2:] == times[1:-1]) & (times[1:-1] == times[:-2]))
    if len(backwards) or len(triple):
        lines = _decode(path, raw).splitlines()
        if len(backwards) and (not len(triple) or backwards[0] < triple[0] + 1):
            row = backwards[0] + 1
            raise TorqueFileError(
                f"{path}:{_line_of_row(lines, row)}: time {times[row]:g} goes backwards "
                f"(previous row: {times[row - 1]:g}); sort the rows by time"
            )
        row = triple[0] + 2
        raise TorqueFileError(
            f"{path}:{_line_of_row(lines, row)}: time {times[row]:g} appears three "
            "times; a jump is two rows with the same time"
        )
    return TorqueTable(np.ascontiguousarray(times), np.ascontiguousarray(torques))
