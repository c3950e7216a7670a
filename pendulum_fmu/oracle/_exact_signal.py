"""The torque signal as the oracle reads it, on its own: times as exact fractions of the decimals
written, its own reader of a torque CSV (_file_rows.py), the communication points (Grid), the pieces
on which the torque is linear (Pieces, SignalWindows: a window of the run at a time) and the torque held at given times
(Holding). _reference.py integrates what this gives; docs/signals.md is the definition both follow.
"""

from __future__ import annotations

import bisect
import heapq
import math
import numbers
import os
from collections.abc import Callable, Sequence
from fractions import Fraction
from pathlib import Path

import numpy as np

from .._errors import InvalidInput
from ..signals._time_grid import step_count
from ..signals._torque_csv import TorqueFileError, check_torque_csv
from ._decimal_times import common_digits, doubles_of, rescaled, scaled, scaled_steps, ticks_of_cells
from ._file_rows import TOLERANCE_STEPS, TOLERANCE_ULPS, FileRows, TorqueFile, event_tolerance

# Times whose torque Holding looks up at once.
_BLOCK = 1 << 16
_DEFAULT_STOP_TIME = Fraction(3)
# Times: a Grid, a list of exact or double times, or an array of doubles; torques likewise.
Times = Sequence[Fraction | float] | np.ndarray
Values = Sequence[float] | np.ndarray


def exact_time(value) -> Fraction:
    """A number as the decimal a person wrote: 0.009 is 9/1000, not the double nearest it."""
    return Fraction(repr(float(value))) if not isinstance(value, (str, Fraction)) else Fraction(value)


def seconds(name: str, value) -> Fraction:
    """A time argument as the decimal a person wrote; InvalidInput unless a finite number."""
    if not (isinstance(value, numbers.Real) and math.isfinite(value)):
        raise InvalidInput(f"{name} {value!r} must be a finite number of seconds")
    return exact_time(value)


def torque_value(value, where: str) -> float:
    """A torque value of the signal; InvalidInput unless a finite number."""
    # A signal written with numpy may return a 0-d array (np.where, np.interp of a scalar).
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf":
        value = value.item()
    if not (isinstance(value, numbers.Real) and math.isfinite(value)):
        raise InvalidInput(f"the torque is {value!r} {where}; it must be a finite number of N.m")
    return float(value)


class Grid(Sequence[Fraction]):
    """start + k*step for k < regular, then stop where it is given: the grid as exact fractions,
    each made only when asked for (a run of millions of steps holds none of them), and as
    doubles in one array (doubles()).
    """

    def __init__(self, start: Fraction, step: Fraction, regular: int, stop: Fraction | None):
        self.start, self.step, self.regular, self.stop = start, step, regular, stop

    def __len__(self) -> int:
        return self.regular + (self.stop is not None)

    def __getitem__(self, k):
        if isinstance(k, slice):
            if k == slice(None, -1, None) and len(self):  # the steps' starts: the grid less its end
                return Grid(self.start, self.step, self.regular - (self.stop is None), None)
            return [self[i] for i in range(*k.indices(len(self)))]
        if k < 0:
            k += len(self)
        if not 0 <= k < len(self):
            raise IndexError(k)
        return self.start + k * self.step if k < self.regular else self.stop

    def doubles(self) -> np.ndarray:
        """Each point as the double nearest it (float of the fraction), in one array."""
        (a, b), (c, d) = self.start.as_integer_ratio(), self.step.as_integer_ratio()
        # (a*d + k*c*b) / (b*d): exact integers below 2**53 are exact doubles, and one IEEE
        # division of them is correctly rounded, as float(Fraction) is.
        if max(abs(a * d), abs(a * d + (self.regular - 1) * c * b), b * d) < 2**53:
            out = (a * d + np.arange(self.regular, dtype=np.int64) * (c * b)) / float(b * d)
        else:
            out = np.array([float(self.start + k * self.step) for k in range(self.regular)])
        return out if self.stop is None else np.append(out, float(self.stop))


class DecimalTimes(Sequence[Fraction]):
    """Exact decimal times held as integers, the times 10**digits (ticks): each made a fraction
    only when asked for, and as doubles in one array (doubles()).
    """

    def __init__(self, ticks: np.ndarray, digits: int):
        self.ticks, self.digits = ticks, digits

    def __len__(self) -> int:
        return len(self.ticks)

    def __getitem__(self, k):
        if isinstance(k, slice):
            return DecimalTimes(self.ticks[k], self.digits)
        return Fraction(int(self.ticks[k]), 10**self.digits)

    def doubles(self) -> np.ndarray:
        return doubles_of(self.ticks, self.digits)


