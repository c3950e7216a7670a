"""The work a run of the reference needs, known before it integrates: its Taylor steps.

_taylor.py steps until the last terms of the series, at the step, are below the tolerance. The
terms follow the rates at which the pendulum's state changes: sin(theta) turns at |omega|, the
gravity/inertia frequency w0 = sqrt(m g L / I) swings theta, the damping's c / I decays omega. A
series whose n-th term is (rate * h)**n / n! falls below tol at h = (tol * n!)**(1/n) / rate; where
|omega| is far above w0, sin(theta)'s terms enter theta'' times w0**2 / omega**2, which lengthens
the step by (omega / w0)**(2/n). So the step is about REACH(tol) / rate with

    rate = max(w0, |omega|**(1 - 2/n) * w0**(2/n), c / I)

and the steps of a span are its integral of rate / REACH, at least one a piece of the torque (the
series restarts where the torque changes).

|omega| is bounded before integrating, from the energy E = I omega**2 / 2 + the gravity's
potential (between 0 and 2 |m g L|) and the torque's work: dE/dt = u omega - c omega**2 <= U |omega|
(U the largest |torque|), so sqrt(E) grows at most by U t / sqrt(2 I), and |omega| by U t / I;
with damping, E stays below its start or 2 |m g L| + I (U / c)**2 / 2, where the damping takes all
the torque gives. Where the torque is held from the start, the energy with the torque's potential,
E - u theta, is conserved or lost; below both barriers of the well theta starts in, the pendulum
stays in that well, and |omega| below what the well's depth allows, however long the run.

This is what the reference refuses (MAX_STEPS) and where it shows a progress bar (BAR_FROM):
held to the steps _taylor.py actually takes by tests/test_work.py.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable, Iterator

import numpy as np

from .._errors import InvalidInput
from ._taylor import order_limit

# Above this many Taylor steps the reference refuses to start: about 100 to 200 us a step in
# Python (tests/test_work.py prints it), half an hour or more, and a run that long is likelier a
# stop time in the wrong unit than one meant.
MAX_STEPS = 10_000_000
# A run allowed more grid steps than MAX_STEPS (--max-steps) may take this many Taylor steps per
# grid step: a torque that changes at every step (a recorded one) restarts the series at each,
# one Taylor step or more apiece.
STEPS_PER_ALLOWED_STEP = 4
# From this many steps (a few seconds) the reference shows its progress on stderr.
BAR_FROM = 20_000
# A swing's series holds harmonics of w0 too (sin of a swinging theta): its terms grow about as
# those of exp(2 w0 t) (measured: tests/test_work.py).
_SWING = 2.0
# Points of the grid the rate is integrated on.
_GRID = 4097


def _reach(tolerance: float, n: int) -> float:
    """The product rate * h of a step: where the n-th term of exp(rate * h) is the tolerance."""
    return math.exp((math.log(tolerance) + math.lgamma(n + 1)) / n)


class Spans:
    """The pieces of a run the reference integrates one by one (the series restarts at each):
    their starts and ends (s), and the torque at each one's start (N.m) and its rate (N.m/s).
    """

    def __init__(self, starts: np.ndarray, ends: np.ndarray, u0: np.ndarray, rate: np.ndarray):
        self.starts, self.ends, self.u0, self.rate = starts, ends, u0, rate


def speed_bound(
    spans: Spans, model: tuple[float, float, float], theta0: float, omega0: float
) -> tuple[Callable, float]:
    """An upper bound on |omega| (rad/s) at any time of the run, from the energy and the torque's
    work.

    Parameters
    ----------
    spans : Spans
        The run's pieces.
    model : (float, float, float)
        mass*gravity*length (N.m), damping (N.m.s/rad) and 1/total inertia (1/(kg.m^2)).
    theta0, omega0 : float
        The state at the first span's start (rad, rad/s).

    Returns
    -------
    (callable, float)
        bound(times): at each time of an array, |omega| is not above it then; and the time the
        bound starts to grow.
    """
    return Work(model, theta0, omega0, (1.0, 1.0)).bound(spans)


class Work:
    """taylor_steps of a run whose spans come a window at a time, in time order (add()): what
    bounds the speed carried from each window to the next (the torque's impulse so far, whether
    the torque held from the start still holds, the largest torque so far), and each window's
    rate integrated on a grid of its own. A run given as one window is taylor_steps' run.

    Parameters
    ----------
    model, theta0, omega0, tolerance
        As taylor_steps takes them.
    """

    def __init__(self, model: tuple[float, float, float], theta0: float, omega0: float, tolerance: tuple[float, float]):
        self.model, self.theta0, self.omega0, self.tolerance = model, theta0, omega0, tolerance
        self.steps = 0.0
        gravity_moment, _, inverse_inertia = model
        # nan where a value is not finite: add() counts nan steps, and the integration refuses it.
        self.finite = all(math.isfinite(value) for value in (*model, theta0, omega0))
        self.energy = math.nan
        if self.finite:
            with np.errstate(over="ignore", invalid="ignore"):
                # The gravity's potential, between 0 and 2 g: g - mgL cos(theta).
                self.energy = (
                    0.5 * np.float64(omega0) ** 2 / inverse_inertia
                    + abs(gravity_moment)
                    - gravity_moment * math.cos(theta0)
                )
        self.start_speed = self.trapped = math.sqrt(2 * self.energy * inverse_inertia)
        self.since: float | None = None  # the end of the torque held from the start, as far as known
        self.holding = False  # whether the torque has held its first value, in its well, up to since
        self.first_u0 = 0.0
        self.impulse, self.pushed_before, self.most = 0.0, 0.0, 0.0

    def bound(self, spans: Spans) -> tuple[Callable, float]:
        """speed_bound over the next window's spans, from what the windows before it carry."""
        gravity_moment, damping, inverse_inertia = self.model
        g = abs(gravity_moment)
        torques = np.maximum(np.abs(spans.u0), np.abs(spans.u0 + spans.rate * (spans.ends - spans.starts)))
        # The torque's impulse from the start, at each span's edge: sqrt(E) grows by at most the
        # impulse over sqrt(2 I), |omega| by at most the impulse over I.
        edges = np.concatenate((spans.starts[:1], spans.ends))
        impulse = self.impulse + np.concatenate(([0.0], np.cumsum(torques * (spans.ends - spans.starts))))
        if self.since is None:  # the run's first window
            self.since, self.first_u0 = float(spans.starts[0]), float(spans.u0[0])
            speed = _well_speed(self.first_u0, self.model, self.theta0, self.omega0) if spans.rate[0] == 0 else None
            if speed is not None:
                # In the well until the held torque changes; then the energy grows as the torque may.
                self.holding, self.trapped = True, speed
                self.start_speed = math.sqrt(speed**2 + 4 * g * inverse_inertia)
        if self.holding:
            held = _held_from_start(spans, self.first_u0)
            self.since = float(spans.ends[held - 1]) if held else self.since
            self.holding = held == len(spans.starts)
            self.pushed_before = float(np.interp(self.since, edges, impulse))
        self.impulse, self.most = float(impulse[-1]), max(self.most, float(torques.max()))
        ceiling = math.inf
        if damping > 0:
            most = self.most
            ceiling = math.sqrt(
                2 * inverse_inertia * max(self.energy, 2 * g + 0.5 * (most / damping) ** 2 / inverse_inertia)
            )
        since, trapped, start_speed, pushed_before = self.since, self.trapped, self.start_speed, self.pushed_before

        def bound(times: np.ndarray) -> np.ndarray:
            pushed = np.maximum(np.interp(times, edges, impulse) - pushed_before, 0.0)
            return np.minimum(np.where(times <= since, trapped, start_speed + pushed * inverse_inertia), ceiling)

        return bound, since

    def add(self, spans: Spans) -> float:
        """Count the next window's steps; the run's steps so far (inf, nan: see taylor_steps)."""
        gravity_moment, damping, inverse_inertia = self.model
        if not self.finite:
            self.steps = math.nan
            return self.steps
        n = order_limit(min(self.tolerance)) - 1  # the power of the last term of omega's series
        w0 = math.sqrt(abs(gravity_moment) * inverse_inertia)
        with np.errstate(over="ignore", invalid="ignore"):
            bound, since = self.bound(spans)

        def rate(times: np.ndarray) -> np.ndarray:
            spin = bound(times) ** (1 - 1 / n) * w0 ** (2 / n)
            return np.maximum(np.maximum(_SWING * w0, spin), damping * inverse_inertia)

        with np.errstate(over="ignore", invalid="ignore"):
            # The rate's integral from the window's start, on a grid fine enough for its bends
            # (the speed's ceiling, the torque's changes); a span's is the difference at its ends.
            start, stop = float(spans.starts[0]), float(spans.ends[-1])
            grid = np.linspace(start, stop, _GRID)
            grid = np.union1d(grid, [since]) if start <= since <= stop else grid
            rates = rate(grid)
            turns = np.concatenate(([0.0], np.cumsum(np.diff(grid) * (rates[1:] + rates[:-1]) / 2)))
            spanned = np.interp(spans.ends, grid, turns) - np.interp(spans.starts, grid, turns)
            steps = np.maximum(np.ceil(spanned / _reach(min(self.tolerance), n)), 1)
        self.steps += float(steps.sum()) if np.isfinite(steps).all() else math.inf
        return self.steps


