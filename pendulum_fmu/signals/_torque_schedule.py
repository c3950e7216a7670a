"""Torque signals and the step-wise schedule a master feeds the FMU.

(A CSV is read by _torque_csv.py; the communication points come from _time_grid.py.)

A signal is one of:
- a constant (N.m);
- a callable of time, sampled at each step's start;
- a per-step array (one held value per communication step);
- a CSV file in fmpy's convention.

A CSV defines torque(t) for every t:
- held before its first row and after its last;
- linear between rows;
- a jump where a time repeats.

Its row times are events: jumps, and kinks where the slope may change. An event within
`event_tolerance` of a communication point *is* that point, so the step that starts there gets
the value after a jump. This holds for decimal times and for running-sum times alike
(0.39100000000000029 is 0.391). docs/signals.md states the definition in full.

A schedule is what one simulation applies:
- communication points `time[0..N]`;
- for each step k, the torque at its start, `torque[k]`;
- for each step k, its rate, `torque_rate[k]` (zero when the torque is held).

Held mode holds the signal's value just after each step's start, and a jump between grid points
becomes a communication point. Ramp mode makes every row time a communication point, so the
FMU's linear ramp over each step is the CSV's own piecewise-linear signal, exactly.
"""

from __future__ import annotations

import inspect
import numbers
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from .._errors import InvalidInput
from ._time_grid import WINDOW_STEPS, event_tolerance, grid_points, nearest, step_count
from ._torque_csv import TorqueTable, read_torque_csv
from ._torque_rows import HeldRows, TorqueCsv, torque_rows

TorqueSignal = (
    float
    | int
    | Callable[[float], float]
    | str
    | Path
    | Sequence[float]
    | np.ndarray
    | TorqueTable
    | TorqueCsv
    | HeldRows
)

# stop_time without a CSV to take it from.
DEFAULT_STOP_TIME = 3.0


@dataclass(frozen=True)
class TorqueSchedule:
    """What one simulation applies, step by step: made by schedule() (see the module's docstring).

    Step k runs from time[k] to time[k + 1] and applies torque[k] + torque_rate[k] * (t - time[k]).

    Attributes
    ----------
    time : numpy.ndarray
        The N + 1 communication points, in s.
    torque : numpy.ndarray
        The N torques at each step's start, in N.m.
    torque_rate : numpy.ndarray
        The N rates over each step, in N.m/s (zero where the torque is held).
    step_size : numpy.ndarray
        The N step lengths, in s.

    Examples
    --------
    >>> from pendulum_fmu import schedule
    >>> plan = schedule(lambda t: 4.0 * t, stop_time=0.75, step_size=0.25, ramp=True)
    >>> plan.time.tolist(), plan.torque.tolist(), plan.torque_rate.tolist()
    ([0.0, 0.25, 0.5, 0.75], [0.0, 1.0, 2.0], [4.0, 4.0, 4.0])
    >>> plan.step_size.tolist()
    [0.25, 0.25, 0.25]
    """

    time: np.ndarray
    torque: np.ndarray
    torque_rate: np.ndarray

    @cached_property  # works on a frozen dataclass: it writes the instance's __dict__ directly
    def step_size(self) -> np.ndarray:
        """The length of each step, in s."""
        return np.diff(self.time)


def _checked_array(values, ramp: bool) -> np.ndarray:
    """A per-step array as floats, or InvalidInput in schedule()'s words."""
    try:
        torque = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise InvalidInput(
            f"a torque array needs one value per step, each a number in N.m; got {_shortened(values)}"
        ) from None
    if torque.ndim != 1 or len(torque) == 0:
        raise InvalidInput(
            f"a torque array needs one value per step (a flat list of numbers); got shape {torque.shape}"
        )
    if ramp:
        raise InvalidInput("a per-step torque array is held over each step; ramp needs a CSV or a callable")
    return torque


def _shortened(values) -> str:
    text = repr(values)
    return text if len(text) <= 60 else text[:57] + "..."


def _takes_time(function: Callable, times: list[float]) -> list[float]:
    """times, once the function is known to take one argument, the time in s."""
    try:
        inspect.signature(function).bind(times[0])
    except TypeError as error:
        raise InvalidInput(
            f"a torque callable takes the time in s and returns N.m; "
            f"{getattr(function, '__name__', 'it')} cannot: {error}"
        ) from None
    except ValueError:  # no signature to read (some builtins): calling it will tell
        pass
    return times


def _sample(function: Callable, t: float) -> float:
    value = function(t)
    if not isinstance(value, numbers.Real):
        raise InvalidInput(
            f"the torque callable returned {_shortened(value)} at t = {t}; it must return a number in N.m"
        )
    return float(value)


