"""The oracle's own reader of a torque CSV: its rows as exact fractions of the decimals written
and float torques, read forward a chunk at a time (FileRows), a stretch of them at a time
(TorqueFile), so that a file of millions of rows is never held whole as fractions.
"""

from __future__ import annotations

import bisect
import csv
import io
import math
import os
from collections.abc import Sequence
from fractions import Fraction
from pathlib import Path

import numpy as np

from ..signals._torque_csv import TorqueFileError
from ._decimal_times import scaled

# Bytes read a chunk (some 25,000 rows of a recorded torque).
CHUNK_BYTES = 1 << 20
# docs/signals.md: an event within max(1e-9 step, 64 ulp of its time) of a communication point
# is that point. Written again here on purpose: the oracle must not borrow the schedule's code.
TOLERANCE_STEPS, TOLERANCE_ULPS = Fraction(1, 10**9), 64


def event_tolerance(time: Fraction | float, step: Fraction) -> Fraction:
    return max(TOLERANCE_STEPS * step, Fraction(TOLERANCE_ULPS * math.ulp(float(time))))


def decimal(written: str) -> Fraction:
    """The fraction a decimal cell is, as Fraction(written) reads it: one with a point and no
    exponent made from its digits, without Fraction's parsing of the text (thrice as long).
    """
    whole, point, digits = written.partition(".")
    if point and not ("e" in digits or "E" in digits):
        return Fraction(int(whole + digits), 10 ** len(digits))
    return Fraction(written)


class TorqueFile:
    """Consecutive rows of a time,torque CSV as exact times and float torques: linear between
    rows, a jump where a time repeats, held outside. A stretch of a file (FileRows.rows) answers
    as the whole file does for times inside it.
    """

    def __init__(self, times: list[Fraction], torques: list[float], doubles: Sequence[float]):
        # doubles: each time's nearest double (float of the decimal written, as float(times[i])).
        self.times, self.torques, self.doubles = times, torques, np.asarray(doubles, dtype=float)
        self._exact: tuple[int, np.ndarray] | None = None

    def after(self, t: Fraction) -> float:
        return self._after(t, 0, len(self.times))

    def _after(self, t: Fraction, lo: int, hi: int) -> float:
        """after(t), given that the rows before lo are before t and those from hi after it."""
        times, torques = self.times, self.torques
        if t >= times[-1]:
            return torques[-1]
        if t < times[0]:
            return torques[0]
        j = bisect.bisect_right(times, t, lo, hi)  # times[j-1] <= t < times[j]
        return self._between(j, t)

    def before(self, t: Fraction) -> float:
        times, torques = self.times, self.torques
        if t > times[-1]:
            return torques[-1]
        if t <= times[0]:
            return torques[0]
        j = bisect.bisect_left(times, t)  # times[j-1] < t <= times[j]
        return self._between(j, t)

    def _between(self, j: int, t: Fraction) -> float:
        t0, t1, u0, u1 = self.times[j - 1], self.times[j], self.torques[j - 1], self.torques[j]
        # At a row's own time (a recorded torque's every point) no fraction need be divided.
        share = 0.0 if t == t0 else float((t - t0) / (t1 - t0))
        value = u0 + (u1 - u0) * share
        # docs/signals.md's form, unless rows near the largest double differ by inf.
        return value if math.isfinite(value) else u0 * (1 - share) + u1 * share

    def jumps(self) -> list[Fraction]:
        return sorted({a for a, b in zip(self.times, self.times[1:], strict=False) if a == b})

    def latest_event_near(self, t: Fraction, step: Fraction) -> Fraction:
        """t, or the latest row time within the tolerance of t: that event is at t."""
        return self._latest_event_near(t, step, 0, len(self.times))

    def _latest_event_near(self, t: Fraction, step: Fraction, lo: int, hi: int) -> Fraction:
        """latest_event_near(t), given that the rows before lo are before t less its tolerance
        and those from hi after t plus it.
        """
        tolerance = event_tolerance(t, step)
        j = bisect.bisect_right(self.times, t + tolerance, lo, hi)
        return max(t, self.times[j - 1]) if j > lo and self.times[j - 1] >= t - tolerance else t

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
        times, row_doubles, torques = self.times, self.doubles, np.array(self.torques)
        tolerance = np.maximum(float(TOLERANCE_STEPS * step), TOLERANCE_ULPS * np.spacing(np.abs(doubles)))
        # What the doubles may be off by (each time's rounding, the tolerance's): a few ulp,
        # bounded here by 16.
        slack = 16 * np.spacing(np.maximum(np.abs(doubles), tolerance))
        # Rows before lo are exactly before p less its tolerance, rows from hi after p plus it.
        lo = np.searchsorted(row_doubles, doubles - (tolerance + slack), "left")
        hi = np.searchsorted(row_doubles, doubles + (tolerance + slack), "right")
        near, last = hi > lo, len(times) - 1
        # A point with no row within reach on a flat stretch holds the row's value.
        after = np.searchsorted(row_doubles, doubles, "right")  # times[j-1] <= p < times[j]
        before = np.clip(after - 1, 0, last)
        values = torques[before]
        unsure = near | (values != torques[np.minimum(after, last)])
        if exact is not None:
            rows = self._exact_rows(exact[0])
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
            values[chosen] = self._exact_after(rows, torques, event)
            unsure &= ~decided
        for k in np.flatnonzero(unsure).tolist():
            first, end = int(lo[k]), int(hi[k])
            values[k] = self._after(self._latest_event_near(points[k], step, first, end), first, end)
        return values

    def _exact_rows(self, digits: int) -> np.ndarray:
        """The row times times 10**digits in int64 (_decimal_times.scaled), made once a stretch."""
        if self._exact is None or self._exact[0] != digits:
            self._exact = (digits, scaled(self.times, digits))
        return self._exact[1]

    def denominators(self) -> set[int]:
        return {t.denominator for t in self.times}

    @staticmethod
    def _exact_after(rows: np.ndarray, torques: np.ndarray, event: np.ndarray) -> np.ndarray:
        """after() of each exact integer time, as after() and _between() compute it."""
        if len(rows) == 1:
            return np.full(len(event), torques[0])
        j = np.clip(np.searchsorted(rows, event, "right"), 1, len(rows) - 1)  # rows[j-1] <= t < rows[j]
        inside = (event >= rows[0]) & (event < rows[-1])
        offset, length, u0, u1 = event - rows[j - 1], rows[j] - rows[j - 1], torques[j - 1], torques[j]
        # Python's integers are divided by Python, correctly rounded as float(Fraction) is; so is
        # one IEEE division of int64 below 2**53 (exact as doubles); larger int64 go to Python.
        share = np.zeros(len(event))
        exact = inside & (offset != 0)
        if offset.dtype != object:
            by_numpy = exact & (np.abs(offset) < 2**53) & (length < 2**53)
            share[by_numpy] = offset[by_numpy] / length[by_numpy]
            exact &= ~by_numpy
        share[exact] = [a / b for a, b in zip(offset[exact].tolist(), length[exact].tolist(), strict=True)]
        with np.errstate(invalid="ignore", over="ignore"):
            value = u0 + (u1 - u0) * share
            value = np.where(np.isfinite(value), value, u0 * (1 - share) + u1 * share)
        return np.where(event >= rows[-1], torques[-1], np.where(event < rows[0], torques[0], value))


