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

import contextlib
import numbers
from collections.abc import Callable
from fractions import Fraction
from pathlib import Path

import numpy as np

from .._errors import InvalidInput, WrongType
from ..fmu._parameters import Fmu
from ..signals._time_grid import WINDOW_STEPS
from ..signals._torque_schedule import TorqueSchedule
from ._exact_signal import Holding, Pieces, SignalWindows, event_tolerance, seconds, time_doubles
from ._integration import COMPUTED, Model, Runs, equation_of_motion, integrate_window, model_constants
from ._work import Work, check_steps, progress

# model_constants and equation_of_motion are _integration's, imported from here by the judge and
# the closed loop.
__all__ = [
    "COMPUTED",
    "ReferenceWindows",
    "equation_of_motion",
    "model_constants",
    "reference",
    "reference_schedule",
    "reference_windows",
]


class ReferenceWindows:
    """A run integrated a window of grid steps at a time, the state carried from each window's
    end to the next: what reference_windows() returns (see there).

    Attributes
    ----------
    windows : int
        The number of windows; next() integrates the next one.
    steps : float
        The work estimate of the whole run, in Taylor steps.
    """

    def __init__(
        self,
        window: Callable[[int, int], Pieces],
        grid_steps: int,
        step: Fraction,
        model: Model,
        window_steps: int,
        *,
        first: Pieces | None = None,
        show_progress: bool = True,
        max_steps: int | None = None,
    ):
        self._window, self._grid_steps, self._step, self._model = window, grid_steps, step, model
        self._window_steps, self._show_progress = window_steps, show_progress
        self.windows = -(-grid_steps // window_steps)
        self._done, self._state = 0, (float(model.theta0), float(model.omega0))
        self._stack: contextlib.ExitStack | None = None
        self._on_step: Callable[[float], None] | None = None
        # The whole run's work, before anything is integrated: each window's pieces made and let
        # go, but the first's, which next() integrates first.
        last = first_runs = Runs(first if first is not None else window(*self._bounds(0)))
        self._first: Runs | None = first_runs
        work = Work(model.constants, model.theta0, model.omega0, model.tolerance)
        work.add(first_runs.spans())
        for j in range(1, self.windows):
            last = Runs(window(*self._bounds(j)))
            work.add(last.spans())
        self.start, self.stop = float(first_runs.starts[0]), float(last.ends[-1])
        self.steps = work.steps
        check_steps(self.steps, self.start, self.stop, model.rtol, max_steps)

    def _bounds(self, j: int) -> tuple[int, int]:
        k0 = j * self._window_steps
        return k0, min(k0 + self._window_steps, self._grid_steps)

    def __enter__(self) -> ReferenceWindows:
        self._stack = contextlib.ExitStack()
        if self._show_progress:
            self._on_step = self._stack.enter_context(progress(self.steps, self.start, self.stop))
        return self

    def __exit__(self, *raised) -> bool | None:
        stack, self._stack, self._on_step = self._stack, None, None
        return stack.__exit__(*raised) if stack is not None else None

    def next(self, at: np.ndarray) -> np.ndarray:
        """Integrate the next window, from the state the one before it ended with.

        Parameters
        ----------
        at : numpy.ndarray
            The times to report, in s, increasing (may be empty): each within the window's first
            and last grid points, widened by the event tolerance.

        Returns
        -------
        numpy.ndarray
            Same result format as reference(), at the times `at`.

        Raises
        ------
        InvalidInput
            A time of `at` outside the window, every window integrated already, or values with
            which the series does not converge.
        """
        return self._next(at, check=True)

    def _next(self, at, *, check: bool) -> np.ndarray:
        j = self._done
        if j >= self.windows:
            raise InvalidInput(f"the run's {self.windows} windows are integrated: next() has no window left")
        # Only the first window's pieces are kept from the estimate; the others are made again.
        runs = self._first if self._first is not None else Runs(self._window(*self._bounds(j)))
        self._first = None
        times = np.asarray(at, dtype=float)
        if check:
            what = "the run" if self.windows == 1 else f"window {j} of the run"
            times = _times(at, runs.pieces, self._step, what)
        final = j == self.windows - 1
        out, theta, omega = integrate_window(runs, times, self._model, self._state, self._on_step, final)
        self._state, self._done = (theta, omega), j + 1
        return out


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
        DEFAULT_MAX_STEPS); a run allowed more than MAX_STEPS may take up to
        STEPS_PER_ALLOWED_STEP Taylor steps per step allowed (a torque that changes every step).

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
    signal = _read_signal(torque, start_time, stop_time, step_size, ramp, max_steps, check_memory=True)
    # The whole run is one window: reference_windows' code, so that the two cannot part.
    pieces = signal.window(0, signal.steps)
    at = _times(time_doubles(pieces.points) if at is None else at, pieces, signal.step)
    model = Model(parameters, theta0, omega0, rtol, atol, fmu_path)
    windows = ReferenceWindows(
        signal.window, signal.steps, signal.step, model, signal.steps, first=pieces, max_steps=max_steps
    )
    with windows as oracle:
        return oracle._next(at, check=False)