def schedule(
    torque: TorqueSignal,
    *,
    start_time: float = 0.0,
    stop_time: float | None = None,
    step_size: float = 1e-3,
    ramp: bool = False,
    max_steps: int | None = None,
) -> TorqueSchedule:
    """The schedule of a signal: the communication points and the torque each step applies.

    See the module's docstring (and docs/signals.md) for what each step applies.

    Parameters
    ----------
    torque : float, callable, sequence of float, str or Path
        A constant (N.m), a callable of time (s) sampled at each step's start, a per-step array
        (one held value per step), or a torque CSV in fmpy's convention (time,torque).
    start_time : float, optional
        The first communication point, in s.
    stop_time : float, optional
        The last, in s; default: a CSV's last time, an array's last step, or 3 s.
    step_size : float, optional
        The communication step, in s; a CSV's jumps between grid points add points.
    ramp : bool, optional
        Ramp the torque linearly over each step (a CSV or a callable) instead of holding it.
    max_steps : int, optional
        The most steps a run may take (default 10 000 000), against a typo in a time.

    Returns
    -------
    TorqueSchedule
        time (N + 1 points), torque and torque_rate (N steps).

    Raises
    ------
    InvalidInput
        A time, step or signal the package refuses (not finite, not positive, too many steps,
        a ramp of a per-step array).
    TorqueFileError
        A CSV that cannot be read as a signal.

    Examples
    --------
    >>> from pendulum_fmu import schedule
    >>> plan = schedule(20.0, stop_time=0.003)
    >>> plan.time.tolist(), plan.torque.tolist()
    ([0.0, 0.001, 0.002, 0.003], [20.0, 20.0, 20.0])
    >>> schedule([5.0, 7.0], step_size=0.5).time.tolist()  # an array's steps set the stop time
    [0.0, 0.5, 1.0]
    """
    signal = _Signal(torque, start_time, stop_time, step_size, ramp, max_steps, check_memory=True, streamed=False)
    # The whole run is one window: the windows' code, so that the two cannot part.
    return signal.window(0, signal.steps)


def schedule_windows(
    torque: TorqueSignal,
    *,
    start_time: float = 0.0,
    stop_time: float | None = None,
    step_size: float = 1e-3,
    ramp: bool = False,
    max_steps: int | None = None,
    window_steps: int = WINDOW_STEPS,
) -> ScheduleWindows:
    """schedule()'s schedule a window of grid steps at a time, for a run too long to hold whole.

    Window j covers the grid steps k0 = j * window_steps to k1 = min(k0 + window_steps, N): its
    time is the grid points k0 to k1 and the events strictly between them (a held CSV's jumps off
    the grid, a ramped CSV's row times), its torque and torque_rate those of its steps.
    Consecutive windows share their boundary point; the windows joined, each later one less its
    first point, are schedule()'s arrays bit for bit.

    Every check schedule() makes of the times, the signal and max_steps is made here, at the
    call, in its words: a CSV is checked here, a block at a time, then read again for its events
    off the grid, and again as the windows are made (_torque_rows.py). Only what depends on the
    value at a point is found in the window holding it: a callable's value that is not finite, a
    ramp past the largest double. A callable is sampled once a point (the boundary's sample is
    carried to the next window). Memory: no array of the whole run is made (nor is the machine's
    free memory checked against one); a window holds O(window_steps + the CSV rows inside it and
    a block's), beside a TorqueTable or a per-step array given, which is the caller's. A CSV
    checked already (a TorqueCsv) is not checked again.

    Parameters
    ----------
    torque, start_time, stop_time, step_size, ramp, max_steps
        As schedule() takes them.
    window_steps : int, optional
        Grid steps per window (default WINDOW_STEPS); the last window may have fewer.

    Returns
    -------
    iterator of TorqueSchedule
        The windows, in time order.

    Raises
    ------
    InvalidInput, TorqueFileError
        As schedule() raises them, at the call; a sample or a ramp refused, when its window is
        made.

    Examples
    --------
    >>> from pendulum_fmu.signals._torque_schedule import schedule_windows
    >>> [w.time.tolist() for w in schedule_windows(20.0, stop_time=0.005, window_steps=2)]
    [[0.0, 0.001, 0.002], [0.002, 0.003, 0.004], [0.004, 0.005]]
    """
    if not (isinstance(window_steps, numbers.Integral) and window_steps >= 1):
        raise InvalidInput(f"window steps {window_steps!r} must be a whole number of steps, at least 1")
    signal = _Signal(torque, start_time, stop_time, step_size, ramp, max_steps, check_memory=False, streamed=True)
    return ScheduleWindows(signal, int(window_steps))


