"""The oracle's integrator: the pendulum's Taylor series, stepped over one piece of linear torque.

    theta'' = (u0 + rate*(t - t0) - gravity_moment*sin(theta) - damping*theta') * inverse_inertia

Each step expands theta, omega, sin(theta) and cos(theta) in powers of the time from the step's
start, their coefficients following from one another by the recurrences of the equation and of
sin and cos (s' = c*theta', c' = -s*theta'), exactly, in floating point; the series is then
summed at the reported times and at the step's end. The order and the step follow Jorba and
Zou (2005, "A software package for the numerical integration of ODEs by means of high-order
Taylor methods"): terms up to the order at which the last two, at the step, are below the
tolerance; where the piece is longer than that, the step at which they are.

Why not scipy's solve_ivp: it is what the oracle used until issue 42, and importing
scipy.integrate took 0.3 s of a 0.7-s `judge`. This code is the pendulum's equation and two
recurrences, shares nothing with the FMU's integrator (C, fmu_src/), and is held to solve_ivp at
tight tolerance and to closed-form solutions by tests/test_taylor.py.

_taylor_native.c is this integrator in C, operation for operation, for a window's runs in one
call (a Python call per run was most of a judge of a torque that changes every step); where it
was compiled integrate_window uses it, and it gives these numbers bit for bit
(tests/test_taylor_native.py). This stays the readable reference and the fallback: a change here
is a change there.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable

import numpy as np

from .._errors import InvalidInput

# Up to this many reports in a step are summed one by one; more, as one array (numpy's call
# costs about as much as summing a few).
_FEW = 8


# The smallest rtol: a double's resolution. Below it no step is exact enough, and the steps
# would shrink without end.
SMALLEST_RTOL = 1e-16


def check_tolerances(rtol: float, atol: float) -> None:
    """InvalidInput unless atol is a positive finite number and rtol one of at least SMALLEST_RTOL.

    Parameters
    ----------
    rtol, atol
        The tolerances integrate_piece takes.
    """
    for name, value in (("rtol", rtol), ("atol", atol)):
        if not (isinstance(value, numbers.Real) and 0 < value < math.inf):
            raise InvalidInput(
                f"{name} {value!r} must be a positive finite number (a tolerance of the reference's integrator)"
            )
    if rtol < SMALLEST_RTOL:
        raise InvalidInput(
            f"rtol {rtol!r} asks for more than a double holds: give at least {SMALLEST_RTOL:g}, "
            "the reference's rounding"
        )


class Diverged(InvalidInput):
    """The series cannot be summed: a coefficient is not finite, or the step underflows."""


def order_limit(tolerance: float) -> int:
    """Jorba and Zou's order for a tolerance: the terms' ratio at the step is then about e**-2.
    At most 30 (a tolerance of 1e-24): a smaller tolerance takes smaller steps instead.
    """
    return min(max(8, math.ceil(-0.5 * math.log(tolerance)) + 2), 30)


def _sum(coefficients: list[float], tau: float) -> float:
    total = coefficients[-1]
    for coefficient in reversed(coefficients[:-1]):
        total = total * tau + coefficient
    return total


def integrate_piece(
    theta: float,
    omega: float,
    span: tuple[float, float],
    torque: tuple[float, float],
    model: tuple[float, float, float],
    tolerance: tuple[float, float],
    reports: np.ndarray | list[float],
    on_step: Callable[[float], None] | None = None,
) -> tuple[np.ndarray, np.ndarray, float, float]:
    """Theta and omega at each of reports and at the piece's end, from theta, omega at its start.

    Parameters
    ----------
    theta, omega : float
        The state at span[0], in rad and rad/s.
    span : (float, float)
        The piece's start and end, in s (end >= start).
    torque : (float, float)
        The torque at the piece's start (N.m) and its rate (N.m/s).
    model : (float, float, float)
        mass*gravity*length (N.m), damping (N.m.s/rad) and 1/total inertia (1/(kg.m^2)).
    tolerance : (float, float)
        rtol and atol: each step's terms past its order stay below atol + rtol * max(abs(theta), abs(omega)).
    reports : numpy.ndarray or list of float
        Sorted times within span.
    on_step : callable, optional
        Called with the time each step reaches (a progress bar's).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray, float, float)
        theta and omega at each report; theta and omega at span[1].

    Raises
    ------
    Diverged
        A coefficient is not finite, or the step needed underflows the time.
    """
    start, end = span
    u0, rate = torque
    gravity_moment, damping, inverse_inertia = model
    rtol, atol = tolerance
    order = order_limit(min(rtol, atol))
    # Arrays, filled a Taylor step's reports at a time: a piece may hold millions of reports,
    # which as lists of floats took four times the memory.
    reports = np.asarray(reports, dtype=float)
    thetas, omegas = np.empty(len(reports)), np.empty(len(reports))
    t, next_report = start, 0
    while True:
        remaining = end - t
        bound = atol + rtol * max(abs(theta), abs(omega))
        x, v = [theta, omega], [omega]
        sines, cosines = [math.sin(theta)], [math.cos(theta)]
        inputs = (u0 + rate * (t - start), rate)
        for k in range(order):
            if k:  # sin and cos to order k, from theta's terms up to k
                sine = cosine = 0.0
                for j in range(1, k + 1):
                    jx = j * x[j]
                    sine += jx * cosines[k - j]
                    cosine += jx * sines[k - j]
                sines.append(sine / k)
                cosines.append(-cosine / k)
            u = inputs[k] if k < 2 else 0.0
            v.append((u - gravity_moment * sines[k] - damping * v[k]) * inverse_inertia / (k + 1))
            x.append(v[k + 1] / (k + 2))
            # The last two terms of each series: omega's to order k+1, theta's to order k+2.
            last_terms = ((x[k + 2], k + 2), (x[k + 1], k + 1), (v[k + 1], k + 1), (v[k], k))
            if not all(math.isfinite(term) for term, _ in last_terms):
                raise Diverged("a Taylor coefficient is not finite")
            if k:  # the longest step at which each of those terms stays below the bound
                reach = min((bound / abs(term)) ** (1.0 / power) if term else math.inf for term, power in last_terms)
                if remaining <= reach:
                    break
        step = min(remaining, reach)
        stop = end if step == remaining else t + step
        if stop <= t < end:
            raise Diverged(f"the step needed underflows at t = {t:g} s")
        upto = len(reports) if stop == end else int(np.searchsorted(reports, stop, side="right"))
        if upto - next_report > _FEW:
            taus = reports[next_report:upto] - t
            thetas[next_report:upto] = np.polyval(x[::-1], taus)
            omegas[next_report:upto] = np.polyval(v[::-1], taus)
        else:
            for i, report in enumerate(reports[next_report:upto].tolist(), start=next_report):
                thetas[i] = _sum(x, report - t)
                omegas[i] = _sum(v, report - t)
        next_report = upto
        theta, omega = _sum(x, stop - t), _sum(v, stop - t)
        if not (math.isfinite(theta) and math.isfinite(omega)):
            raise Diverged("the state is not finite")
        t = stop
        if on_step is not None:
            on_step(t)
        if t == end:
            return thetas, omegas, theta, omega