def _held_from_start(spans: Spans, u: float) -> int:
    """How many spans from the first hold the torque u (0 when it ramps)."""
    ramps_or_changes = (spans.rate != 0) | (spans.u0 != u)
    return int(np.argmax(ramps_or_changes)) if ramps_or_changes.any() else len(spans.starts)


def _well_speed(u: float, model: tuple[float, float, float], theta0: float, omega0: float) -> float | None:
    """The most |omega| of a pendulum under the held torque u that stays in the well of
    mgL (1 - cos theta) - u theta where it starts; None where it can leave it (or there is none).
    """
    gravity_moment, _, inverse_inertia = model
    g = abs(gravity_moment)
    if not g > abs(u):  # no well: the torque outweighs the gravity everywhere
        return None
    # Measured from the bottom of the gravity's own well (theta - pi where mgL < 0).
    shift = 0.0 if gravity_moment > 0 else math.pi
    x0 = theta0 - shift
    tilt = math.asin(u / g)

    def potential(x: float) -> float:
        return g * (1 - math.cos(x)) - u * (x + shift)

    # The barriers at x = pi - tilt + 2 pi k; the well x0 is in lies between two of them.
    right = math.pi - tilt + 2 * math.pi * math.ceil((x0 - (math.pi - tilt)) / (2 * math.pi))
    left = right - 2 * math.pi
    energy = 0.5 * np.float64(omega0) ** 2 / inverse_inertia + potential(x0)
    if not energy < min(potential(left), potential(right)):
        return None
    bottom = potential(right - math.pi + 2 * tilt)  # the well's lowest point, between the barriers
    return math.sqrt(2 * max(energy - bottom, 0.0) * inverse_inertia)


