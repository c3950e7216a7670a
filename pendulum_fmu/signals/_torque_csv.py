"""A torque CSV read as a signal: a TorqueTable, piecewise linear with a jump where a time repeats.

The numbers are parsed in C by pyarrow in one pass, those of a small file of plain numbers in
Python (quicker than importing pyarrow); a file that is no signal is refused with
TorqueFileError, naming the file, the line and the problem (docs/signals.md).
"""

from __future__ import annotations

import csv
import io
import itertools
import math
import os
import re
import stat
import zlib
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Literal

import numpy as np

from .._errors import InvalidInput
from .._received_files import MAX_TORQUE_CSV_BYTES, bounded_read, check_lines, check_size, shortened
from ._time_grid import event_tolerance, nearest

# A file up to this size whose numbers are all plain is read in Python, in a few ms: importing
# pyarrow takes ~30 ms of the start-up of a judge or a simulate given a short signal. A larger file,
# or one with anything else in it, is pyarrow's to read, to accept or to refuse.
SMALL_FILE_BYTES = 2**16
# Whole lines parsed at a time: a file of millions of rows is never held whole as bytes (1 MB:
# pyarrow's and the checks' transients of a block some 50 MB less than 8 MB blocks', and quicker).
BLOCK_BYTES = 1 << 20
ADVICE = "give a CSV of time,torque rows"
# Files read and accepted lately (check_torque_csv): the oracle checks the file the judge read.
ACCEPTED_FILES = 8
_ACCEPTED: dict[tuple[str, int, int], None] = {}
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


def _undecodable(path: Path, raw: bytes, first_line: int) -> TorqueFileError | None:
    """The one-line error for a block of whole lines (the first line first_line) that is not
    UTF-8, or None.
    """
    try:
        raw.decode("utf-8")
    except UnicodeDecodeError as error:
        line = raw[: error.start].count(b"\n") + first_line
        return TorqueFileError(
            f"{path}:{line}: byte 0x{raw[error.start]:02x} is not UTF-8; save the "
            "file as UTF-8 (with or without a byte-order mark)"
        )
    return None


def _blocks(file: IO[bytes]) -> Iterator[tuple[int, bytes]]:
    """The file's bytes, less a byte-order mark, in blocks of whole lines (the last may end
    without a newline), each with the number of its first line.
    """
    file.seek(0)
    number, carry, first = 1, b"", True
    while True:
        read = file.read(BLOCK_BYTES)
        at_end = len(read) < BLOCK_BYTES
        if first:  # spreadsheets write a byte-order mark
            read, first = read[3:] if read.startswith(b"\xef\xbb\xbf") else read, False
        data = carry + read
        cut = len(data) if at_end else data.rfind(b"\n") + 1
        carry = data[cut:]
        if cut:  # no newline in a whole block: a line longer than any (check_lines), read on
            yield number, data[:cut]
            number += data.count(b"\n", 0, cut)
        if at_end:
            return


def _lines(file: IO[bytes]) -> Iterator[str]:
    """The lines of a file checked as UTF-8, as str.splitlines of the whole text gives them."""
    for _, block in _blocks(file):
        yield from block.decode("utf-8").splitlines()


def _first_bad_row(path: Path, lines: Iterator[str], columns: tuple[int, int]) -> TorqueFileError | None:
    """The one-line error for the first row that is not two finite numbers, or has more
    columns than the header, or None.
    """
    header = len(next(csv.reader([next(lines)])))
    for number, line in enumerate(lines, start=2):
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


def _line_of_row(lines: Iterator[str], row: int) -> int:
    """The file line (1-based) of data row `row` (0-based), skipping blank lines."""
    seen, number = -1, 1
    for number, line in enumerate(itertools.islice(lines, 1, None), start=2):
        if line.strip():
            seen += 1
            if seen == row:
                return number
    return number


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


def check_torque_csv(path: str | Path) -> None:
    """Refuse a torque CSV as read_torque_csv() does, without reading it again where it read
    and accepted the same file, unchanged (its size and checksum), lately.

    Parameters
    ----------
    path : str or Path
        The CSV.

    Raises
    ------
    TorqueFileError
        As read_torque_csv() raises it.
    """
    if _stamp(Path(path)) not in _ACCEPTED:
        read_torque_csv(path)


