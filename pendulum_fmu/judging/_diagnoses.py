"""The candidate mistakes a failed result is tried against, and the diagnosis they give.

Each candidate is a variant of the run with that mistake made (see _judge.py's docstring): the
schedule changed as the mistake changes it, integrated exactly (reference_schedule) at the
result's times. diagnose() names the candidate whose variant leaves only noise, an integration
error, or none; an integration error whose variant leaves only noise is named by its integrator
(INTEGRATORS).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..fmu import _results as results
from ..fmu._model import FmuModel
from ..oracle._reference import equation_of_motion, reference_schedule
from ..signals._time_grid import event_tolerance
from ..signals._torque_csv import TorqueTable, read_torque_csv
from ..signals._torque_schedule import TorqueSchedule

AGREES = "agrees"


LATE, EARLY = "input one step late", "input one step early"


INTERPOLATED, HELD = "input interpolated linearly", "input held"


DRIFT, NOT_RESTORED = "time grid drift", "state not restored"


# A time column one step off its values (a master that files a step's result under the step's
# start, or the reverse), and a result whose theta went through single precision (float32).
SHIFTED, SINGLE = "time column one step off", "result in single precision"


INTEGRATION, UNEXPLAINED = "integration error", "unexplained"


# The integrators of integration error's variants, in their order: what a master that integrates
# the Model Exchange interface itself steps by, and Pendulum-v1 (Gymnasium's, EnvPool's) does.
EXPLICIT_EULER = "explicit Euler at the communication step"
SEMI_IMPLICIT_EULER = "semi-implicit (symplectic) Euler at the communication step"
INTEGRATORS = (EXPLICIT_EULER, SEMI_IMPLICIT_EULER)


DIAGNOSES = (
    AGREES, LATE, EARLY, INTERPOLATED, HELD, DRIFT, SHIFTED, NOT_RESTORED, SINGLE, INTEGRATION, UNEXPLAINED
)  # fmt: skip


# The mistakes in the timing of the input or of the result's rows: a solver's error must be
# small beside them.
INPUT_TIMING = (LATE, EARLY, INTERPOLATED, HELD, DRIFT, SHIFTED)


# A candidate explains a result when its variant removes nearly all of the difference: its
# residual is at most EXPLAINS of the raw difference, or below the noise floor of the comparison
# (NOISE of the tolerance; a correct run leaves 1e-11 rad against the reference). A variant that
# removes only part of it merely resembles the mistake made: explicit Euler lags like an input half
# a step late, and with gravity off semi-implicit Euler is close to an input ramped over each step.
# Measured on the deliberately wrong masters of tests/test_judge.py: the mistake made leaves at most
# 1.2e-8 of the raw difference; the closest other candidate 3.3e-4 of it (semi-implicit Euler
# against a ramped input, gravity off), the others 0.37 or more. 1e-5 sits between 1.2e-8 and
# 3.3e-4, and the smallest residual decides among candidates under it.
EXPLAINS = 1e-5


NOISE = 0.1


# A difference no candidate explains is an integration error when it grows as a solver's does:
# no larger than explicit Euler's at the communication step (the crudest solver a master would
# use), and at most INTEGRATION_SMALL of the smallest difference any input-timing mistake makes in
# this run, so that no such mistake hides in it. Measured: Heun's method at the communication step
# (second order) is 3.2e-3 and 6.4e-3 of the input-timing effects; an input late at one jump only
# (no candidate of its own) 0.38. 0.05 sits between, about a decade from either.
INTEGRATION_SMALL = 0.05


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


def _summed_clock(run: Run, ramp: bool) -> list[np.ndarray]:
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
            variants.append(run.integrate(steps, at=plan.time[done]))
    changes = np.flatnonzero(np.diff(plan.torque)) + 1
    applied = np.r_[0, changes[clock[changes] == plan.time[changes]]]
    if len(applied) <= len(changes):
        last_applied = applied[np.searchsorted(applied, np.arange(len(plan.torque)), side="right") - 1]
        variants.append(run.integrate(_changed(plan, plan.torque[last_applied])))
    return variants


def _shifted(run: Run) -> list[np.ndarray]:
    """Each row holds the run's state one communication point after its time (a master that files
    a step's result under the step's start), or one before; the first row the initial state. The
    last row's next point is one more step of the run's last torque, as the FMU makes it.
    """
    index = _plan_index(run.plan, run.times, run.step_size)
    if index is None:
        return []
    plan = run.plan
    end_torque = plan.torque[-1] + plan.torque_rate[-1] * plan.step_size[-1]
    beyond = TorqueSchedule(
        time=np.r_[plan.time, plan.time[-1] + plan.step_size[-1]],
        torque=np.r_[plan.torque, end_torque],
        torque_rate=np.r_[plan.torque_rate, 0.0],
    )
    return [run.integrate(beyond, at=beyond.time[np.maximum(index + shift, 0)]) for shift in (1, -1)]


def _single_precision(correct: np.ndarray, result: np.ndarray) -> list[np.ndarray]:
    """The reference with theta rounded to float32, where every theta of the result is a float32
    value (a master that hands observations out in single precision); else none.
    """
    theta = np.asarray(result["theta"], dtype=float)
    if not np.array_equal(theta.astype(np.float32).astype(float), theta):
        return []
    variant = correct.copy()
    variant["theta"] = correct["theta"].astype(np.float32)
    return [variant]


def _euler(run: Run, acceleration, semi_implicit: bool) -> np.ndarray:
    """The equation of motion stepped once per communication step of the run's plan, holding
    each step's start torque: explicit Euler, or semi-implicit (the new omega moves theta).
    """
    plan, theta, omega = run.plan, run.theta0, run.omega0
    out = results.empty(len(plan.time), run.model.recorded)  # its FMU's fields: no other looked up
    out["time"] = plan.time
    for k, (h, u) in enumerate(zip(plan.step_size.tolist(), plan.torque.tolist(), strict=False)):
        out["theta"][k], out["omega"][k] = theta, omega
        alpha = acceleration(theta, omega, u)
        if semi_implicit:
            omega += h * alpha
            theta += h * omega
        else:
            theta, omega = theta + h * omega, omega + h * alpha
    out["theta"][-1], out["omega"][-1] = theta, omega
    out["torque"][:-1], out["torque"][-1] = plan.torque, plan.torque[-1]
    return out


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

    def integrate(self, plan: TorqueSchedule, at: np.ndarray | None = None) -> np.ndarray:
        """The schedule from the run's initial state, exactly, at the result's times (or at)."""
        return reference_schedule(
            plan,
            parameters=self.parameters,
            theta0=self.theta0,
            omega0=self.omega0,
            at=self.times if at is None else at,
            fmu_path=self.model,
        )


def _not_restored(run: Run, correct: np.ndarray, first_wrong: int) -> list[np.ndarray]:
    """Up to a point the reference; from there the run restarts from its initial state, as a
    resumed run that did not restore its saved FMU state. The restart is where the first row that
    disagrees is (it shows the initial state), or the row before it (it shows the old instance's
    state, the next row the new one's).
    """
    variants = []
    for restart_row in (first_wrong, first_wrong - 1):
        if restart_row < 1:  # a restart at the very start is no restart
            continue
        restart = run.times[restart_row]
        k = int(np.argmin(np.abs(run.plan.time - restart)))
        off = abs(run.plan.time[k] - restart) > event_tolerance(restart, run.step_size)
        if off or k + 1 >= len(run.plan.time):
            continue
        tail = TorqueSchedule(time=run.plan.time[k:], torque=run.plan.torque[k:], torque_rate=run.plan.torque_rate[k:])
        variant = correct.copy()
        variant[first_wrong:] = run.integrate(tail, at=run.times[first_wrong:])
        variants.append(variant)
    return variants


def _integration(run: Run) -> list[np.ndarray]:
    """The run stepped by each of INTEGRATORS, in their order, at the result's times."""
    index = _plan_index(run.plan, run.times, run.step_size)
    if index is None:
        return []
    acceleration = equation_of_motion(run.parameters)
    return [_euler(run, acceleration, integrator == SEMI_IMPLICIT_EULER)[index] for integrator in INTEGRATORS]


def shared_variants(run: Run, torque, held: TorqueSchedule | None, start_torque: float) -> dict[str, list[np.ndarray]]:
    """{candidate: its variants at the result's times} of every candidate whose variants do not
    depend on the result (all but state not restored): made once for the results of a run that
    share their times. An empty list where a candidate does not apply.
    held: for a ramp run, the same signal held over each step (schedule without ramp).
    """
    plan, ramp = run.plan, held is not None
    off_grid = _plan_index(plan, run.times, run.step_size) is None
    return {
        LATE: [run.integrate(p) for p in _late(plan, start_torque)],
        EARLY: [run.integrate(p) for p in _early(plan)],
        INTERPOLATED: [] if ramp else [run.integrate(p) for p in _interpolated(plan)],
        HELD: [run.integrate(held)] if held is not None else [],
        DRIFT: [run.integrate(p) for p in _drifted(torque, run.times, ramp)] if off_grid else _summed_clock(run, ramp),
        SHIFTED: _shifted(run),
        INTEGRATION: _integration(run),
    }


def candidate_variants(
    shared: dict[str, list[np.ndarray]], run: Run, correct: np.ndarray, result: np.ndarray, tolerance: float
) -> dict[str, list[np.ndarray]]:
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


def diagnose(
    raw: float, tolerance: float, scores: dict[str, dict | None], smallest_input_effect: float | None
) -> tuple[str, float, bool]:
    """The candidate that explains the difference, or integration error, or unexplained; its
    residual; and whether its variant explains it (leaves only noise).
    """
    applicable = {name: score for name, score in scores.items() if score is not None}
    best = min(applicable, key=lambda name: applicable[name]["residual"], default=None)
    if best is not None and applicable[best]["residual"] <= max(EXPLAINS * raw, NOISE * tolerance):
        # Variants the same to the noise are the same run: from rest at an equilibrium, a first step
        # without torque and a restart from the initial state after it cannot be told apart. The
        # earlier in DIAGNOSES, the commoner mistake, names it.
        tied = [
            name
            for name in DIAGNOSES
            if name in applicable and applicable[name]["residual"] <= applicable[best]["residual"] + NOISE * tolerance
        ]
        return tied[0], applicable[tied[0]]["residual"], True
    euler = applicable.get(INTEGRATION)
    if (
        euler is not None
        and raw <= euler["effect"]
        and (smallest_input_effect is None or raw <= INTEGRATION_SMALL * smallest_input_effect)
    ):
        return INTEGRATION, raw, False
    return UNEXPLAINED, applicable[best]["residual"] if best is not None else raw, False
