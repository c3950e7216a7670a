"""The independent oracle: a torque signal as docs/signals.md defines it, integrated on its own.

`reference()` shares no code with the path that feeds the tools (`torque_schedule.schedule`)
beyond its checks of what it is given (a file that is no signal, a run length, refused in the
same words), never how it reads or samples a signal. It reads a CSV with its own small reader,
keeps the times as exact fractions of the decimals written in the file, and finds the
communication points and the torque of each step from the written definition. A schedule that
does not carry the user's signal to the tools then shows as a difference between them and this
oracle. `reference_schedule()` integrates a given schedule, to
judge a tool on exactly the torques it was fed.

Both integrate the equation of motion by its Taylor series (_taylor.py, rtol = atol = 1e-14 a
step) over pieces on which the torque is linear (held or ramped), restarting at every piece
boundary.
"""

from __future__ import annotations

import bisect
import csv
import heapq
import itertools
import math
import numbers
from collections.abc import Callable, Sequence
from fractions import Fraction
from pathlib import Path

import numpy as np

from .._errors import InvalidInput, WrongType
from ..fmu import _results as results
from ..fmu._parameters import Fmu, start_value, total_inertia
from ..fmu._simulate import resolve_parameters
from ..signals._time_grid import step_count
from ..signals._torque_csv import read_torque_csv
from ..signals._torque_schedule import TorqueSchedule
from ._taylor import Diverged, check_tolerances, integrate_piece
from ._work import Spans, check_steps, progress, taylor_steps

# docs/signals.md: an event within max(1e-9 step, 64 ulp of its time) of a communication point
# is that point. Written again here on purpose: the oracle must not borrow the schedule's code.
_TOLERANCE_STEPS, _TOLERANCE_ULPS = Fraction(1, 10**9), 64
# Times whose torque _Holding looks up at once.
_BLOCK = 1 << 16
_DEFAULT_STOP_TIME = Fraction(3)
# Times: a _Grid, a list of exact or double times, or an array of doubles; torques likewise.
_Times = Sequence[Fraction | float] | np.ndarray
_Values = Sequence[float] | np.ndarray
# What the reference computes, whatever an FMU records.
COMPUTED = ("torque", "theta", "omega", "alpha")


def _exact(value) -> Fraction:
    """A number as the decimal a person wrote: 0.009 is 9/1000, not the double nearest it."""
    return Fraction(repr(float(value))) if not isinstance(value, (str, Fraction)) else Fraction(value)


def _seconds(name: str, value) -> Fraction:
    """A time argument as the decimal a person wrote; InvalidInput unless a finite number."""
    if not (isinstance(value, numbers.Real) and math.isfinite(value)):
        raise InvalidInput(f"{name} {value!r} must be a finite number of seconds")
    return _exact(value)


def _torque(value, where: str) -> float:
    """A torque value of the signal; InvalidInput unless a finite number."""
    # A signal written with numpy may return a 0-d array (np.where, np.interp of a scalar).
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf":
        value = value.item()
    if not (isinstance(value, numbers.Real) and math.isfinite(value)):
        raise InvalidInput(f"the torque is {value!r} {where}; it must be a finite number of N.m")
    return float(value)


def _tolerance(time: Fraction | float, step: Fraction) -> Fraction:
    return max(_TOLERANCE_STEPS * step, Fraction(_TOLERANCE_ULPS * math.ulp(float(time))))


