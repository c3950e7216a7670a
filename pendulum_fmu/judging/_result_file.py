"""A result file from any tool, read as a result array: the time column and theta (omega and
alpha where it has them), under any names and units a --map gives.
"""

from __future__ import annotations

import csv
import io
import math
import os
import stat
import sys
from array import array
from collections.abc import Iterator, Sequence
from pathlib import Path

import numpy as np

from .._errors import InvalidInput
from .._received_files import bounded_lines, shortened
from ..comparing._mapped_fmu import as_map
from ..fmu import _results as results

RESULT_QUANTITIES = ("time", "theta", "omega", "alpha")


OPTIONAL = ("omega", "alpha")


class ResultFileError(InvalidInput):
    r"""A result file, or a kit's folder, that cannot be judged; the message names the file, the
    line and the problem.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from pendulum_fmu import ResultFileError, judge
    >>> result = Path(tempfile.mkdtemp(), "result.csv")
    >>> _ = result.write_text("time,theta\n0,0\n0.5,x\n")
    >>> try:
    ...     judge(result, 20.0, stop_time=1.0)
    ... except ResultFileError as error:
    ...     print(str(error).replace(str(result), "result.csv"))
    result.csv:3: theta 'x' is not a number
    """


_GIVE_CSV = "give the result CSV the tool wrote"


# A result larger than this is read by pyarrow (_read_arrow): importing it takes about 0.2 s,
# more than the csv module takes to read a quick start's result (3,000 rows, 0.2 MB).
ARROW_BYTES = 4 << 20


# pyarrow's block: rows a block holds are converted together. Its pool keeps what the largest
# blocks took: reading a 3,000,001-row result (242 MB) alone peaked at 322 MB in 16-MB blocks,
# 187 MB in 4-MB ones and 106 MB in 1-MB ones (with numpy and pyarrow loaded), and took no longer.
_BLOCK_BYTES = 1 << 20


def read_result(
    path: str | Path, mapping: str | dict | None = None, recorded: Sequence[str] | None = None
) -> np.ndarray:
    """A result CSV as a result array (_results.py); omega and alpha are NaN where it has none.

    The blocks of result_blocks, joined: a long result is better judged block by block.

    Parameters
    ----------
    path : str or Path
        A CSV with a header: a time column and theta, optionally omega and alpha.
    mapping : str or dict, optional
        Their names and unit factors, as --map gives them: "time=t,theta=phi*0.0174532925".
    recorded : sequence of str, optional
        The array's fields after time: the judged run's FMU's (FmuModel.recorded; default: the
        default FMU's, looked up for it).

    Returns
    -------
    numpy.ndarray
        Fields time (s), torque (NaN: not judged), theta (rad), omega (rad/s), alpha (rad/s2).

    Raises
    ------
    ResultFileError
        As result_blocks.
    """
    return np.concatenate(list(result_blocks(path, mapping, recorded)))


def result_blocks(
    path: str | Path, mapping: str | dict | None = None, recorded: Sequence[str] | None = None
) -> Iterator[np.ndarray]:
    """A result CSV as result arrays of consecutive rows, a block at a time, checked as read.

    The file is read as it is when the reading starts (its size then): a file larger than
    ARROW_BYTES by pyarrow's CSV reader, a block of about 16 MB at a time, only the judged columns
    converted; a smaller one, or the rest of one where pyarrow refuses a block, row by row, which
    names the first row that cannot be judged. Nothing of the file is held beyond a block.

    Parameters
    ----------
    path, mapping, recorded
        As read_result takes them.

    Yields
    ------
    numpy.ndarray
        Fields time (s), torque (NaN: not judged), theta (rad), omega (rad/s), alpha (rad/s2):
        at least one block, none empty.

    Raises
    ------
    ResultFileError
        One line naming the file, the line and the problem: no time column, a mapped column
        missing, a cell that is not a finite number, times that go backwards, a last line cut
        short, no rows; or a file that grew or shrank while it was read (a master still writing
        it), said once the last block is read.
    """
    path = Path(path)
    mapped = as_map(mapping, RESULT_QUANTITIES)
    try:
        raw = open(path, "rb")
    except OSError as error:
        raise ResultFileError(f"{path}: cannot read: {error.strerror}") from None
    with raw:
        try:
            regular = stat.S_ISREG(os.fstat(raw.fileno()).st_mode)
            # A pipe (judge <(...)) is read once, whole: it cannot be read again from its start.
            whole = b"" if regular else raw.read()
        except OSError as error:
            raise ResultFileError(f"{path}: cannot read: {error.strerror}") from None
        source = raw if regular else io.BytesIO(whole)
        size = os.fstat(raw.fileno()).st_size if regular else len(whole)
        for columns in _read(path, source, size, mapped):
            out = results.empty(len(columns["time"]), recorded)
            for quantity, values in columns.items():
                out[quantity] = values
            yield out
    try:
        now = path.stat().st_size if regular else size
    except OSError as error:
        raise ResultFileError(f"{path}: cannot read: {error.strerror}") from None
    if now != size:
        raise ResultFileError(
            f"{path}: the file went from {size:,} to {now:,} bytes while it was read: a master is "
            "still writing it; judge it once the run has finished"
        )


