"""The variants of a run with a candidate mistake made: the schedule changed as the mistake
changes it, integrated exactly (reference_schedule) at the result's times; integration error's
variants stepped by each of INTEGRATORS. _diagnoses.py names the candidates and decides.
"""

from __future__ import annotations

import functools
import math
from array import array
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..fmu import _results as results
from ..fmu._model import FmuModel
from ..oracle._reference import model_constants, reference_schedule
from ..signals._time_grid import event_tolerance
from ..signals._torque_csv import TorqueTable, read_torque_csv
from ..signals._torque_schedule import TorqueSchedule
from ._diagnoses import (
    DIAGNOSES,
    DRIFT,
    EARLY,
    HELD,
    INTEGRATION,
    INTEGRATORS,
    INTERPOLATED,
    LATE,
    NOT_RESTORED,
    SEMI_IMPLICIT_EULER,
    SHIFTED,
    SINGLE,
)


def _plan_index(plan: TorqueSchedule, times: np.ndarray, step_size: float) -> np.ndarray | None:
    """For each time, the index of the communication point it is; None when one is off them."""
    index = np.clip(np.searchsorted(plan.time, times), 1, len(plan.time) - 1)
    index = np.where(np.abs(plan.time[index] - times) < np.abs(plan.time[index - 1] - times), index, index - 1)
    on_grid = np.abs(plan.time[index] - times) <= event_tolerance(times, step_size)
    return index if np.all(on_grid) else None


def _changed(plan: TorqueSchedule, torque: np.ndarray, rate: np.ndarray | None = None) -> TorqueSchedule:
    return TorqueSchedule(time=plan.time, torque=torque, torque_rate=plan.torque_rate if rate is None else rate)


def _late(plan: TorqueSchedule, start_torque: float) -> list[TorqueSchedule]:
    """Step k holds what step k-1 should; the first step the signal's first value or the FMU's
    start value (whatever the master set before it began).
    """
    variants = []
    for first in dict.fromkeys((float(plan.torque[0]), start_torque)):
        first_rate = plan.torque_rate[0] if first == plan.torque[0] else 0.0
        variants.append(_changed(plan, np.r_[first, plan.torque[:-1]], np.r_[first_rate, plan.torque_rate[:-1]]))
    return variants


def _early(plan: TorqueSchedule) -> list[TorqueSchedule]:
    return [_changed(plan, np.r_[plan.torque[1:], plan.torque[-1]], np.r_[plan.torque_rate[1:], 0.0])]


def _interpolated(plan: TorqueSchedule) -> list[TorqueSchedule]:
    """Each step ramps from its value to the next step's; the last one holds."""
    return [_changed(plan, plan.torque, np.r_[np.diff(plan.torque) / plan.step_size[:-1], 0.0])]


def _signal_values(torque, times: np.ndarray, side: str) -> np.ndarray | None:
    """The signal just after (side "after") or before each time, sampled as a master would,
    without the definition's snapping of events onto communication points; None for a per-step
    array, which has no value between its steps.
    """
    if isinstance(torque, (str, Path)):
        torque = read_torque_csv(torque)
    if isinstance(torque, TorqueTable):
        return torque.value_after(times) if side == "after" else torque.value_before(times)
    if callable(torque):
        return np.array([float(torque(t)) for t in times.tolist()])
    if isinstance(torque, (list, tuple, np.ndarray)):
        return None
    return np.full(len(times), float(torque))


def _drifted(torque, times: np.ndarray, ramp: bool) -> list[TorqueSchedule]:
    """The master's steps are the result's own times; each samples the signal at its start."""
    points = np.unique(times)
    start = _signal_values(torque, points[:-1], "after")
    if start is None or len(points) < 2:
        return []
    rate = (_signal_values(torque, points[1:], "before") - start) / np.diff(points) if ramp else np.zeros(len(start))
    return [TorqueSchedule(time=points, torque=start, torque_rate=rate)]