def reported_after(signal: TorqueFile, times: np.ndarray, step: Fraction) -> np.ndarray:
    """signal.after(signal.latest_event_near(exact_time(t), step)) of each time (s), a whole
    array at once (held_after), each time read as the decimal a person wrote (exact_time).
    """
    times = np.asarray(times, dtype=float)
    digits, ticks = ticks_of_cells([repr(t) for t in times.tolist()])
    common = max(digits, signal.digits)
    return signal.held_after(DecimalTimes(ticks, digits), step, times, (common, rescaled(ticks, common - digits)))


def rows_off_grid(grid: Grid, signal: TorqueFile, step: Fraction) -> list[Fraction]:
    """off_grid(grid, signal.times, step): the rows surely within the tolerance of a grid point
    (a recorded torque's every row) found with doubles, a whole array at once; the others
    decided by off_grid in fractions.
    """
    doubles, points = signal.doubles, grid.doubles()
    j = np.clip(np.searchsorted(points, doubles), 1, len(points) - 1)
    distance = np.minimum(np.abs(points[j] - doubles), np.abs(doubles - points[j - 1]))
    tolerance = np.maximum(float(TOLERANCE_STEPS * step), TOLERANCE_ULPS * np.spacing(np.abs(doubles)))
    # What the doubles may be off by (each time's rounding, the difference's and the
    # tolerance's): a few ulp, bounded here by 16.
    slack = 16 * np.spacing(np.maximum(np.abs(doubles), tolerance))
    unsure = np.flatnonzero(~(distance < tolerance - slack)).tolist()
    return off_grid(grid, [Fraction(int(signal.ticks[k]), 10**signal.digits) for k in unsure], step)


def time_doubles(points: Times) -> np.ndarray:
    """A sequence of times (a Grid, DecimalTimes, fractions or doubles) as an array of doubles."""
    if isinstance(points, (Grid, DecimalTimes)):
        return points.doubles()
    if isinstance(points, np.ndarray):
        return points.astype(float)
    return np.array([float(p) for p in points])


def exact_times(points: Sequence[Fraction], signal: TorqueFile) -> tuple[int, np.ndarray] | None:
    """The points times 10**digits (_decimal_times), digits those of a decimal denominator
    common to the points and the signal's rows; None where there is none.
    """
    stop = [points.stop] if isinstance(points, Grid) and points.stop is not None else []
    ends = [points.start, points.step, *stop] if isinstance(points, Grid) else points
    digits = common_digits(t.denominator for t in ends)
    if digits is None:
        return None
    digits = max(digits, signal.digits)
    if not isinstance(points, Grid):
        return digits, scaled(points, digits)
    regular = scaled_steps(points.start, points.step, points.regular, digits)
    return digits, np.concatenate([regular, scaled(stop, digits)])


def time_grid(
    start: Fraction, stop: Fraction, step: Fraction, max_steps: int | None = None, check_memory: bool = True
) -> Grid:
    """Start + k*step up to stop; stop itself ends a shorter last step unless it is on the grid."""
    # Only checked by the schedule's code, in simulate()'s words (a step that is not positive, a
    # stop not after the start, a run too long to hold): the grid below is the oracle's own.
    step_count(float(start), float(stop), float(step), max_steps, check_memory=check_memory)
    # The points start + k*step before stop less its tolerance: k < (last - start) / step.
    last = stop - event_tolerance(stop, step)
    return Grid(start, step, max(math.ceil((last - start) / step), 0), stop)


def off_grid(grid: Grid, events: list[Fraction], step: Fraction) -> list[Fraction]:
    """The events inside the grid not within the tolerance of a grid point, sorted, once each."""
    extra = set()
    for event in events:
        if not grid[0] < event < grid[-1]:
            continue
        j = bisect.bisect_left(grid, event)
        if min(grid[j] - event, event - grid[j - 1]) > event_tolerance(event, step):
            extra.add(event)
    return sorted(extra)


def with_events(grid: Grid, events: list[Fraction], step: Fraction) -> Sequence[Fraction]:
    """The grid plus every event inside it that is not within the tolerance of a grid point."""
    return with_extra(grid, off_grid(grid, events, step))


def with_extra(grid: Grid, extra: list[Fraction]) -> Sequence[Fraction]:
    """The grid plus the events of extra (off_grid's of the run) strictly inside it."""
    inside = extra[bisect.bisect_right(extra, grid[0]) : bisect.bisect_left(extra, grid[-1])]
    if not inside:  # the grid as it is, its points made only when asked for
        return grid
    # The grid is sorted and no extra event is on it: merged, not sorted anew.
    return list(heapq.merge(grid, inside))