def _read(path: Path, raw: io.BufferedIOBase, size: int, mapped: dict) -> Iterator[dict[str, np.ndarray]]:
    """{quantity: its column in SI} of the file's first size bytes, a block of rows at a time
    (result_blocks).
    """
    cut = _ends_mid_line(raw, size)
    try:
        with _text(raw, size) as text:
            rows = _numbered_rows(path, text)
            found = next(((number, row) for number, row in rows if any(cell.strip() for cell in row)), None)
            if found is None:
                raise ResultFileError(f"{path}: the file is empty; expected a header such as time,theta")
            header = [cell.strip() for cell in found[1]]
            columns = _columns(path, header, mapped)
            if not (found[0] == 1 and size > ARROW_BYTES):
                yield from _read_rows(path, rows, columns, cut)
                return
        read = 0
        for block in _read_arrow(raw, size, len(header), columns):
            if block is None:
                break
            read += len(block["time"])
            yield block
        else:
            if read:
                if pyarrow := sys.modules.get("pyarrow"):  # its blocks let go: its pool hands their memory back
                    pyarrow.default_memory_pool().release_unused()
                return
        # Read again row by row from the start: the first row pyarrow could not take is named,
        # or the rows it could not take are read.
        with _text(raw, size) as again:
            rows = _numbered_rows(path, again)
            next(rows)
            yield from _read_rows(path, rows, columns, cut, skip=read)
    except csv.Error as error:  # a quoted cell across lines, over csv.field_size_limit()
        raise ResultFileError(f"{path}: not a CSV the judge reads ({error}); {_GIVE_CSV}") from None
    except UnicodeDecodeError:
        raise ResultFileError(f"{path}: not UTF-8 text; save the result as a UTF-8 CSV") from None


def _numbered_rows(path: Path, text: io.TextIOWrapper) -> Iterator[tuple[int, list[str]]]:
    """The CSV's rows, each with its number from 1."""
    return enumerate(csv.reader(bounded_lines(text, str(path), ResultFileError, _GIVE_CSV)), start=1)


def _columns(path: Path, header: list[str], mapped: dict) -> dict[str, tuple[int, float]]:
    """{quantity: (its column's index, its factor to SI)} of the quantities the header has."""
    listed = shortened(",".join(header))
    columns = {}
    for quantity in RESULT_QUANTITIES:
        given = mapped.get(quantity)
        name = given.variable if given else quantity
        if name in header:
            columns[quantity] = (header.index(name), given.factor if given else 1.0)
        elif given:
            raise ResultFileError(
                f"{path}:1: no column {name!r}, which --map names for {quantity} (header is {listed})"
            )
        elif quantity not in OPTIONAL:
            raise ResultFileError(
                f"{path}:1: no column {quantity!r} (header is {listed}); "
                f"name the result's {quantity} column with --map {quantity}=NAME"
            )
    return columns


class _Snapshot(io.RawIOBase):
    """The first size bytes of a file open for reading: what it held when the reading started,
    whatever a master appends to it meanwhile.
    """

    def __init__(self, raw: io.BufferedIOBase, size: int):
        self.raw, self.left = raw, size
        raw.seek(0)

    def readable(self) -> bool:
        return True

    def readinto(self, buffer) -> int:
        view = memoryview(buffer)[: self.left]
        count = self.raw.readinto(view) or 0
        self.left -= count
        return count


def _text(raw: io.BufferedIOBase, size: int) -> io.TextIOWrapper:
    """The snapshot (_Snapshot) as text, a BOM skipped, line ends left to the csv module."""
    return io.TextIOWrapper(io.BufferedReader(_Snapshot(raw, size)), encoding="utf-8-sig", newline="")


def _ends_mid_line(raw: io.BufferedIOBase, size: int) -> bool:
    """Whether the snapshot's last line has no line end (a file cut off, or still being written)."""
    if not size:
        return False
    raw.seek(size - 1)
    return raw.read(1) not in (b"\n", b"\r")


