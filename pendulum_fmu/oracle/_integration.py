"""The oracle's integration of a window of pieces of linear torque, from a given state: the part
reference(), reference_windows() and reference_schedule() share (_reference.py).

The pieces that continue one another (the same held torque) are one run, integrated by the
Taylor series (_taylor.py) restarting only where the torque changes; a window's reports are
summed where they fall, and the state at the window's end is carried to the next. Where the
native Taylor stepping was compiled (_taylor_native.c) it integrates a window's runs in a few
calls, to the same bits as _taylor.integrate_piece run by run, which is the fallback.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .._errors import InvalidInput
from ..fmu import _results as results
from ..fmu._parameters import Fmu, start_value, total_inertia
from ..fmu._simulate import resolve_parameters
from . import _taylor_native
from ._exact_signal import Pieces, time_doubles
from ._taylor import Diverged, check_tolerances, integrate_piece
from ._work import Spans

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


class Model:
    """The pendulum a run integrates: its start state, tolerances and parameters, each checked
    (and the FMU's defaults read) once, whatever the number of windows.
    """

    def __init__(self, parameters: dict | None, theta0: float, omega0: float, rtol: float, atol: float, fmu_path: Fmu):
        self.theta0, self.omega0 = start_value("theta0", theta0, "rad"), start_value("omega0", omega0, "rad/s")
        check_tolerances(rtol, atol)
        self.rtol, self.tolerance = rtol, (rtol, atol)
        self.parameters = resolve_parameters(parameters, fmu_path)
        self.acceleration, self.constants = equation_of_motion(self.parameters), model_constants(self.parameters)


class Runs:
    """A window's pieces as doubles, and its runs: the pieces that continue one another (the
    same held torque) are one run, so that the series restarts only where the torque changes.
    """

    def __init__(self, pieces: Pieces):
        self.pieces = pieces
        self.starts = time_doubles(pieces.starts)
        self.ends = np.append(self.starts[1:], float(pieces.stop))
        self.u0s, self.rates = np.asarray(pieces.u0, dtype=float), np.asarray(pieces.rate, dtype=float)
        u0s, rates = self.u0s, self.rates
        continues = (rates[1:] == 0) & (rates[:-1] == 0) & (u0s[1:] == u0s[:-1])
        self.firsts = np.flatnonzero(np.r_[True, ~continues])
        self.lasts = np.r_[self.firsts[1:] - 1, len(self.starts) - 1]

    def spans(self) -> Spans:
        """The runs, as the work estimate takes them."""
        firsts, lasts = self.firsts, self.lasts
        return Spans(self.starts[firsts], self.ends[lasts], self.u0s[firsts], self.rates[firsts])


def integrate_window(
    runs: Runs,
    at: np.ndarray,
    model: Model,
    state: tuple[float, float],
    on_step: Callable[[float], None] | None,
    final: bool,
) -> tuple[np.ndarray, float, float]:
    """The result at the times `at` (sorted or not, within the window or a rounding past its
    ends), and theta and omega at the window's end, integrated from `state` at its start.

    Parameters
    ----------
    runs : Runs
        The window's pieces.
    at : numpy.ndarray
        The times to report, in s.
    model : Model
        The pendulum.
    state : (float, float)
        theta and omega at the window's start.
    on_step : callable or None
        The progress bar's, called with each time a Taylor step reaches.
    final : bool
        Whether the run ends with this window: a report at its end then gives the torque the
        last piece reached, as a master reads it back, not the torque just after it.

    Returns
    -------
    (numpy.ndarray, float, float)
        The result (time, torque, theta, omega, alpha); theta and omega at the window's end.
    """
    pieces, starts, ends, u0s, rates = runs.pieces, runs.starts, runs.ends, runs.u0s, runs.rates
    firsts, lasts = runs.firsts, runs.lasts
    # The reports in time order (a result's are: no copy is made). Each belongs to the first piece
    # that reaches it, so a run's are a slice: those after the run before's end, up to its own (a
    # time a rounding past the end of the run belongs to the last).
    order = None if np.all(at[1:] >= at[:-1]) else np.argsort(at, kind="stable")
    ordered = at if order is None else at[order]
    bounds = np.searchsorted(ordered, ends[lasts], side="right")
    bounds[-1] = len(at)
    out = results.empty(len(at), COMPUTED)
    out["time"] = at
    if _taylor_native.available():
        # The numbers of integrate_piece below, without a Python call per run: with a torque that
        # changes every communication step, a run is one step.
        try:
            thetas, omegas, theta, omega = _taylor_native.integrate_runs(
                (starts[firsts], ends[lasts], u0s[firsts], rates[firsts]),
                np.r_[0, bounds],
                ordered,
                state,
                model.constants,
                model.tolerance,
                on_step,
            )
        except _taylor_native.RunDiverged as error:
            raise _failed(str(error), error.start, model, pieces) from None
        mine = slice(None) if order is None else order
        out["theta"][mine], out["omega"][mine] = thetas, omegas
    else:
        theta, omega = state
        for first, last, lo, hi in np.stack([firsts, lasts, np.r_[0, bounds[:-1]], bounds]).T.tolist():
            t0, t1, u0, rate = float(starts[first]), float(ends[last]), float(u0s[first]), float(rates[first])
            try:
                thetas, omegas, theta, omega = integrate_piece(
                    theta,
                    omega,
                    (t0, t1),
                    (u0, rate),
                    model.constants,
                    model.tolerance,
                    np.clip(ordered[lo:hi], t0, t1),
                    on_step,
                )
            except Diverged as error:
                raise _failed(str(error), t0, model, pieces) from None
            mine = slice(lo, hi) if order is None else order[lo:hi]
            out["theta"][mine], out["omega"][mine] = thetas, omegas
    out["torque"] = pieces.values_after(at)
    if final:
        # The end of the run reports the torque the last piece reached, as a master reads it back.
        at_end = at >= ends[-1]
        out["torque"][at_end] = u0s[-1] + rates[-1] * (ends[-1] - starts[-1])
    with np.errstate(over="ignore", invalid="ignore"):
        out["alpha"] = model.acceleration(out["theta"], out["omega"], out["torque"])
    if not np.isfinite(out["alpha"]).all():  # the states stayed finite, the acceleration did not
        at_time = float(out["time"][np.flatnonzero(~np.isfinite(out["alpha"]))[0]])
        raise _failed("the acceleration is not finite", at_time, model, pieces)
    return out, theta, omega


def _failed(why: str, t: float, model: Model, pieces: Pieces) -> InvalidInput:
    """The one-line error for an integration these values break, naming every value."""
    values = ", ".join(
        f"{name} = {value:g}"
        for name, value in {**model.parameters, "theta0": model.theta0, "omega0": model.omega0}.items()
    )
    torque = max(abs(u) for u in pieces.u0)
    return InvalidInput(
        f"the reference cannot integrate the pendulum from t = {t:g} s with {values} "
        f"and torques up to {torque:g}: {why.rstrip('.')}; values near the largest "
        "double (mass*gravity*length, mass*length^2, the torque over the inertia) "
        "break it: give physically meaningful values"
    )