def _identity(status: os.stat_result) -> tuple[int, int, int, int]:
    """What tells a file from the same file changed or another moved to its path."""
    return status.st_dev, status.st_ino, status.st_size, status.st_mtime_ns


class FileRows:
    """A torque CSV read forward a chunk of lines at a time: rows(a, b) is the stretch of the
    file's rows that answers for the times a to b as the whole file does. Stretches asked for in
    time order read the file once; one asked for before the rows let go reads it again from the
    start. last is the last row's time.

    Only a file the schedule's reader accepted (read_torque_csv) is read here: its refusals come
    first, in its words. (A file whose lines end in a lone carriage return is one line to
    Python's readlines: it is read as one chunk.)
    """

    def __init__(self, path: Path):
        self.path = path
        # The file as it was first read: each chunk is read from it, or refused.
        self._identity = _identity(os.stat(path))
        self._rewind()
        self.last = self._last_time()

    def _rewind(self) -> None:
        self._offset, self._end = 0, False
        self._columns: tuple[int, int] | None = None
        self._times: list[Fraction] = []
        self._doubles: list[float] = []
        self._torques: list[float] = []
        self._dropped = False  # whether rows before those held were let go

    def _text(self) -> str:
        """The next chunk of whole lines ("" at the end of the file)."""
        with open(self.path, "rb") as file:
            if _identity(os.fstat(file.fileno())) != self._identity:
                raise TorqueFileError(
                    f"{self.path}: the file changed while it was read (a master still writing it, or "
                    "another file moved there); judge once it is written"
                )
            file.seek(self._offset)
            lines = file.readlines(CHUNK_BYTES)
            raw, first, self._offset = b"".join(lines), self._offset == 0, file.tell()
        self._end = not lines
        return raw.decode("utf-8-sig" if first else "utf-8")

    def _read_chunk(self) -> None:
        columns = self._columns
        for row in csv.reader(io.StringIO(self._text(), newline="")):
            if not any(cell.strip() for cell in row):
                continue
            if columns is None:
                names = [cell.strip() for cell in row]
                columns = self._columns = (names.index("time"), names.index("torque"))
                continue
            written = row[columns[0]].strip()
            self._times.append(decimal(written))
            self._doubles.append(float(written))  # the double nearest the decimal, as float(Fraction)
            self._torques.append(float(row[columns[1]]))

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
        times = self._times
        if self._dropped and not (times and times[0] < a):
            self._rewind()
            times = self._times
        # Two rows past b: the rows at the earliest time after it (one, or a jump's two) are held.
        while not self._end and len(times) - bisect.bisect_right(times, b) < 2:
            self._read_chunk()
        start = bisect.bisect_left(times, a)
        start = bisect.bisect_left(times, times[start - 1]) if start else 0
        end = bisect.bisect_right(times, b)
        end = bisect.bisect_right(times, times[end]) if end < len(times) else end
        stretch = TorqueFile(times[start:end], self._torques[start:end], self._doubles[start:end])
        # The rows before the stretch are let go: later stretches start later.
        del times[:start], self._torques[:start], self._doubles[:start]
        self._dropped |= start > 0
        return stretch