class Pieces:
    """The torque as pieces [start, end) on which it is u0 + rate * (t - start), the
    communication points the signal defines, and the torque just after each of an array of times.
    """

    def __init__(
        self,
        starts: Times,
        stop: Fraction | float,
        u0: Values,
        rate: Values,
        points: Times,
        values_after: Callable[[np.ndarray], np.ndarray],
    ):
        self.starts, self.stop, self.u0, self.rate = starts, stop, u0, rate
        self.points, self.values_after = points, values_after


class SignalWindows:
    """A signal checked once, its pieces made a window of grid steps at a time: window(k0, k1) is
    the pieces of the oracle's own grid steps k0 to k1 (and the events between them), so that a
    run of millions of steps holds one window's pieces at a time. A CSV's rows are read as the
    windows are made, those near a window at a time (FileRows).
    """

    def __init__(
        self,
        torque,
        start: Fraction,
        stop: Fraction | None,
        step: Fraction,
        ramp: bool,
        max_steps: int | None,
        *,
        check_memory: bool = True,
    ):
        self.step, self.ramp = step, ramp
        self.file: FileRows | None = None
        self.values: np.ndarray | None = None
        self.sample: Callable | None = None
        # A callable's sample at the end of the window last made, for the next one to start from.
        self._carried: tuple[int, float] | None = None
        if isinstance(torque, (str, Path)):
            if os.path.exists(torque) and not (os.path.isfile(torque) or os.path.isdir(torque)):
                raise TorqueFileError(
                    f"{torque}: the reference reads the torque file on its own, again, which a pipe "
                    "cannot be; save it to a file and give that"
                )
            # (The tools' reader may have read a pipe already, whole.)
            check_torque_csv(torque)  # a file that is no signal refused where it is wrong; read below anew
            self.file = FileRows(Path(torque))
            stop = self.file.last if stop is None else stop
            self.grid = time_grid(start, stop, step, max_steps, check_memory)
        elif isinstance(torque, (list, tuple, np.ndarray)):
            self.values = np.fromiter(
                (torque_value(u, f"at step {k} of the array") for k, u in enumerate(torque)), float, len(torque)
            )
            self.grid = time_grid(
                start, start + len(self.values) * step if stop is None else stop, step, max_steps, check_memory
            )
            if len(self.grid) - 1 != len(self.values):
                raise InvalidInput(f"the torque array has {len(self.values)} values for {len(self.grid) - 1} steps")
        else:
            self.grid = time_grid(start, _DEFAULT_STOP_TIME if stop is None else stop, step, max_steps, check_memory)
            if callable(torque):
                self.sample = torque
            else:  # a constant: checked once, at the first point, as a callable's first sample is
                self.constant = torque_value(torque, f"at t = {float(self.grid[0])}")
        self.steps = len(self.grid) - 1

    def window_grid(self, k0: int, k1: int) -> Grid:
        """The grid points k0 to k1, as fractions made only when asked for."""
        grid = self.grid
        end = grid.stop if k1 == self.steps else grid.start + k1 * grid.step
        return Grid(grid.start + k0 * grid.step, grid.step, k1 - k0, end)

    def window(self, k0: int, k1: int) -> Pieces:
        """The pieces of grid steps k0 to k1; their values_after holds, past the window's end (a
        report there), the value the next window starts with, unless the run ends there.
        """
        grid, step, final = self.window_grid(k0, k1), self.step, k1 == self.steps
        u0: Values
        rate: Values
        values: Values
        if self.file is not None:
            signal = self._rows(grid)
            points = with_events(grid, signal.jumps(), step)
            if self.ramp:
                return self._ramp_pieces(grid, signal)
            held_points = points[:-1] if final else points
            held = signal.held_after(held_points, step, time_doubles(held_points), exact_times(held_points, signal))
            u0 = held[: len(points) - 1]
            return Pieces(
                points[:-1], grid[-1], u0, np.zeros(len(u0)), points, Holding(points, held, step).values_after
            )
        if self.values is not None:
            values = self.values[k0 : k1 + 1]
        elif self.sample is None:
            values = np.full(k1 - k0 + 1, self.constant)
        else:
            values = self._samples(k0, grid)
        if self.ramp and self.sample is not None:
            rate = [(b - a) / float(t1 - t0) for a, b, t0, t1 in zip(values, values[1:], grid, grid[1:], strict=False)]
        else:  # held, or a constant's ramp: no slope
            rate = np.zeros(k1 - k0)
        u0 = values[: k1 - k0]
        return Pieces(grid[:-1], grid[-1], u0, rate, grid, Holding(grid, u0 if final else values, step).values_after)

    def _ramp_pieces(self, grid: Grid, signal: TorqueFile) -> Pieces:
        """The file's own piecewise-linear signal: a piece between consecutive row times (and the
        window's ends), each time, torque and rate found in exact integers, a window at once.
        """
        step, start, stop = self.step, grid[0], grid[-1]
        ends_digits = common_digits([start.denominator, stop.denominator])
        assert ends_digits is not None, "a window's ends are decimals"
        digits = max(signal.digits, ends_digits)
        ends, rows = scaled([start, stop], digits), rescaled(signal.ticks, digits - signal.digits)
        ticks = np.unique(np.concatenate([ends[:1], rows[(rows > ends[0]) & (rows < ends[1])], ends[1:]]))
        u0 = signal.values_at(ticks[:-1], digits, "after")
        rate = (signal.values_at(ticks[1:], digits, "before") - u0) / doubles_of(np.diff(ticks), digits)
        points = with_extra(grid, rows_off_grid(grid, signal, step))
        return Pieces(
            DecimalTimes(ticks[:-1], digits), stop, u0, rate, points, lambda times: reported_after(signal, times, step)
        )

    def _rows(self, grid: Grid) -> TorqueFile:
        """The file's rows that answer for the window's times, its reports' and their tolerances."""
        assert self.file is not None, "a CSV's rows are read"
        first, last = grid[0], grid[-1]
        # A step's margin: far wider than any tolerance the look-ups add to a time.
        margin = self.step + 2 * event_tolerance(max(abs(first), abs(last)), self.step)
        return self.file.rows(first - margin, last + margin)

    def _samples(self, k0: int, grid: Grid) -> list[float]:
        """The callable at each point of the window, once a point as the windows are walked."""
        sample, values = self.sample, []
        assert sample is not None, "a callable's signal is sampled"
        doubles = time_doubles(grid).tolist()
        if self._carried is not None and self._carried[0] == k0:
            values, doubles = [self._carried[1]], doubles[1:]
        values += [torque_value(sample(p), f"at t = {p}") for p in doubles]
        self._carried = (k0 + len(values) - 1, values[-1])
        return values