class _TorqueFile:
    """A time,torque CSV as exact times and float torques: linear between rows, a jump where a
    time repeats, held outside.
    """

    def __init__(self, path: Path):
        with open(path, newline="", encoding="utf-8-sig") as file:
            rows = [row for row in csv.reader(file) if any(cell.strip() for cell in row)]
        header = [cell.strip() for cell in rows[0]]
        time_column, torque_column = header.index("time"), header.index("torque")
        self.times = [Fraction(row[time_column].strip()) for row in rows[1:]]
        self.torques = [float(row[torque_column]) for row in rows[1:]]

    def after(self, t: Fraction) -> float:
        times, torques = self.times, self.torques
        if t >= times[-1]:
            return torques[-1]
        if t < times[0]:
            return torques[0]
        j = bisect.bisect_right(times, t)  # times[j-1] <= t < times[j]
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
        share = float((t - t0) / (t1 - t0))
        value = u0 + (u1 - u0) * share
        # docs/signals.md's form, unless rows near the largest double differ by inf.
        return value if math.isfinite(value) else u0 * (1 - share) + u1 * share

    def jumps(self) -> list[Fraction]:
        return sorted({a for a, b in zip(self.times, self.times[1:], strict=False) if a == b})

    def latest_event_near(self, t: Fraction, step: Fraction) -> Fraction:
        """t, or the latest row time within the tolerance of t: that event is at t."""
        tolerance = _tolerance(t, step)
        j = bisect.bisect_right(self.times, t + tolerance)
        return max(t, self.times[j - 1]) if j and self.times[j - 1] >= t - tolerance else t

    def held_after(self, points: Sequence[Fraction], step: Fraction) -> np.ndarray:
        """after(latest_event_near(p, step)) of each point, the same values: the row times as
        doubles decide each point with no row near it on a flat stretch (its value is the row's);
        the exact methods decide the others.
        """
        times, torques = self.times, self.torques
        row_doubles, doubles = np.array([float(t) for t in times]), _doubles(points)
        reach = np.maximum(float(_TOLERANCE_STEPS * step), _TOLERANCE_ULPS * np.spacing(np.abs(doubles)))
        # Widened by what the doubles may be off by (each time's rounding, the tolerance's):
        # a few ulp, bounded here by 16.
        reach += 16 * np.spacing(np.maximum(np.abs(doubles), reach))
        near = np.searchsorted(row_doubles, doubles + reach, "right") > np.searchsorted(
            row_doubles, doubles - reach, "left"
        )
        after = np.searchsorted(row_doubles, doubles, "right")  # times[j-1] <= p < times[j]
        before = np.clip(after - 1, 0, len(times) - 1)
        torque_doubles = np.array(torques)
        sloped = torque_doubles[before] != torque_doubles[np.minimum(after, len(times) - 1)]
        values = torque_doubles[before]
        for k in np.flatnonzero(near | sloped).tolist():
            values[k] = self.after(self.latest_event_near(points[k], step))
        return values


class _Grid(Sequence[Fraction]):
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
                return _Grid(self.start, self.step, self.regular - (self.stop is None), None)
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


def _doubles(points: _Times) -> np.ndarray:
    """A sequence of times (a _Grid, fractions or doubles) as an array of doubles."""
    if isinstance(points, _Grid):
        return points.doubles()
    if isinstance(points, np.ndarray):
        return points.astype(float)
    return np.array([float(p) for p in points])


def _grid(start: Fraction, stop: Fraction, step: Fraction, max_steps: int | None = None) -> _Grid:
    """Start + k*step up to stop; stop itself ends a shorter last step unless it is on the grid."""
    # Only checked by the schedule's code, in simulate()'s words (a step that is not positive, a
    # stop not after the start, a run too long to hold): the grid below is the oracle's own.
    step_count(float(start), float(stop), float(step), max_steps)
    # The points start + k*step before stop less its tolerance: k < (last - start) / step.
    last = stop - _tolerance(stop, step)
    return _Grid(start, step, max(math.ceil((last - start) / step), 0), stop)


def _with_events(grid: _Grid, events: list[Fraction], step: Fraction) -> Sequence[Fraction]:
    """The grid plus every event inside it that is not within the tolerance of a grid point."""
    extra = []
    for event in events:
        if not grid[0] < event < grid[-1]:
            continue
        j = bisect.bisect_left(grid, event)
        if min(grid[j] - event, event - grid[j - 1]) > _tolerance(event, step):
            extra.append(event)
    if not extra:  # the grid as it is, its points made only when asked for
        return grid
    # The grid is sorted and no extra event is on it: merged, not sorted anew.
    return list(heapq.merge(grid, sorted(set(extra))))