def _read_signal(torque, start_time, stop_time, step_size, ramp, max_steps, check_memory: bool) -> SignalWindows:
    """The signal, checked and read by the oracle's own reader; InvalidInput in reference()'s words."""
    if not (isinstance(torque, (str, Path, list, tuple, np.ndarray, int, float)) or callable(torque)):
        raise InvalidInput(
            f"the reference takes a constant, a callable, a per-step array or a CSV path, "
            f"not a {type(torque).__name__}: it reads the signal itself"
        )
    if isinstance(torque, (list, tuple, np.ndarray)) and ramp:
        raise InvalidInput("a per-step torque array is held over each step; ramp needs a CSV or a callable")
    step, start = seconds("step size", step_size), seconds("start time", start_time)
    stop = None if stop_time is None else seconds("stop time", stop_time)
    return SignalWindows(torque, start, stop, step, ramp, max_steps, check_memory=check_memory)


def _times(at, pieces: Pieces, step: Fraction, what: str = "the run") -> np.ndarray:
    """The times to report: within the run (or the window), or a rounding past its ends."""
    try:
        times = np.asarray(at, dtype=float)
    except (TypeError, ValueError):
        raise InvalidInput(f"at is the times to report, numbers in s; got {at!r}") from None
    start, stop = pieces.starts[0], pieces.stop
    earliest, latest = float(start - event_tolerance(start, step)), float(stop + event_tolerance(stop, step))
    outside = times.ravel()[~((times.ravel() >= earliest) & (times.ravel() <= latest))]
    if times.ndim != 1 or len(outside):
        shown = float(outside[0]) if len(outside) else at
        raise InvalidInput(f"at: {shown!r} is no time of {what}, {float(start):g} to {float(stop):g} s")
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
    show_progress: bool = True,
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
    show_progress : bool, optional
        Show the progress bar of a long run (False: a caller showing its own, the judge's a
        window of the run at a time); the run is refused past MAX_STEPS either way.

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
    model = Model(parameters, theta0, omega0, rtol, atol, fmu_path)
    oracle = ReferenceWindows(
        lambda k0, k1: pieces, 1, Fraction(0), model, 1, first=pieces, show_progress=show_progress
    )
    with oracle:
        return oracle._next(plan.time if at is None else at, check=False)


def reference_windows(
    torque=20.0,
    *,
    start_time: float = 0.0,
    stop_time: float | None = None,
    step_size: float = 1e-3,
    ramp: bool = False,
    parameters: dict | None = None,
    theta0: float = 0.0,
    omega0: float = 0.0,
    rtol: float = 1e-14,
    atol: float = 1e-14,
    fmu_path: Fmu = None,
    max_steps: int | None = None,
    window_steps: int = WINDOW_STEPS,
) -> ReferenceWindows:
    """reference()'s run integrated a window of grid steps at a time, for a run too long to hold.

    Window j is the grid steps j * window_steps to min((j + 1) * window_steps, N) of the oracle's
    own grid, as schedule_windows() splits the schedule's. Each check reference() makes is made
    here, at the call, in its words: the signal is checked, and the whole run's work estimated,
    window by window, and refused past MAX_STEPS before anything is integrated (a callable is
    sampled for the estimate, then again as each window is integrated; a CSV is read by the
    oracle's own reader for the estimate, then again as the windows are integrated). Memory: a
    window's pieces and reports at a time, and a CSV's rows near the window.

    Parameters
    ----------
    torque, start_time, stop_time, step_size, ramp, parameters, theta0, omega0, rtol, atol, fmu_path, max_steps
        As reference() takes them; the machine's free memory is not checked against the run,
        whose arrays are never held whole.
    window_steps : int, optional
        Grid steps per window (default WINDOW_STEPS).

    Returns
    -------
    ReferenceWindows
        A context manager: within ``with``, a progress bar of the whole run from BAR_FROM
        estimated steps. windows is their number; next(at) integrates the next window from the
        state the one before ended with (at its last grid point, whatever the times reported)
        and returns the result at the times `at`, increasing, each within the window's first and
        last grid points widened by the event tolerance.

    Raises
    ------
    InvalidInput
        As reference() raises it, at the call; from next(), a time outside its window, or a
        call past the last window.

    Examples
    --------
    >>> import numpy as np
    >>> from pendulum_fmu.oracle._reference import reference, reference_windows
    >>> with reference_windows(20.0, stop_time=1.0, window_steps=300) as oracle:
    ...     runs = [oracle.next(np.linspace(0.3 * j, min(0.3 * (j + 1), 1.0), 4)) for j in range(oracle.windows)]
    >>> oracle.windows, round(float(runs[-1]["theta"][-1]), 6)
    (4, 0.187205)
    """
    if not (isinstance(window_steps, numbers.Integral) and window_steps >= 1):
        raise InvalidInput(f"window steps {window_steps!r} must be a whole number of steps, at least 1")
    signal = _read_signal(torque, start_time, stop_time, step_size, ramp, max_steps, check_memory=False)
    model = Model(parameters, theta0, omega0, rtol, atol, fmu_path)
    return ReferenceWindows(signal.window, signal.steps, signal.step, model, int(window_steps), max_steps=max_steps)