def _stamp(path: Path) -> tuple[str, int, int] | None:
    """The file's path, size and checksum (zlib's CRC-32, in C, a block at a time), or None
    where it cannot be read (read_torque_csv says why) or read again (a pipe, which reading here
    would empty).
    """
    checksum = size = 0
    try:
        if not stat.S_ISREG(os.stat(path).st_mode):  # before it is opened: a named pipe's open waits
            return None
        with open(path, "rb") as file:
            while block := file.read(BLOCK_BYTES):
                checksum, size = zlib.crc32(block, checksum), size + len(block)
    except OSError:
        return None
    return str(path.resolve()), size, checksum


@dataclass(frozen=True)
class CsvLayout:
    """What a check of a torque CSV learned of it: its header line (bytes, with its line end), the
    time and torque columns' indices, its number of columns and rows, and its last row's time.
    """

    header: bytes
    columns: tuple[int, int]
    width: int
    rows: int
    last: float


def read_torque_csv(path: str | Path) -> TorqueTable:
    """Read a ``time,torque`` CSV (UTF-8, with or without a byte-order mark; other columns are
    ignored). A bad file raises TorqueFileError naming the file, line and problem. The numbers
    are parsed in C a block of lines at a time, with no Python object per row: the file is
    never held whole, as bytes or as text, only the table's two arrays.
    """
    table, _ = _checked(Path(path), keep=True)
    assert table is not None, "the table is kept"
    return table


def scan_torque_csv(path: str | Path) -> CsvLayout:
    """Refuse a torque CSV as read_torque_csv() does, a block at a time, holding none of its rows.

    Parameters
    ----------
    path : str or Path
        The CSV: a file that can be read again (not a pipe).

    Returns
    -------
    CsvLayout
        Its header, columns, rows and last time.

    Raises
    ------
    TorqueFileError
        As read_torque_csv() raises it.
    """
    return _checked(Path(path), keep=False)[1]


def _checked(path: Path, keep: bool) -> tuple[TorqueTable | None, CsvLayout]:
    stamp = _stamp(path)  # before it is read: a file changed meanwhile is read again when checked
    try:
        with open(path, "rb") as file:
            source: IO[bytes] = file
            try:
                check_size(file, str(path), MAX_TORQUE_CSV_BYTES, TorqueFileError, ADVICE)
            except OSError:  # a pipe: read whole, as far as the limit, to be read twice
                source = io.BytesIO(bounded_read(file, str(path), MAX_TORQUE_CSV_BYTES, TorqueFileError, ADVICE))
            checked = _read(path, source, keep)
    except OSError as error:
        raise TorqueFileError(f"{path}: cannot read: {error.strerror}") from None
    if stamp is not None:
        _ACCEPTED[stamp] = None
        while len(_ACCEPTED) > ACCEPTED_FILES:
            del _ACCEPTED[next(iter(_ACCEPTED))]
    return checked


def _read(path: Path, file: IO[bytes], keep: bool) -> tuple[TorqueTable | None, CsvLayout]:
    # The refusals in the order the checks of a file read whole make them: first whatever
    # line is too long or holds a NUL byte, anywhere, then whatever byte is not UTF-8.
    line_fault: TorqueFileError | None = None
    text_fault: TorqueFileError | None = None
    header_line, header_bytes, content, lines = "", b"", False, 0
    for number, block in _blocks(file):
        lines += block.count(b"\n") + 1
        if number == 1:
            header_bytes = block[: block.find(b"\n") + 1] if b"\n" in block else block
            header_line = header_bytes.rstrip(b"\r\n").decode("utf-8", "replace")
        content = content or bool(block.strip())
        if line_fault is None:
            try:
                check_lines(block, str(path), TorqueFileError, ADVICE, first_line=number)
            except TorqueFileError as fault:
                line_fault = fault
        text_fault = text_fault or _undecodable(path, block, number)
    if line_fault or text_fault:
        raise line_fault or text_fault  # type: ignore[misc]
    if not header_line.strip():
        if content:
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
    order = _Order()
    times, torques = (np.empty(lines), np.empty(lines)) if keep else (np.empty(0), np.empty(0))
    rows = 0
    for block_times, block_torques in _numbers(path, file, header, columns):
        order.add(block_times)
        count = len(block_times)
        if keep and rows + count > len(times):  # lines ended by a lone carriage return, which pyarrow splits
            times, torques = (np.concatenate([column, np.empty(rows + count)]) for column in (times, torques))
        if keep:
            times[rows : rows + count], torques[rows : rows + count] = block_times, block_torques
        rows += count
    if rows == 0:
        raise TorqueFileError(f"{path}: no data rows after the header")
    order.check(path, file)
    layout = CsvLayout(header_bytes, columns, len(header), rows, order.last)
    return (TorqueTable(times[:rows], torques[:rows]) if keep else None), layout