def _summed_clock(run: Run, ramp: bool) -> list[Variant]:
    """Masters whose clock is summed step by step and compared with times without a tolerance.

    One steps the FMU while its own time, the result's, is at or past the FMU's next communication
    point on that clock (FMI++'s FixedStepSizeFMU.sync), and after each row sets the torque of the
    step that starts at the row's time: where the clocks round apart a step is skipped, the FMU a
    step behind (its rows a step old, its input a step early) until a row takes two. Only for a
    row per communication point, where a step is skipped. The other applies a change of the
    torque only where its clock equals the change's time (a scenario's actions, ECOS's through
    ecospy): a change it misses never reaches the FMU. Only where a change is missed.
    """
    plan, times = run.plan, run.times
    if ramp:
        return []
    clock = np.cumsum(np.r_[plan.time[0], np.full(len(plan.step_size), run.step_size)])
    variants = []
    index = _plan_index(plan, times, run.step_size)
    if index is not None and np.array_equal(index, np.arange(len(plan.time))):
        # The FMU's steps done when each row is written (none before the start: a row within rounding of it).
        done = np.maximum(np.searchsorted(clock, times, side="right") - 1, 0)
        if done[-1] >= 1 and not np.array_equal(done, np.arange(len(times))):
            # Step j runs with what the row before the first row that has it done set.
            setter = np.searchsorted(done, np.arange(done[-1]) + 1, side="left") - 1
            steps = TorqueSchedule(
                time=plan.time[: done[-1] + 1], torque=plan.torque[setter], torque_rate=np.zeros(done[-1])
            )
            variants.append(run.variant(functools.partial(run.integrate, steps, at=plan.time[done])))
    changes = np.flatnonzero(np.diff(plan.torque)) + 1
    applied = np.r_[0, changes[clock[changes] == plan.time[changes]]]
    if len(applied) <= len(changes):
        last_applied = applied[np.searchsorted(applied, np.arange(len(plan.torque)), side="right") - 1]
        variants.append(run.variant(functools.partial(run.integrate, _changed(plan, plan.torque[last_applied]))))
    return variants


def _shifted(run: Run) -> list[Variant]:
    """Each row holds the run's state one communication point after its time (a master that files
    a step's result under the step's start), or one before; the first row the initial state. The
    last row's next point is one more step of the run's last torque, as the FMU makes it.
    """
    index = _plan_index(run.plan, run.times, run.step_size)
    if index is None:
        return []
    return [run.variant(functools.partial(_shifted_by, run, index, shift)) for shift in (1, -1)]


def _shifted_by(run: Run, index: np.ndarray, shift: int) -> np.ndarray:
    """The run one more step long, at the plan's points index + shift (the first at the start)."""
    plan = run.plan
    end_torque = plan.torque[-1] + plan.torque_rate[-1] * plan.step_size[-1]
    beyond = TorqueSchedule(
        time=np.r_[plan.time, plan.time[-1] + plan.step_size[-1]],
        torque=np.r_[plan.torque, end_torque],
        torque_rate=np.r_[plan.torque_rate, 0.0],
    )
    return run.integrate(beyond, at=beyond.time[np.maximum(index + shift, 0)])


def _single_precision(correct: np.ndarray, result: np.ndarray) -> list[Variant]:
    """The reference with theta rounded to float32, where every theta of the result is a float32
    value (a master that hands observations out in single precision); else none.
    """
    theta = np.asarray(result["theta"], dtype=float)
    if not np.array_equal(theta.astype(np.float32).astype(float), theta):
        return []
    return [functools.partial(_rounded_to_single, correct)]


def _rounded_to_single(correct: np.ndarray) -> np.ndarray:
    variant = correct.copy()
    variant["theta"] = correct["theta"].astype(np.float32)
    return variant


