"""The oracle's own reader of a torque CSV: its rows' times as exact integers on a common decimal
denominator (ticks, _decimal_times.py) and float torques, read forward a chunk at a time
(FileRows), a stretch of them at a time (TorqueFile), so that a file of millions of rows is never
held whole, and no Fraction is made per row.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Sequence
from fractions import Fraction
from functools import cached_property
from pathlib import Path

import numpy as np

from .._received_files import ReadAgain
from ..signals._torque_csv import TorqueFileError
from ._decimal_times import (
    count_at_most,
    count_below,
    doubles_of,
    rescaled,
    ticks_of_arrow,
    ticks_of_cells,
)

# Bytes read a chunk (some 25,000 rows of a recorded torque).
CHUNK_BYTES = 1 << 20
# A file up to this size is parsed in Python; a larger one by pyarrow, whose import (some 60 ms)
# a short judge would feel.
SMALL_FILE_BYTES = 1 << 16
# docs/signals.md: an event within max(1e-9 step, 64 ulp of its time) of a communication point
# is that point. Written again here on purpose: the oracle must not borrow the schedule's code.
TOLERANCE_STEPS, TOLERANCE_ULPS = Fraction(1, 10**9), 64


def event_tolerance(time: Fraction | float, step: Fraction) -> Fraction:
    return max(TOLERANCE_STEPS * step, Fraction(TOLERANCE_ULPS * math.ulp(float(time))))


class TorqueFile:
    """Consecutive rows of a time,torque CSV: linear between rows, a jump where a time repeats,
    held outside. A stretch of a file (FileRows.rows) answers as the whole file does for times
    inside it.

    Parameters
    ----------
    ticks : numpy.ndarray
        The row times times 10**digits, exact integers (int64, or Python's in an object array).
    digits : int
        Their decimal digits.
    torques : numpy.ndarray
        The rows' torques (N.m).
    doubles : numpy.ndarray
        Each time's nearest double.
    """

    def __init__(self, ticks: np.ndarray, digits: int, torques: np.ndarray, doubles: np.ndarray):
        self.ticks, self.digits, self.torques, self.doubles = ticks, digits, torques, doubles

    @cached_property
    def times(self) -> list[Fraction]:
        """The row times as fractions, made when first asked for (the ramp's pieces)."""
        power = 10**self.digits
        return [Fraction(n, power) for n in self.ticks.tolist()]

    def _time(self, j: int) -> Fraction:
        return Fraction(int(self.ticks[j]), 10**self.digits)

    def after(self, t: Fraction) -> float:
        return self._after(t, 0, len(self.ticks))

    def _after(self, t: Fraction, lo: int, hi: int) -> float:
        """after(t), given that the rows before lo are before t and those from hi after it."""
        j = count_at_most(self.ticks, self.digits, t, lo, hi)  # times[j-1] <= t < times[j]
        if j == len(self.ticks):
            return float(self.torques[-1])
        return float(self.torques[0]) if j == 0 else self._between(j, t)

    def before(self, t: Fraction) -> float:
        j = count_below(self.ticks, self.digits, t)  # times[j-1] < t <= times[j]
        if j == len(self.ticks):
            return float(self.torques[-1])
        return float(self.torques[0]) if j == 0 else self._between(j, t)

    def _between(self, j: int, t: Fraction) -> float:
        n0, n1 = int(self.ticks[j - 1]), int(self.ticks[j])
        u0, u1 = float(self.torques[j - 1]), float(self.torques[j])
        scaled = t * 10**self.digits
        # At a row's own time (a recorded torque's every point) no fraction need be divided.
        share = 0.0 if scaled == n0 else float((scaled - n0) / (n1 - n0))
        value = u0 + (u1 - u0) * share
        # docs/signals.md's form, unless rows near the largest double differ by inf.
        return value if math.isfinite(value) else u0 * (1 - share) + u1 * share

    def jumps(self) -> list[Fraction]:
        """The times that repeat (a jump), sorted, once each."""
        ticks = self.ticks
        repeated = np.unique(ticks[1:][ticks[1:] == ticks[:-1]]).tolist()
        return [Fraction(int(n), 10**self.digits) for n in repeated]

    def latest_event_near(self, t: Fraction, step: Fraction) -> Fraction:
        """t, or the latest row time within the tolerance of t: that event is at t."""
        return self._latest_event_near(t, step, 0, len(self.ticks))

    def _latest_event_near(self, t: Fraction, step: Fraction, lo: int, hi: int) -> Fraction:
        """latest_event_near(t), given that the rows before lo are before t less its tolerance
        and those from hi after t plus it.
        """
        tolerance = event_tolerance(t, step)
        j = count_at_most(self.ticks, self.digits, t + tolerance, lo, hi)
        if j > lo and (latest := self._time(j - 1)) >= t - tolerance:
            return max(t, latest)
        return t

    def held_after(
        self, points: Sequence[Fraction], step: Fraction, doubles: np.ndarray, exact: tuple[int, np.ndarray] | None
    ) -> np.ndarray:
        """after(latest_event_near(p, step)) of each point, the same values (doubles: each
        point's nearest double; exact: the points times 10**digits, as _decimal_times scales
        them, or None).

        The row times as doubles find the rows that may be within a point's tolerance (within
        reach) and those that surely are. A point with no row within reach on a flat stretch
        holds the row's value; one whose rows within reach surely all are within its tolerance
        is decided with the times as exact integers (exact), a whole array at once; every other
        point by the exact look-ups of fractions, narrowed to the rows within reach.
        """
        row_doubles, torques = self.doubles, self.torques
        tolerance = np.maximum(float(TOLERANCE_STEPS * step), TOLERANCE_ULPS * np.spacing(np.abs(doubles)))
        # What the doubles may be off by (each time's rounding, the tolerance's): a few ulp,
        # bounded here by 16.
        slack = 16 * np.spacing(np.maximum(np.abs(doubles), tolerance))
        # Rows before lo are exactly before p less its tolerance, rows from hi after p plus it.
        lo = np.searchsorted(row_doubles, doubles - (tolerance + slack), "left")
        hi = np.searchsorted(row_doubles, doubles + (tolerance + slack), "right")
        near, last = hi > lo, len(self.ticks) - 1
        # A point with no row within reach on a flat stretch holds the row's value.
        after = np.searchsorted(row_doubles, doubles, "right")  # times[j-1] <= p < times[j]
        before = np.clip(after - 1, 0, last)
        values = torques[before]
        unsure = near | (values != torques[np.minimum(after, last)])
        if exact is not None:
            rows = rescaled(self.ticks, exact[0] - self.digits)
            # Those whose rows within reach all surely are within the tolerance, the latest row
            # hi - 1, are decided in exact integers; the others below.
            inner = tolerance - slack
            decided = unsure & ~(
                near
                & (
                    (doubles - row_doubles[np.clip(lo, 0, last)] > inner)
                    | (row_doubles[np.clip(hi - 1, 0, last)] - doubles > inner)
                )
            )
            chosen = np.flatnonzero(decided)
            point = exact[1][chosen]
            event = np.where(near[chosen], np.maximum(point, rows[np.clip(hi[chosen] - 1, 0, last)]), point)
            values[chosen] = self._exact_value(rows, torques, event)
            unsure &= ~decided
        for k in np.flatnonzero(unsure).tolist():
            first, end = int(lo[k]), int(hi[k])
            values[k] = self._after(self._latest_event_near(points[k], step, first, end), first, end)
        return values

    def values_at(self, events: np.ndarray, digits: int, side: str) -> np.ndarray:
        """after() (side "after") or before() of each exact time, given times 10**digits (digits
        at least the rows'), a whole array at once.
        """
        return self._exact_value(rescaled(self.ticks, digits - self.digits), self.torques, events, side)

    @staticmethod
    def _exact_value(rows: np.ndarray, torques: np.ndarray, event: np.ndarray, side: str = "after") -> np.ndarray:
        """after() or before() of each exact integer time, as they and _between() compute it."""
        if len(rows) == 1:
            return np.full(len(event), torques[0])
        if side == "after":  # rows[j-1] <= t < rows[j]
            j = np.clip(np.searchsorted(rows, event, "right"), 1, len(rows) - 1)
            first, last = event < rows[0], event >= rows[-1]
        else:  # rows[j-1] < t <= rows[j]
            j = np.clip(np.searchsorted(rows, event, "left"), 1, len(rows) - 1)
            first, last = event <= rows[0], event > rows[-1]
        offset, length, u0, u1 = event - rows[j - 1], rows[j] - rows[j - 1], torques[j - 1], torques[j]
        # Python's integers are divided by Python, correctly rounded as float(Fraction) is; so is
        # one IEEE division of int64 below 2**53 (exact as doubles); larger int64 go to Python.
        share = np.zeros(len(event))
        exact = ~first & ~last & (offset != 0)
        if offset.dtype != object:
            by_numpy = exact & (np.abs(offset) < 2**53) & (length < 2**53)
            share[by_numpy] = offset[by_numpy] / length[by_numpy]
            exact &= ~by_numpy
        share[exact] = [a / b for a, b in zip(offset[exact].tolist(), length[exact].tolist(), strict=True)]
        with np.errstate(invalid="ignore", over="ignore"):
            value = u0 + (u1 - u0) * share
            value = np.where(np.isfinite(value), value, u0 * (1 - share) + u1 * share)
        return np.where(last, torques[-1], np.where(first, torques[0], value))


class FileRows:
    """A torque CSV read forward a chunk of lines at a time: rows(a, b) is the stretch of the
    file's rows that answers for the times a to b as the whole file does. Stretches asked for in
    time order read the file once; one asked for before the rows let go reads it again from the
    start. last is the last row's time.

    Only a file the schedule's reader accepted (read_torque_csv) is read here: its refusals come
    first, in its words. Its lines may end in a newline, a carriage return or both.
    """

    def __init__(self, path: Path):
        self.path = path
        # The file as it was first read: each chunk is read from it, or refused.
        self._file = ReadAgain(path, TorqueFileError, "judge once it is written")
        self._rewind()
        self.last = self._last_time()

    def _rewind(self) -> None:
        self._offset, self._end = 0, False
        self._columns: tuple[int, int, int] | None = None  # time's, torque's, how many
        self._ticks, self._digits = np.zeros(0, dtype=np.int64), 0
        self._doubles, self._torques = np.zeros(0), np.zeros(0)
        self._dropped = False  # whether rows before those held were let go

    def _raw(self) -> bytes:
        """The next chunk of whole lines (b"" at the end of the file), less a byte-order mark."""
        raw = self._file.block(self._offset, CHUNK_BYTES)
        first, self._offset = self._offset == 0, self._offset + len(raw)
        self._end = not raw
        return raw[3:] if first and raw.startswith(b"\xef\xbb\xbf") else raw

    def _read_chunk(self) -> None:
        first = self._offset == 0
        raw = self._raw()
        if self._columns is None:
            rows = csv.reader(io.StringIO(raw.decode("utf-8"), newline=""))
            names = [cell.strip() for cell in next(row for row in rows if any(cell.strip() for cell in row))]
            self._columns = (names.index("time"), names.index("torque"), len(names))
        time, torque, width = self._columns
        if self._file.size <= SMALL_FILE_BYTES:
            cells, torques = _python_cells(raw, time, torque, first=first)
            digits, ticks = ticks_of_cells(cells)
        else:
            arrow_cells, torques = _arrow_cells(raw, time, torque, width, first=first)
            digits, ticks = ticks_of_arrow(arrow_cells)
        common = max(digits, self._digits)
        self._ticks = np.concatenate([rescaled(self._ticks, common - self._digits), rescaled(ticks, common - digits)])
        self._digits = common
        self._doubles = np.concatenate([self._doubles, doubles_of(ticks, digits)])
        self._torques = np.concatenate([self._torques, torques])

    def _last_time(self) -> Fraction:
        """The last row's time, read from the file's end."""
        size, tail = self.path.stat().st_size, CHUNK_BYTES
        while True:
            with open(self.path, "rb") as file:
                file.seek(max(size - tail, 0))
                raw = file.read()
            whole = tail >= size
            rows = list(csv.reader(io.StringIO(raw.decode("utf-8-sig" if whole else "utf-8", "replace"), newline="")))
            # Past the first row, which a chunk from inside the file may begin halfway through;
            # a whole file's first row is its header.
            rows = [row for row in rows[1:] if any(cell.strip() for cell in row)]
            if rows or whole:
                break
            tail *= 2
        with open(self.path, newline="", encoding="utf-8-sig") as file:
            header = next(row for row in csv.reader(file) if any(cell.strip() for cell in row))
        return Fraction(rows[-1][[cell.strip() for cell in header].index("time")].strip())

    def rows(self, a: Fraction, b: Fraction) -> TorqueFile:
        """The rows at a to b, the rows at the latest time before a and those at the earliest
        after b: what answers, for a time from a to b, as the whole file does.
        """
        if self._dropped and not (len(self._ticks) and count_below(self._ticks, self._digits, a)):
            self._rewind()
        # Two rows past b: the rows at the earliest time after it (one, or a jump's two) are held.
        while not self._end and len(self._ticks) - count_at_most(self._ticks, self._digits, b) < 2:
            self._read_chunk()
        ticks = self._ticks
        start = count_below(ticks, self._digits, a)
        start = int(np.searchsorted(ticks, ticks[start - 1], "left")) if start else 0
        end = count_at_most(ticks, self._digits, b)
        end = int(np.searchsorted(ticks, ticks[end], "right")) if end < len(ticks) else end
        stretch = TorqueFile(ticks[start:end], self._digits, self._torques[start:end], self._doubles[start:end])
        # The rows before the stretch are let go: later stretches start later.
        self._ticks, self._torques, self._doubles = ticks[start:], self._torques[start:], self._doubles[start:]
        self._dropped |= start > 0
        return stretch


def _python_cells(raw: bytes, time: int, torque: int, first: bool) -> tuple[list[str], np.ndarray]:
    """A chunk's time cells and torques, by Python's csv reader (the header skipped in the first)."""
    rows = (row for row in csv.reader(io.StringIO(raw.decode("utf-8"), newline="")) if any(c.strip() for c in row))
    if first:
        next(rows)
    cells, torques = [], []
    for row in rows:
        cells.append(row[time])
        torques.append(float(row[torque]))
    return cells, np.array(torques, dtype=float)


def _arrow_cells(raw: bytes, time: int, torque: int, width: int, first: bool):
    """A chunk's time cells (a pyarrow array of strings) and torques, by pyarrow's C reader."""
    import pyarrow as pa
    import pyarrow.csv as pa_csv

    names = [f"c{i}" for i in range(width)]
    if not raw.strip():
        return pa.array([], pa.string()), np.zeros(0)
    table = pa_csv.read_csv(
        pa.py_buffer(raw),
        read_options=pa_csv.ReadOptions(column_names=names, skip_rows=int(first)),
        convert_options=pa_csv.ConvertOptions(
            include_columns=[names[time], names[torque]],
            column_types={names[time]: pa.string(), names[torque]: pa.float64()},
        ),
    )
    return table.column(names[time]).combine_chunks(), table.column(names[torque]).to_numpy()