class _Pieces:
    """The torque as pieces [start, end) on which it is u0 + rate * (t - start), the
    communication points the signal defines, and the torque just after each of an array of times.
    """

    def __init__(
        self,
        starts: _Times,
        stop: Fraction | float,
        u0: _Values,
        rate: _Values,
        points: _Times,
        values_after: Callable[[np.ndarray], np.ndarray],
    ):
        self.starts, self.stop, self.u0, self.rate = starts, stop, u0, rate
        self.points, self.values_after = points, values_after


def _signal_pieces(
    torque, start: Fraction, stop: Fraction | None, step: Fraction, ramp: bool, max_steps: int | None
) -> _Pieces:
    if isinstance(torque, (str, Path)):
        read_torque_csv(torque)  # a file that is no signal refused where it is wrong; read below anew
        signal = _TorqueFile(Path(torque))
        stop = signal.times[-1] if stop is None else stop
        grid = _grid(start, stop, step, max_steps)
        if ramp:
            # The file's own piecewise-linear signal: a piece between consecutive row times.
            rows = sorted({start, stop} | {t for t in signal.times if start < t < stop})
            u0 = [signal.after(a) for a in rows[:-1]]
            rate = [(signal.before(b) - signal.after(a)) / float(b - a) for a, b in itertools.pairwise(rows)]
            return _Pieces(
                rows[:-1],
                stop,
                u0,
                rate,
                _with_events(grid, signal.times, step),
                lambda times: np.array(
                    [signal.after(signal.latest_event_near(_exact(t), step)) for t in times.tolist()]
                ),
            )
        events = _with_events(grid, signal.jumps(), step)
        held = signal.held_after(events[:-1], step)
        return _Pieces(events[:-1], stop, held, np.zeros(len(held)), events, _Holding(events, held, step).values_after)

    if isinstance(torque, (list, tuple, np.ndarray)):
        values = [_torque(u, f"at step {k} of the array") for k, u in enumerate(torque)]
        points = _grid(start, start + len(values) * step if stop is None else stop, step, max_steps)
        if len(points) - 1 != len(values):
            raise InvalidInput(f"the torque array has {len(values)} values for {len(points) - 1} steps")
    else:
        points = _grid(start, _DEFAULT_STOP_TIME if stop is None else stop, step, max_steps)
        sample = torque if callable(torque) else (lambda t, u=torque: u)
        values = [_torque(sample(p), f"at t = {p}") for p in _doubles(points).tolist()]
    if ramp:
        rate = [(b - a) / float(t1 - t0) for a, b, t0, t1 in zip(values, values[1:], points, points[1:], strict=False)]
    else:
        rate = [0.0] * (len(points) - 1)
    u0 = values[: len(points) - 1]
    return _Pieces(points[:-1], points[-1], u0, rate, points, _Holding(points, u0, step).values_after)


class _Holding:
    """The torque just after t of a signal holding values[k] from points[k]: the step holding t
    is the one starting at the latest point at or (within the tolerance) just after t.

    value_after(t) decides it in exact fractions. values_after(times) decides a whole array with
    the points as doubles, looked up once; a time whose reach (t plus its tolerance) lies within
    rounding of a point, where doubles cannot tell the side, is decided by value_after.
    """

    def __init__(self, points: _Times, values: _Values, step: Fraction):
        self.points, self.values, self.step = points, values, step
        self._point_doubles = _doubles(points)
        self._value_doubles = np.array(values, dtype=float)
        self._step_tolerance = float(_TOLERANCE_STEPS * step)

    def value_after(self, t: Fraction) -> float:
        """The value held just after the exact time t."""
        j = max(bisect.bisect_right(self.points, t + _tolerance(t, self.step)) - 1, 0)
        return self.values[min(j, len(self.values) - 1)]

    def values_after(self, times: np.ndarray) -> np.ndarray:
        """value_after of each time, read as the decimal a person wrote (_exact)."""
        times = np.asarray(times, dtype=float)
        out = np.empty(len(times))
        # A block at a time: a dozen arrays of a block's times, not of millions.
        for begin in range(0, len(times), _BLOCK):
            out[begin : begin + _BLOCK] = self._values_after(times[begin : begin + _BLOCK])
        return out

    def _values_after(self, times: np.ndarray) -> np.ndarray:
        tolerance = np.maximum(self._step_tolerance, _TOLERANCE_ULPS * np.spacing(np.abs(times)))
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
            out[i] = self.value_after(_exact(times[i]))
        return out