def _euler(run: Run, semi_implicit: bool, index: np.ndarray) -> np.ndarray:
    """The equation of motion stepped once per communication step of the run's plan, holding
    each step's start torque: explicit Euler, or semi-implicit (the new omega moves theta); at
    the plan's points index (the result's rows).
    """
    plan, theta, omega = run.plan, run.theta0, run.omega0
    # The equation written out with math.sin: a step in Python costs a third of one through numpy.
    gravity_moment, damping, inverse_inertia = model_constants(run.parameters)
    thetas, omegas = array("d"), array("d")
    # The steps' lengths and torques as floats a block at a time: lists of a whole long run's
    # would take 64 bytes a step.
    for begin in range(0, len(plan.torque), _BLOCK):
        block = slice(begin, begin + _BLOCK)
        for h, u in zip(plan.step_size[block].tolist(), plan.torque[block].tolist(), strict=True):
            thetas.append(theta)
            omegas.append(omega)
            alpha = (u - gravity_moment * math.sin(theta) - damping * omega) * inverse_inertia
            if semi_implicit:
                omega += h * alpha
                theta += h * omega
            else:
                theta, omega = theta + h * omega, omega + h * alpha
    thetas.append(theta)
    omegas.append(omega)
    out = results.empty(len(index), run.model.recorded)  # its FMU's fields: no other looked up
    out["time"] = plan.time[index]
    out["theta"], out["omega"] = np.frombuffer(thetas)[index], np.frombuffer(omegas)[index]
    out["torque"] = plan.torque[np.minimum(index, len(plan.torque) - 1)]
    return out


_SCHEDULE = ("time", "torque", "torque_rate")


# Steps of integration error's Euler taken as floats at once.
_BLOCK = 1 << 16


# A variant at the result's times, made when called.
Variant = Callable[[], np.ndarray]


# Results up to this many rows keep their variants once made (for the next result on the same
# times; 40 bytes a row each); a longer one's are made one at a time, scored and let go.
KEEP_ROWS = 200_000


@dataclass
class Run:
    """What every variant of one run needs."""

    plan: TorqueSchedule
    times: np.ndarray
    step_size: float
    parameters: dict
    theta0: float
    omega0: float
    model: FmuModel

    # Kept: whether this run's variants stay made once made (KEEP_ROWS), and the run's own
    # schedule integrated, which variants of a run holding its torque for long stretches often
    # are (a constant torque one step late).
    keep: bool = True
    _own: np.ndarray | None = field(default=None, repr=False)

    def integrate(self, plan: TorqueSchedule, at: np.ndarray | None = None) -> np.ndarray:
        """The schedule from the run's initial state, exactly, at the result's times (or at)."""
        own = at is None and all(np.array_equal(getattr(plan, name), getattr(self.plan, name)) for name in _SCHEDULE)
        if own and self._own is not None:
            return self._own
        integrated = reference_schedule(
            plan,
            parameters=self.parameters,
            theta0=self.theta0,
            omega0=self.omega0,
            at=self.times if at is None else at,
            fmu_path=self.model,
        )
        if own:
            self._own = integrated
        return integrated

    def variant(self, make: Callable[[], np.ndarray]) -> Variant:
        """A variant made by make() when it is first asked for: kept then for a short run (its
        results share it), made anew each time for a long one, which holds one at a time.
        """
        if not self.keep:
            return make
        return functools.cache(make)


def _not_restored(run: Run, correct: np.ndarray, first_wrong: int) -> list[Variant]:
    """Up to a point the reference; from there the run restarts from its initial state, as a
    resumed run that did not restore its saved FMU state. The restart is where the first row that
    disagrees is (it shows the initial state), or the row before it (it shows the old instance's
    state, the next row the new one's).
    """
    variants: list[Variant] = []
    for restart_row in (first_wrong, first_wrong - 1):
        if restart_row < 1:  # a restart at the very start is no restart
            continue
        restart = run.times[restart_row]
        k = int(np.argmin(np.abs(run.plan.time - restart)))
        off = abs(run.plan.time[k] - restart) > event_tolerance(restart, run.step_size)
        if off or k + 1 >= len(run.plan.time):
            continue
        tail = TorqueSchedule(time=run.plan.time[k:], torque=run.plan.torque[k:], torque_rate=run.plan.torque_rate[k:])
        variants.append(functools.partial(_restarted, run, correct, first_wrong, tail))
    return variants