class _Order:
    """The rows' times taken a block at a time: the first that goes backwards and the first that
    appears three times, as the whole column's differences find them, and the last time.
    """

    def __init__(self):
        self.rows, self.tail, self.last = 0, np.empty(0), math.nan
        self.backwards: tuple[int, float, float] | None = None  # row, its time, the previous row's
        self.triple: tuple[int, float] | None = None  # row, its time

    def add(self, times: np.ndarray) -> None:
        # The last two times before the block, for a backwards step or a triple across its border.
        joined, base = np.concatenate([self.tail, times]), self.rows - len(self.tail)
        if self.backwards is None:
            found = np.flatnonzero(joined[1:] < joined[:-1])  # np.diff's sign, without its array of doubles
            if len(found):
                k = found[0] + 1
                self.backwards = (base + k, joined[k], joined[k - 1])
        if self.triple is None:
            found = np.flatnonzero((joined[2:] == joined[1:-1]) & (joined[1:-1] == joined[:-2]))
            if len(found):
                self.triple = (base + found[0] + 2, joined[found[0] + 2])
        self.rows, self.tail = self.rows + len(times), joined[-2:]
        self.last = float(joined[-1]) if len(joined) else self.last

    def check(self, path: Path, file: IO[bytes]) -> None:
        """Refuse the first of the two faults found, by its file line."""
        if self.backwards and (not self.triple or self.backwards[0] < self.triple[0]):
            row, time, previous = self.backwards
            raise TorqueFileError(
                f"{path}:{_line_of_row(_lines(file), row)}: time {time:g} goes backwards "
                f"(previous row: {previous:g}); sort the rows by time"
            )
        if self.triple:
            row, time = self.triple
            raise TorqueFileError(
                f"{path}:{_line_of_row(_lines(file), row)}: time {time:g} appears three "
                "times; a jump is two rows with the same time"
            )


def _numbers(
    path: Path, file: IO[bytes], header: list[str], columns: tuple[int, int]
) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """The time and torque columns, a block at a time; a row that is not two finite numbers
    refused with the line of the file's first such row.
    """
    header_bytes = b""
    for number, block in _blocks(file):
        if number == 1:
            header_bytes = block[: block.find(b"\n") + 1] if b"\n" in block else block
            raw = block
        else:
            raw = header_bytes + block
        data = parse_block(raw, header, columns, small=number == 1)
        if data is None or not all(np.all(np.isfinite(column)) for column in data):
            bad_row = _first_bad_row(path, _lines(file), columns)
            raise bad_row or TorqueFileError(f"{path}: rows must have as many columns as the header ({len(header)})")
        yield data


def parse_block(
    raw: bytes, header: list[str], columns: tuple[int, int], small: bool
) -> tuple[np.ndarray, np.ndarray] | None:
    """A block of whole lines, its first the header (skipped), as the time and torque columns;
    None when a row is not numbers (_first_bad_row says which). A small block (small, and up to
    SMALL_FILE_BYTES) of plain numbers is read in Python, quicker than pyarrow.
    """
    data = _parse_plain_numbers(raw, header, columns) if small and len(raw) <= SMALL_FILE_BYTES else None
    return data if data is not None else _parse_numbers(raw, header, columns)