def equation_of_motion(parameters: dict[str, float]) -> Callable:
    """alpha(theta, omega, torque) of the pendulum with these (resolved) parameters, in rad/s2;
    works on scalars and numpy arrays alike.

    Parameters
    ----------
    parameters : dict
        mass, length, inertia, gravity and damping, as resolve_parameters gives them.

    Returns
    -------
    callable
        acceleration(theta, omega, torque).
    """
    gravity_moment, damping, inverse_inertia = model_constants(parameters)

    def acceleration(theta, omega, u):
        return (u - gravity_moment * np.sin(theta) - damping * omega) * inverse_inertia

    return acceleration


def model_constants(parameters: dict[str, float]) -> tuple[float, float, float]:
    """mass*gravity*length, damping and 1/total inertia: the equation's three constants, as
    _taylor.integrate_piece takes them.

    Parameters
    ----------
    parameters : dict
        mass, length, inertia, gravity and damping, as resolve_parameters gives them.

    Returns
    -------
    (float, float, float)
    """
    with np.errstate(over="ignore"):  # values past the largest double fail where they are used
        return (
            parameters["mass"] * parameters["gravity"] * parameters["length"],
            parameters["damping"],
            1.0 / total_inertia(parameters),
        )


def _integrate(
    pieces: _Pieces,
    at: np.ndarray,
    parameters: dict | None,
    theta0: float,
    omega0: float,
    rtol: float,
    atol: float,
    fmu_path: Fmu,
) -> np.ndarray:
    theta0, omega0 = start_value("theta0", theta0, "rad"), start_value("omega0", omega0, "rad/s")
    check_tolerances(rtol, atol)
    parameters = resolve_parameters(parameters, fmu_path)
    acceleration, model = equation_of_motion(parameters), model_constants(parameters)
    starts = _doubles(pieces.starts)
    ends = np.append(starts[1:], float(pieces.stop))
    u0s, rates = np.asarray(pieces.u0, dtype=float), np.asarray(pieces.rate, dtype=float)
    # Pieces that continue one another (the same held torque) are one run, so that the series
    # restarts only where the torque changes.
    continues = (rates[1:] == 0) & (rates[:-1] == 0) & (u0s[1:] == u0s[:-1])
    firsts = np.flatnonzero(np.r_[True, ~continues])
    lasts = np.r_[firsts[1:] - 1, len(starts) - 1]
    # The reports in time order (a result's are: no copy is made). Each belongs to the first piece
    # that reaches it, so a run's are a slice: those after the run before's end, up to its own (a
    # time a rounding past the end of the run belongs to the last).
    order = None if np.all(at[1:] >= at[:-1]) else np.argsort(at, kind="stable")
    ordered = at if order is None else at[order]
    bounds = np.searchsorted(ordered, ends[lasts], side="right")
    bounds[-1] = len(at)
    runs = np.stack([firsts, lasts, np.r_[0, bounds[:-1]], bounds])
    out = results.empty(len(at), COMPUTED)
    out["time"] = at
    spans = Spans(starts[firsts], ends[lasts], u0s[firsts], rates[firsts])
    steps = taylor_steps(spans, model, theta0, omega0, (rtol, atol))
    check_steps(steps, starts[0], ends[-1], rtol)
    theta, omega = float(theta0), float(omega0)
    with progress(steps, float(starts[0]), float(ends[-1])) as on_step:
        for first, last, lo, hi in runs.T.tolist():
            t0, t1, u0, rate = float(starts[first]), float(ends[last]), float(u0s[first]), float(rates[first])
            try:
                thetas, omegas, theta, omega = integrate_piece(
                    theta, omega, (t0, t1), (u0, rate), model, (rtol, atol), np.clip(ordered[lo:hi], t0, t1), on_step
                )
            except Diverged as error:
                raise _failed(str(error), t0, parameters, theta0, omega0, pieces) from None
            mine = slice(lo, hi) if order is None else order[lo:hi]
            out["theta"][mine], out["omega"][mine] = thetas, omegas
    out["torque"] = pieces.values_after(at)
    # The end of the run reports the torque the last piece reached, as a master reads it back.
    at_end = at >= ends[-1]
    out["torque"][at_end] = u0s[-1] + rates[-1] * (ends[-1] - starts[-1])
    with np.errstate(over="ignore", invalid="ignore"):
        out["alpha"] = acceleration(out["theta"], out["omega"], out["torque"])
    if not np.isfinite(out["alpha"]).all():  # the states stayed finite, the acceleration did not
        at_time = float(out["time"][np.flatnonzero(~np.isfinite(out["alpha"]))[0]])
        raise _failed("the acceleration is not finite", at_time, parameters, theta0, omega0, pieces)
    return out