class ScheduleWindows(Iterator[TorqueSchedule]):
    """schedule_windows' windows, in time order, and what is known of the run before they are
    made: its first and last communication points (start_time, stop_time, s), its grid steps
    and its windows.
    """

    def __init__(self, signal: _Signal, window_steps: int):
        self._signal, self._window_steps = signal, window_steps
        self.steps = signal.steps
        self.windows = -(-signal.steps // window_steps)
        self.start_time, self.stop_time = (
            float(t) for t in signal.points(0, 0)[:1].tolist() + signal.points(signal.steps, signal.steps).tolist()
        )
        self._k0 = 0

    def __next__(self) -> TorqueSchedule:
        if self._k0 >= self.steps:
            raise StopIteration
        k0, self._k0 = self._k0, self._k0 + self._window_steps
        return self._signal.window(k0, min(self._k0, self.steps))


class _Signal:
    """A signal checked, and a CSV read, once; its schedule made a window of grid steps at a time."""

    def __init__(
        self,
        torque: TorqueSignal,
        start_time: float,
        stop_time: float | None,
        step_size: float,
        ramp: bool,
        max_steps: int | None,
        *,
        check_memory: bool,
        streamed: bool,
    ):
        self.source, self.ramp, self.step_size = "the torque table", ramp, step_size
        self.table: TorqueCsv | HeldRows | None = None
        self.values: np.ndarray | None = None
        self.function: Callable | None = None
        self.constant = 0.0
        # A callable's sample at the end of the window last made, for the next one to start from.
        self._carried: tuple[int, float] | None = None
        if isinstance(torque, (str, Path)):
            # A run made whole holds the table anyway: read whole, into arrays of its size.
            self.source, torque = str(torque), torque_rows(torque) if streamed else HeldRows(read_torque_csv(torque))
        elif isinstance(torque, TorqueTable):
            torque = HeldRows(torque)
        elif isinstance(torque, TorqueCsv):
            self.source = str(torque.path)
        if isinstance(torque, (list, tuple, np.ndarray)):
            self.values = _checked_array(torque, ramp)
            if stop_time is None:
                stop_time = start_time + len(self.values) * step_size
            self._count(start_time, stop_time, max_steps, check_memory)
            if self.steps != len(self.values):
                raise InvalidInput(
                    f"the torque array has {len(self.values)} values but {start_time:g} to {stop_time:g} s "
                    f"in steps of {step_size:g} s is {self.steps} steps; give one value per step or "
                    "leave out the stop time"
                )
            bad = np.flatnonzero(~np.isfinite(self.values))
            if len(bad):
                raise InvalidInput(f"the torque array's value {bad[0]} is {self.values[bad[0]]}; values must be finite")
        elif isinstance(torque, (TorqueCsv, HeldRows)):
            stop = torque.last if stop_time is None else stop_time
            if stop <= start_time and stop_time is None:
                raise InvalidInput(
                    f"{self.source} ends at {stop:g} s, not after the start time {start_time:g} s; give a stop time"
                )
            self._count(start_time, stop, max_steps, check_memory)
            # The table as given (the caller's, not copied) or read a block at a time, snapped a
            # window's rows at a time.
            self.table, self._reader = torque, torque.rows()
            self.events = self._events()
        else:
            self._count(start_time, DEFAULT_STOP_TIME if stop_time is None else stop_time, max_steps, check_memory)
            first = self.points(0, 0)
            if callable(torque):
                self.function = torque
                _takes_time(torque, first.tolist())
            else:
                try:
                    # Whatever else it is is tried as a number: float() refuses what is none.
                    self.constant = float(torque)  # type: ignore[arg-type]
                except (TypeError, ValueError):
                    raise InvalidInput(
                        f"a torque is a number, a callable of time, a per-step array or a CSV "
                        f"path; got {type(torque).__name__}"
                    ) from None
                _check_finite(np.array([self.constant]), first)

    def _count(self, start_time: float, stop_time: float, max_steps: int | None, check_memory: bool) -> None:
        self.start_time, self.stop_time = start_time, stop_time
        self.steps = step_count(start_time, stop_time, self.step_size, max_steps, check_memory=check_memory)

    def _grid(self, k: np.ndarray) -> np.ndarray:
        return grid_points(self.start_time, self.stop_time, self.step_size, self.steps, k)

    def points(self, k0: int, k1: int) -> np.ndarray:
        """The grid points k0 to k1, as the whole run's grid holds them."""
        return self._grid(np.arange(k0, k1 + 1))

    def _points_near(self, times: np.ndarray) -> np.ndarray:
        """The grid points around each time: nearest() of them is nearest() of the whole grid,
        found without it (the two points either side of each time, and a margin for rounding).
        """
        with np.errstate(over="ignore", invalid="ignore"):
            guess = np.clip(np.floor((times - self.start_time) / self.step_size), 0, self.steps)
        near = np.clip(guess[:, None] + np.arange(-2, 4), 0, self.steps).astype(np.int64).ravel()
        # Sorted rows' points nearly in order: a stable (merging) sort is some 6 times quicker
        # than np.unique's hashing of them.
        near.sort(kind="stable")
        return self._grid(near[np.flatnonzero(np.diff(near, prepend=-1))])

    def _snapped(self, table: TorqueTable) -> TorqueTable:
        """The rows snapped onto the grid, row by row: a stretch's as in the whole table."""
        return table.snapped(self._points_near(table.time), self.step_size)

    def _events(self) -> np.ndarray:
        """The snapped table's events off the grid (_off_grid), found a block of rows at a time."""
        assert self.table is not None, "a CSV's events"
        found, before = [], TorqueTable(np.empty(0), np.empty(0))
        for block in self.table.blocks():
            # A block after the first starts with the row before it, for a jump across the border.
            rows = self._snapped(TorqueTable(np.r_[before.time, block.time], np.r_[before.torque, block.torque]))
            found.append(self._off_grid(rows.time[len(before.time) :] if self.ramp else rows.jumps()))
            if len(block.time):
                before = TorqueTable(block.time[-1:], block.torque[-1:])
        return np.unique(np.concatenate(found))

    def _rows_near(self, time: np.ndarray) -> TorqueTable:
        """The snapped rows that answer for time[0] to time[-1] as the whole snapped table does."""
        reach = max(abs(time[0]), abs(time[-1]))
        margin = self.step_size + 2 * event_tolerance(reach, self.step_size)
        return self._snapped(self._reader.near(time[0] - margin, time[-1] + margin))

    def _off_grid(self, events: np.ndarray) -> np.ndarray:
        """The events strictly inside the run not within event_tolerance of a grid point, sorted."""
        first, last = self._grid(np.array([0, self.steps]))
        events = np.unique(events[(events > first) & (events < last)])
        if len(events):
            distance = np.abs(nearest(self._points_near(events), events) - events)
            events = events[distance > event_tolerance(events, self.step_size)]
        return events

    def window(self, k0: int, k1: int) -> TorqueSchedule:
        """The schedule of grid steps k0 to k1: the points, the events between them, the torques."""
        time = self.points(k0, k1)
        if self.table is not None:
            lo, hi = np.searchsorted(self.events, time[0], "right"), np.searchsorted(self.events, time[-1])
            inside = self.events[lo:hi]
            time = np.union1d(time, inside) if len(inside) else time
            rows = self._rows_near(time)
            start_values, end_values = rows.value_after(time[:-1]), rows.value_before(time[1:])
        elif self.values is not None:
            start_values = end_values = self.values[k0:k1]
        else:
            samples = self._samples(k0, time)
            start_values, end_values = samples[:-1], samples[1:]
        if not self.ramp:
            return TorqueSchedule(time=time, torque=start_values, torque_rate=np.zeros(len(time) - 1))
        with np.errstate(over="ignore", invalid="ignore"):
            rate = (end_values - start_values) / np.diff(time)
        steep = np.flatnonzero(~np.isfinite(rate))
        if len(steep):
            k = steep[0]
            raise InvalidInput(
                f"{self.source if self.table is not None else 'the torque'} ramps from "
                f"{start_values[k]:g} to {end_values[k]:g} N.m between t = {time[k]:g} and "
                f"{time[k + 1]:g} s, a rate past the largest double: hold the torque "
                "(no ramp) or give values that change less steeply"
            )
        return TorqueSchedule(time=time, torque=start_values, torque_rate=rate)

    def _samples(self, k0: int, time: np.ndarray) -> np.ndarray:
        """The signal at each point: a constant's value, or a callable's samples, each point once."""
        if self.function is None:
            return np.full(len(time), self.constant)
        samples = np.empty(len(time))
        first = 0
        if self._carried is not None and self._carried[0] == k0:
            samples[0], first = self._carried[1], 1
        function = self.function
        for i, t in enumerate(time[first:].tolist(), start=first):
            samples[i] = _sample(function, t)
        _check_finite(samples, time)
        self._carried = (k0 + len(time) - 1, float(samples[-1]))
        return samples


def _check_finite(samples: np.ndarray, time: np.ndarray) -> None:
    if not np.isfinite(samples).all():
        bad = np.flatnonzero(~np.isfinite(samples))[0]
        raise InvalidInput(f"the torque is {samples[bad]} at t = {time[bad]}; it must be finite")