def taylor_steps(
    spans: Spans, model: tuple[float, float, float], theta0: float, omega0: float, tolerance: tuple[float, float]
) -> float:
    """About how many steps _taylor.integrate_piece takes over the spans, at most rather than at
    least: the speed is an upper bound.

    Parameters
    ----------
    spans : Spans
        The run's pieces.
    model : (float, float, float)
        As integrate_piece takes it.
    theta0, omega0 : float
        The state at the first span's start.
    tolerance : (float, float)
        rtol and atol.

    Returns
    -------
    float
        The steps: inf where the run has more than a double counts, nan where the model's
        constants or the state are not finite (the integration refuses those in its own words).
    """
    return Work(model, theta0, omega0, tolerance).add(spans)


def check_steps(steps: float, start: float, stop: float, rtol: float, max_steps: int | None = None) -> None:
    """InvalidInput past MAX_STEPS, or STEPS_PER_ALLOWED_STEP per grid step the run is allowed
    where that is more, naming what to change.

    Parameters
    ----------
    steps : float
        taylor_steps' estimate.
    start, stop : float
        The run's start and stop (s), for the message.
    rtol : float
        The tolerance asked for, for the message.
    max_steps : int, optional
        The most grid steps the run was allowed (--max-steps), where given.
    """
    limit = max(MAX_STEPS, STEPS_PER_ALLOWED_STEP * (max_steps or 0))
    if steps > limit:
        shown = f"about {steps:,.0f}" if steps < 1e15 else f"about {steps:.3g}" if steps < math.inf else "over 1e308"
        raise InvalidInput(
            f"the reference would take {shown} Taylor steps from {start:g} to {stop:g} s "
            f"(rtol {rtol:g}), over its limit of {limit:,}: give a shorter stop time, smaller "
            "torques or speeds, or a looser rtol"
        )


@contextlib.contextmanager
def progress(steps: float, start: float, stop: float) -> Iterator[Callable[[float], None] | None]:
    """A progress bar of the simulated time on stderr where the run takes BAR_FROM steps or more:
    yields what to call with each time reached, or None for a run too short for one.
    """
    if not steps >= BAR_FROM:  # nan too: a run the integration refuses at once
        yield None
        return
    from .._progress_bar import progress_bar

    with progress_bar("reference", "{n:.4g}/{total:.4g} s", stop - start) as bar:
        reached = [start]

        def advance(t: float) -> None:
            bar.update(t - reached[0])
            reached[0] = t

        yield advance