def _failed(why: str, t: float, parameters: dict, theta0: float, omega0: float, pieces: _Pieces) -> InvalidInput:
    """The one-line error for an integration these values break, naming every value."""
    values = ", ".join(
        f"{name} = {value:g}" for name, value in {**parameters, "theta0": theta0, "omega0": omega0}.items()
    )
    torque = max(abs(u) for u in pieces.u0)
    return InvalidInput(
        f"the reference cannot integrate the pendulum from t = {t:g} s with {values} "
        f"and torques up to {torque:g}: {why.rstrip('.')}; values near the largest "
        "double (mass*gravity*length, mass*length^2, the torque over the inertia) "
        "break it: give physically meaningful values"
    )


def reference(
    torque=20.0,
    *,
    start_time: float = 0.0,
    stop_time: float | None = None,
    step_size: float = 1e-3,
    ramp: bool = False,
    parameters: dict | None = None,
    theta0: float = 0.0,
    omega0: float = 0.0,
    at: np.ndarray | None = None,
    rtol: float = 1e-14,
    atol: float = 1e-14,
    fmu_path: Fmu = None,
    max_steps: int | None = None,
) -> np.ndarray:
    """The trajectory under a signal as docs/signals.md defines it, integrated by the pendulum's
    Taylor series: the independent oracle, which reads the signal itself.

    Parameters
    ----------
    torque : float, callable, sequence of float, str or Path
        As simulate() takes it: a constant (N.m), a callable of time, a per-step array or a CSV
        path.
    start_time, stop_time, step_size, ramp, theta0, omega0
        As simulate() takes them.
    parameters : dict, optional
        Overrides of the defaults of the FMU at fmu_path.
    at : numpy.ndarray, optional
        The times to report, in s (default: the signal's communication points).
    rtol, atol : float, optional
        The integrator's tolerances: the terms each step leaves out of the series stay below
        atol + rtol * max(abs(theta), abs(omega)).
    fmu_path : str or Path, optional
        The FMU whose parameters and defaults apply (default: pendulum_fmu.default_fmu()).
    max_steps : int, optional
        The most communication steps the run may have, as simulate() takes it (default:
        DEFAULT_MAX_STEPS).

    Returns
    -------
    numpy.ndarray
        Same result format as simulate(); torque is the signal's value just after each time.

    Raises
    ------
    InvalidInput
        A signal the reference cannot read, parameters the FMU refuses, or values with which
        the series does not converge (mass*gravity*length past the largest double, say).

    Examples
    --------
    The FMU's run against the oracle, which shares no code with it:

    >>> from pendulum_fmu import reference, simulate
    >>> oracle = reference(20.0, stop_time=1.0)
    >>> round(float(oracle["theta"][-1]), 6)
    0.187205
    >>> bool(abs(simulate(20.0, stop_time=1.0)["theta"] - oracle["theta"]).max() < 1e-9)
    True
    """
    if not (isinstance(torque, (str, Path, list, tuple, np.ndarray, int, float)) or callable(torque)):
        raise InvalidInput(
            f"the reference takes a constant, a callable, a per-step array or a CSV path, "
            f"not a {type(torque).__name__}: it reads the signal itself"
        )
    if isinstance(torque, (list, tuple, np.ndarray)) and ramp:
        raise InvalidInput("a per-step torque array is held over each step; ramp needs a CSV or a callable")
    step, start = _seconds("step size", step_size), _seconds("start time", start_time)
    stop = None if stop_time is None else _seconds("stop time", stop_time)
    pieces = _signal_pieces(torque, start, stop, step, ramp, max_steps)
    if at is None:
        at = _doubles(pieces.points)
    return _integrate(pieces, _times(at, pieces, step), parameters, theta0, omega0, rtol, atol, fmu_path)


