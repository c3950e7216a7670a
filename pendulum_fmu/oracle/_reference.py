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

from collections.abc import Callable
from fractions import Fraction
from pathlib import Path

import numpy as np

from .._errors import InvalidInput, WrongType
from ..fmu import _results as results
from ..fmu._parameters import Fmu, start_value, total_inertia
from ..fmu._simulate import resolve_parameters
from ..signals._torque_schedule import TorqueSchedule
from ._exact_signal import Holding, Pieces, event_tolerance, seconds, signal_pieces, time_doubles
from ._taylor import Diverged, check_tolerances, integrate_piece
from ._work import Spans, check_steps, progress, taylor_steps

# What the reference computes, whatever an FMU records.
COMPUTED = ("torque", "theta", "omega", "alpha")


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
    pieces: Pieces,
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
    starts = time_doubles(pieces.starts)
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


def _failed(why: str, t: float, parameters: dict, theta0: float, omega0: float, pieces: Pieces) -> InvalidInput:
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
    step, start = seconds("step size", step_size), seconds("start time", start_time)
    stop = None if stop_time is None else seconds("stop time", stop_time)
    pieces = signal_pieces(torque, start, stop, step, ramp, max_steps)
    if at is None:
        at = time_doubles(pieces.points)
    return _integrate(pieces, _times(at, pieces, step), parameters, theta0, omega0, rtol, atol, fmu_path)


def _times(at, pieces: Pieces, step: Fraction) -> np.ndarray:
    """The times to report: within the run, or a rounding past its ends."""
    try:
        times = np.asarray(at, dtype=float)
    except (TypeError, ValueError):
        raise InvalidInput(f"at is the times to report, numbers in s; got {at!r}") from None
    start, stop = pieces.starts[0], pieces.stop
    earliest, latest = float(start - event_tolerance(start, step)), float(stop + event_tolerance(stop, step))
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
    pieces = Pieces(points[:-1], points[-1], u0, rate, points, Holding(points, u0, Fraction(0)).values_after)
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