def _read_arrow(raw: io.BufferedIOBase, size: int, width: int, columns: dict) -> Iterator[dict[str, np.ndarray] | None]:
    """The columns a block of whole lines at a time by pyarrow's CSV parser, only those judged
    converted, then None where it refuses a row, one is not finite or the times go backwards
    (_read_rows then names the row). pyarrow is imported here only: it takes longer to import than
    a short result to read.

    The blocks are read here, one at a time, and each is parsed on its own: pyarrow's streaming
    reader reads ahead of its consumer on threads of its own, up to 32 blocks measured, and a
    judge that integrates each block's rows consumes slowly.
    """
    import pyarrow as pa
    from pyarrow import csv as pa_csv

    names = [f"c{index}" for index in range(width)]
    wanted = {quantity: names[index] for quantity, (index, _) in columns.items()}
    read_options = pa_csv.ReadOptions(column_names=names, use_threads=True)
    convert_options = pa_csv.ConvertOptions(
        include_columns=list(wanted.values()), column_types=dict.fromkeys(wanted.values(), pa.float64())
    )
    last = -math.inf
    snapshot = io.BufferedReader(_Snapshot(raw, size), buffer_size=_BLOCK_BYTES)
    snapshot.readline()  # the header, read already
    rest = b""
    try:
        while True:
            read = snapshot.read(_BLOCK_BYTES)
            # Whole lines: the part of a line a block ends in is read with the next.
            if read:
                cut = read.rfind(b"\n") + 1
                if not cut:
                    rest += read
                    continue
                lines, rest = rest + read[:cut], read[cut:]
            else:
                lines, rest = rest, b""
            if not lines.strip():
                if not read:
                    return
                continue
            table = pa_csv.read_csv(pa.py_buffer(lines), read_options=read_options, convert_options=convert_options)
            block = {q: _in_si(table.column(wanted[q]).to_numpy(), factor) for q, (_, factor) in columns.items()}
            time = block["time"]
            # Nulls (an empty cell, NA) are NaN too.
            if len(time) and (
                not all(np.isfinite(values).all() for values in block.values())
                or time[0] < last
                or np.any(np.diff(time) < 0)
            ):
                yield None
                return
            if len(time):
                last = time[-1]
                yield block
            if not read:
                return
    except (pa.ArrowException, ValueError):
        yield None


def _in_si(values: np.ndarray, factor: float) -> np.ndarray:
    """A column times its --map factor (the same array where the factor is 1)."""
    return values * factor if factor != 1.0 else values


def _number(cell: str) -> float:
    """The cell's number; NaN when it is none."""
    try:
        return float(cell)
    except ValueError:
        return math.nan


# Rows the row reader gives in one block.
_ROWS = 1 << 17


def _read_rows(
    path: Path, rows: Iterator[tuple[int, list[str]]], columns: dict, ends_mid_line: bool, skip: int = 0
) -> Iterator[dict[str, np.ndarray]]:
    """The columns from numbered rows, read one by one, in blocks of _ROWS rows: ResultFileError
    at the first that cannot be judged (a cell missing, not a number or not finite, a time that
    goes backwards, the last line cut short). The first `skip` rows are checked, not given.
    """
    read = {quantity: array("d") for quantity in columns}
    wanted = [(quantity, column, factor, read[quantity].append) for quantity, (column, factor) in columns.items()]
    previous, given = -math.inf, 0
    for number, row in rows:
        if not any(cell.strip() for cell in row):
            continue
        for quantity, column, factor, append in wanted:
            cell = row[column].strip() if column < len(row) else ""
            value = _number(cell)
            if not math.isfinite(value):
                # The row is refused: the next may be read. None, and no line end: the last
                # line was cut off (a master still writing, a copy cut short), not miswritten.
                if ends_mid_line and next(rows, None) is None:
                    raise ResultFileError(
                        f"{path}:{number}: the last line is cut short ({len(row)} cells, no line end): "
                        "the file ends mid-row; judge the result once the tool has written it whole"
                    )
                if math.isnan(value) and cell.lower().lstrip("+-") != "nan":
                    raise ResultFileError(f"{path}:{number}: {quantity} {shortened(repr(cell))} is not a number")
                raise ResultFileError(f"{path}:{number}: {quantity} is {shortened(cell)}; values must be finite")
            append(value * factor)
        time = read["time"][-1]
        if time < previous:
            raise ResultFileError(
                f"{path}:{number}: time {time:.17g} goes backwards (previous "
                f"row: {previous:.17g}); a result's times must not decrease"
            )
        previous = time
        given += 1
        if given <= skip:
            for values in read.values():
                del values[:]
        elif len(read["time"]) == _ROWS:
            yield {quantity: np.frombuffer(values, dtype=float).copy() for quantity, values in read.items()}
            for values in read.values():
                del values[:]
    if not given:
        raise ResultFileError(f"{path}: no data rows after the header")
    if read["time"]:
        yield {quantity: np.frombuffer(values, dtype=float) for quantity, values in read.items()}