def _times(at, pieces: _Pieces, step: Fraction) -> np.ndarray:
    """The times to report: within the run, or a rounding past its ends."""
    try:
        times = np.asarray(at, dtype=float)
    except (TypeError, ValueError):
        raise InvalidInput(f"at is the times to report, numbers in s; got {at!r}") from None
    start, stop = pieces.starts[0], pieces.stop
    earliest, latest = float(start - _tolerance(start, step)), float(stop + _tolerance(stop, step))
    outside = times.ravel()[~((times.ravel() >= earliest) & (times.ravel() <= latest))]
    if times.ndim != 1 or len(outside):
        shown = float(outside[0]) if len(outside) else at
        raise InvalidInput(f"at: {shown!r} is no time of the run, {float(start):g} to {float(stop):g} s")
    return times


def reference_schedule(
    plan,
    *,
    parameters: dict | None = None,
    theta0: float = 0.0,
    omega0: float = 0.0,
    at: np.ndarray | None = None,
    rtol: float = 1e-14,
    atol: float = 1e-14,
    fmu_path: Fmu = None,
) -> np.ndarray:
    """Integrate exactly the torques of a schedule, reported at its communication points (or at
    the times `at`): the judge of a tool that was fed that schedule, and the judge's variants of
    a run with a mistake made (_judge.py).

    Parameters
    ----------
    plan : TorqueSchedule
        time (N + 1 points, s), torque (N start values, N.m) and torque_rate (N, N.m/s).
    parameters, theta0, omega0, rtol, atol, fmu_path
        As reference() takes them.
    at : numpy.ndarray, optional
        The times to report, in s (default: the schedule's communication points).

    Returns
    -------
    numpy.ndarray
        Same result format as simulate().

    Raises
    ------
    WrongType
        plan is no TorqueSchedule.
    InvalidInput
        Parameters the FMU refuses, times in `at` outside the run, or values with which
        the series does not converge.

    Examples
    --------
    20 N.m for 1 s with gravity off: theta(1 s) = 20 / (2 * 30 kg.m^2) = 1/3 rad.

    >>> from pendulum_fmu import reference_schedule, schedule
    >>> run = reference_schedule(schedule(20.0, stop_time=1.0), parameters={"gravity": 0.0})
    >>> run.dtype.names, len(run), round(float(run["theta"][-1]), 12)
    (('time', 'torque', 'theta', 'omega', 'alpha'), 1001, 0.333333333333)
    """
    if not isinstance(plan, TorqueSchedule):
        raise WrongType(f"plan is a TorqueSchedule (torque_schedule.schedule(...)), not a {type(plan).__name__}")
    # Doubles, compared with exact times exactly where it matters (a Fraction and a float compare
    # by value): converting 3000 points to fractions would cost more than the integration.
    points, u0, rate = plan.time, plan.torque, plan.torque_rate
    # The schedule's points are the tools' own: no tolerance beyond rounding.
    pieces = _Pieces(points[:-1], points[-1], u0, rate, points, _Holding(points, u0, Fraction(0)).values_after)
    return _integrate(
        pieces,
        np.asarray(plan.time if at is None else at, dtype=float),
        parameters,
        theta0,
        omega0,
        rtol,
        atol,
        fmu_path,
    )