class Holding:
    """The torque just after t of a signal holding values[k] from points[k]: the step holding t
    is the one starting at the latest point at or (within the tolerance) just after t.

    value_after(t) decides it in exact fractions. values_after(times) decides a whole array with
    the points as doubles, looked up once; a time whose reach (t plus its tolerance) lies within
    rounding of a point, where doubles cannot tell the side, is decided by value_after.
    """

    def __init__(self, points: Times, values: Values, step: Fraction):
        self.points, self.values, self.step = points, values, step
        self._point_doubles = time_doubles(points)
        self._value_doubles = np.array(values, dtype=float)
        self._step_tolerance = float(TOLERANCE_STEPS * step)

    def value_after(self, t: Fraction) -> float:
        """The value held just after the exact time t."""
        j = max(bisect.bisect_right(self.points, t + event_tolerance(t, self.step)) - 1, 0)
        return self.values[min(j, len(self.values) - 1)]

    def values_after(self, times: np.ndarray) -> np.ndarray:
        """value_after of each time, read as the decimal a person wrote (exact_time)."""
        times = np.asarray(times, dtype=float)
        out = np.empty(len(times))
        # A block at a time: a dozen arrays of a block's times, not of millions.
        for begin in range(0, len(times), _BLOCK):
            out[begin : begin + _BLOCK] = self._values_after(times[begin : begin + _BLOCK])
        return out

    def _values_after(self, times: np.ndarray) -> np.ndarray:
        tolerance = np.maximum(self._step_tolerance, TOLERANCE_ULPS * np.spacing(np.abs(times)))
        reach = times + tolerance
        points = self._point_doubles
        j = np.searchsorted(points, reach, side="right") - 1
        below, above = points[np.clip(j, 0, len(points) - 1)], points[np.clip(j + 1, 0, len(points) - 1)]
        # What the doubles may be off by: the decimal of t and its double, the tolerance's and the
        # sum's roundings, each point's double; a few ulp of the largest magnitude, bounded
        # here by 16.
        scale = np.abs(times)  # the largest magnitude, one array at a time (not five stacked)
        for other in (tolerance, reach, below, above):
            np.maximum(scale, np.abs(other), out=scale)
        margin = 16 * np.spacing(scale)
        near = (np.abs(reach - below) <= margin) | (np.abs(above - reach) <= margin)
        out = self._value_doubles[np.clip(j, 0, len(self.values) - 1)]
        for i in np.flatnonzero(near).tolist():
            out[i] = self.value_after(exact_time(times[i]))
        return out
