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
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Union

import numpy as np

from .._errors import InvalidInput
from ._time_grid import communication_points, event_tolerance, nearest
from ._torque_csv import TorqueTable, read_torque_csv

TorqueSignal = Union[float, int, Callable[[float], float], str, Path, Sequence[float], np.ndarray, "TorqueTable"]

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


def write_torque_csv(path: str | Path, plan: TorqueSchedule) -> Path:
    """Write a schedule as a torque CSV in fmpy's convention, which schedule() reads back.

    A row where each run of equal steps starts and ends, so a held torque reads as steps and a
    ramp as a line. Times are written with 17 significant digits, so they read back as the same
    doubles. The file is written whole or not at all.

    Parameters
    ----------
    path : str or Path
        The CSV to write (replaced if it is there).
    plan : TorqueSchedule
        The schedule, from schedule().

    Returns
    -------
    Path
        path.

    Raises
    ------
    CannotWrite
        path cannot be written.

    Examples
    --------
    5 N.m for 1 s, then 7 N.m:

    >>> import tempfile
    >>> from pathlib import Path
    >>> from pendulum_fmu import schedule, write_torque_csv
    >>> plan = schedule([5.0, 5.0, 7.0], step_size=0.5)
    >>> csv = write_torque_csv(Path(tempfile.mkdtemp(), "torque.csv"), plan)
    >>> print(csv.read_text(), end="")
    time,torque
    0.0,5.0
    1.0,5.0
    1.0,7.0
    1.5,7.0
    >>> schedule(csv, step_size=0.5).torque.tolist()
    [5.0, 5.0, 7.0]
    """
    from .._atomic_files import replacing

    end = plan.torque + plan.torque_rate * plan.step_size
    points: list[tuple[float, float]] = []
    for t0, t1, u0, u1 in zip(
        plan.time[:-1].tolist(), plan.time[1:].tolist(), plan.torque.tolist(), end.tolist(), strict=False
    ):
        if not points or points[-1] != (t0, u0):
            points.append((t0, u0))
        points.append((t1, u1))
    # A point inside a run of constant torque adds nothing.
    rows = [
        p for i, p in enumerate(points) if i in (0, len(points) - 1) or not points[i - 1][1] == p[1] == points[i + 1][1]
    ]
    with replacing(path, newline="") as file:
        file.write("time,torque\n")
        file.writelines(f"{t!r},{u!r}\n" for t, u in rows)
    return Path(path)


def _with_events(grid: np.ndarray, events: np.ndarray | None, step_size: float) -> np.ndarray:
    """The grid plus the events inside it that are not within event_tolerance of a grid point."""
    if events is None or not len(events):
        return grid
    events = np.unique(events[(events > grid[0]) & (events < grid[-1])])
    if len(events):
        distance = np.abs(nearest(grid, events) - events)
        events = events[distance > event_tolerance(events, step_size)]
    return np.union1d(grid, events)


def _array_schedule(
    values, start_time: float, stop_time: float | None, step_size: float, ramp: bool, max_steps: int | None
) -> TorqueSchedule:
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
    if stop_time is None:
        stop_time = start_time + len(torque) * step_size
    time = communication_points(start_time, stop_time, step_size, max_steps=max_steps)
    steps = len(time) - 1
    if steps != len(torque):
        raise InvalidInput(
            f"the torque array has {len(torque)} values but {start_time:g} to {stop_time:g} s "
            f"in steps of {step_size:g} s is {steps} steps; give one value per step or "
            "leave out the stop time"
        )
    bad = np.flatnonzero(~np.isfinite(torque))
    if len(bad):
        raise InvalidInput(f"the torque array's value {bad[0]} is {torque[bad[0]]}; values must be finite")
    return TorqueSchedule(time=time, torque=torque, torque_rate=np.zeros(len(torque)))


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
    source = "the torque table"
    if isinstance(torque, (str, Path)):
        source, torque = str(torque), read_torque_csv(torque)
    if isinstance(torque, (list, tuple, np.ndarray)):
        return _array_schedule(torque, start_time, stop_time, step_size, ramp, max_steps)
    if isinstance(torque, TorqueTable):
        stop = float(torque.time[-1]) if stop_time is None else stop_time
        if stop <= start_time and stop_time is None:
            raise InvalidInput(
                f"{source} ends at {stop:g} s, not after the start time {start_time:g} s; give a stop time"
            )
        grid = communication_points(start_time, stop, step_size, max_steps=max_steps)
        table = torque.snapped(grid, step_size)
        time = _with_events(grid, table.time if ramp else table.jumps(), step_size)
        start_values = table.value_after(time[:-1])
        end_values = table.value_before(time[1:])
    else:
        time = communication_points(
            start_time, DEFAULT_STOP_TIME if stop_time is None else stop_time, step_size, max_steps=max_steps
        )
        if callable(torque):
            samples = np.array([_sample(torque, t) for t in _takes_time(torque, time.tolist())])
        else:
            try:
                # Whatever else it is is tried as a number: float() refuses what is none.
                samples = np.full(len(time), float(torque))  # type: ignore[arg-type]
            except (TypeError, ValueError):
                raise InvalidInput(
                    f"a torque is a number, a callable of time, a per-step array or a CSV "
                    f"path; got {type(torque).__name__}"
                ) from None
        if not np.isfinite(samples).all():
            bad = np.flatnonzero(~np.isfinite(samples))[0]
            raise InvalidInput(f"the torque is {samples[bad]} at t = {time[bad]}; it must be finite")
        start_values, end_values = samples[:-1], samples[1:]
    if not ramp:
        return TorqueSchedule(time=time, torque=start_values, torque_rate=np.zeros(len(time) - 1))
    with np.errstate(over="ignore", invalid="ignore"):
        rate = (end_values - start_values) / np.diff(time)
    steep = np.flatnonzero(~np.isfinite(rate))
    if len(steep):
        k = steep[0]
        raise InvalidInput(
            f"{source if isinstance(torque, TorqueTable) else 'the torque'} ramps from "
            f"{start_values[k]:g} to {end_values[k]:g} N.m between t = {time[k]:g} and "
            f"{time[k + 1]:g} s, a rate past the largest double: hold the torque "
            "(no ramp) or give values that change less steeply"
        )
    return TorqueSchedule(time=time, torque=start_values, torque_rate=rate)