def _restarted(run: Run, correct: np.ndarray, first_wrong: int, tail: TorqueSchedule) -> np.ndarray:
    """The reference up to first_wrong, the tail of the schedule from the initial state after."""
    variant = correct.copy()
    variant[first_wrong:] = run.integrate(tail, at=run.times[first_wrong:])
    return variant


def _integration(run: Run) -> list[Variant]:
    """The run stepped by each of INTEGRATORS, in their order, at the result's times."""
    index = _plan_index(run.plan, run.times, run.step_size)
    if index is None:
        return []
    return [run.variant(functools.partial(_stepped, run, integrator, index)) for integrator in INTEGRATORS]


def _stepped(run: Run, integrator: str, index: np.ndarray) -> np.ndarray:
    """The run stepped by the integrator (one of INTEGRATORS), at the result's rows (index)."""
    return _euler(run, integrator == SEMI_IMPLICIT_EULER, index)


def shared_variants(run: Run, torque, held: TorqueSchedule | None, start_torque: float) -> dict[str, list[Variant]]:
    """{candidate: its variants at the result's times} of every candidate whose variants do not
    depend on the result (all but state not restored): made once for the results of a run that
    share their times (Run.variant). An empty list where a candidate does not apply.
    held: for a ramp run, the same signal held over each step (schedule without ramp).
    """
    plan, ramp = run.plan, held is not None
    off_grid = _plan_index(plan, run.times, run.step_size) is None

    def integrated(make: Callable[..., list[TorqueSchedule]], *args) -> list[Variant]:
        # The schedules are made again by each variant when it is made: a long run's would
        # hold 24 bytes a step each, all the while.
        return [run.variant(functools.partial(_integrated, run, make, args, i)) for i in range(len(make(*args)))]

    return {
        LATE: integrated(_late, plan, start_torque),
        EARLY: integrated(_early, plan),
        INTERPOLATED: [] if ramp else integrated(_interpolated, plan),
        HELD: integrated(_held, held) if held is not None else [],
        DRIFT: integrated(_drifted, torque, run.times, ramp) if off_grid else _summed_clock(run, ramp),
        SHIFTED: _shifted(run),
        INTEGRATION: _integration(run),
    }


def _integrated(run: Run, make: Callable[..., list[TorqueSchedule]], args: tuple, i: int) -> np.ndarray:
    """The i-th schedule make(*args) gives, integrated at the result's times."""
    return run.integrate(make(*args)[i])


def _held(held: TorqueSchedule) -> list[TorqueSchedule]:
    """A ramp run's signal held over each step: the one variant of input held."""
    return [held]


def candidate_variants(
    shared: dict[str, list[Variant]], run: Run, correct: np.ndarray, result: np.ndarray, tolerance: float
) -> dict[str, list[Variant]]:
    """{candidate: its variants at the result's times}, in DIAGNOSES' order: the shared ones
    (shared_variants), state not restored, which restarts where this result first disagrees, and
    single precision, which applies to a result whose theta are all float32 values.
    """
    wrong = np.flatnonzero(np.abs(result["theta"] - correct["theta"]) > tolerance)
    own = {
        NOT_RESTORED: _not_restored(run, correct, int(wrong[0])) if len(wrong) else [],
        SINGLE: _single_precision(correct, result),
    }
    return {name: own[name] if name in own else shared[name] for name in DIAGNOSES if name in own or name in shared}
