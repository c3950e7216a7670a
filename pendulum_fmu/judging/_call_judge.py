"""Name where what a master did to the FMU (read by _call_record.py) differs from the intended run.

    pendulum-fmu judge --calls LOG [--torque N | --torque-file F.csv] [--ramp] [--set NAME=VALUE ...]

Given the intended run (the simulate options) it names each difference exactly, step by step,
and says what regression tools would make of the run the steps made.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field
from itertools import pairwise
from pathlib import Path

import numpy as np

from .._atomic_files import replacing
from ..fmu._model import START_VALUES
from ..fmu._parameters import default_parameters
from ..oracle._reference import reference_schedule
from ..signals._torque_schedule import TorqueSchedule, TorqueSignal, schedule
from ._call_record import TIME_TOLERANCE, InstanceCalls, read_calls, reconstruct, timeline
from ._regression_tools import format_verdicts, regression_verdicts

# A value a master passed agrees with the intended one to this (relative): both are doubles
# printed at round-trip precision, or at fmpy's repr, so only the master's arithmetic differs.
VALUE_TOLERANCE = 1e-12
# How many steps late or early the reading looks for.
MAX_SHIFT = 10


@dataclass
class IntendedRun:
    """The run a master was meant to make, in the simulate command's terms.

    Parameters
    ----------
    torque : float, str or Path
        A constant torque or a torque CSV.
    ramp : bool
        Whether each step ramps along the signal (input derivatives).
    parameters : dict
        Parameters set with --set, by name.
    start_values : dict
        theta0 and omega0 where given.
    start_time : float
    """

    torque: TorqueSignal
    ramp: bool = False
    parameters: dict = field(default_factory=dict)
    start_values: dict = field(default_factory=dict)
    start_time: float = 0.0


def _close(a: float, b: float) -> bool:
    return abs(a - b) <= VALUE_TOLERANCE * max(1.0, abs(a), abs(b))


def _first_mismatch(applied: np.ndarray, intended: np.ndarray) -> int | None:
    bad = np.flatnonzero(np.abs(applied - intended) > VALUE_TOLERANCE * np.maximum(1.0, np.abs(intended)))
    return int(bad[0]) if len(bad) else None


def _shift(applied: np.ndarray, intended: np.ndarray, first: int) -> int | None:
    """The shift k of the steps from `first` on, or None when no shift explains them.

    k > 0: each step applies what step k earlier was meant to (late); k < 0: what step |k| later
    was meant to (early).
    """
    n = len(applied)
    for k in (k for size in range(1, MAX_SHIFT + 1) for k in (size, -size)):
        lo, hi = max(first, k), min(n, n + k)
        if hi - lo < 1:
            continue
        if _first_mismatch(applied[lo:hi], intended[lo - k : hi - k]) is None:
            return k
    return None


def differences(record: InstanceCalls, intended: IntendedRun) -> list[str]:
    """Each way what the master did differs from the intended run, exactly and by step.

    Parameters
    ----------
    record : InstanceCalls
        One instance, as reconstruct returns it.
    intended : IntendedRun

    Returns
    -------
    list of str
        Empty when the master did what was intended.

    Examples
    --------
    >>> differences(record, IntendedRun(torque=20.0))  # doctest: +SKIP
    ['input applied 1 step late from step 0 (t = 0): ...']
    """
    found = [*_settings_differences(record, intended), *_restore_differences(record)]
    steps = record.steps
    if record.interface == "ModelExchange" or (not steps and record.model_exchange_times):
        return [*found, *_model_exchange(record)]
    if not steps:
        return [*found, "no communication step taken"]
    sizes = np.array([step.size for step in steps])
    times = np.array([step.time for step in steps])
    size = float(sizes[0])
    if not np.allclose(sizes, size, rtol=TIME_TOLERANCE, atol=0):
        k = int(np.flatnonzero(~np.isclose(sizes, size, rtol=TIME_TOLERANCE, atol=0))[0])
        return [
            *found,
            f"variable step sizes: {sizes.min():.17g} to {sizes.max():.17g} s (step {k} "
            f"at t = {times[k]:.17g} is {sizes[k]:.17g} s, step 0 {size:.17g} s)",
        ]
    grid = intended.start_time + size * np.arange(len(steps))
    drift = np.abs(times - grid)
    if drift.max() > TIME_TOLERANCE * max(1.0, abs(grid[-1])):
        k = int(np.argmax(drift > TIME_TOLERANCE * max(1.0, abs(grid[-1]))))
        found.append(
            f"communication points drift: step {k} starts at t = {times[k]:.17g}, not "
            f"{grid[k]:.17g} (up to {drift.max():.3g} s off by step {int(np.argmax(drift))})"
        )
    plan = _plan(record, intended)
    n = min(len(steps), len(plan.torque))
    found.extend(_torque_differences(np.array([step.torque for step in steps[:n]]), plan.torque[:n], times))
    found.extend(_ramp_differences(np.array([step.torque_rate for step in steps[:n]]), plan.torque_rate[:n], times))
    if len(steps) != len(plan.torque):
        found.append(f"{len(steps)} steps taken, {len(plan.torque)} intended")
    return found


def _settings_differences(record: InstanceCalls, intended: IntendedRun) -> list[str]:
    """The intended parameters and start values the master did not set, or set otherwise."""
    found = []
    for name, value in intended.parameters.items():
        if name not in record.set_before_start:
            found.append(f"parameter {name} not set (intended {value:.17g}; the FMU used its start value)")
        elif not _close(record.set_before_start[name], value):
            found.append(f"parameter {name} set to {record.set_before_start[name]:.17g}, intended {value:.17g}")
    for option, value in intended.start_values.items():
        variable = START_VALUES[option]
        if variable not in record.set_before_start and value != 0.0:
            found.append(f"start value {variable} not set (intended {value:.17g})")
        elif variable in record.set_before_start and not _close(record.set_before_start[variable], value):
            found.append(
                f"start value {variable} set to {record.set_before_start[variable]:.17g}, intended {value:.17g}"
            )
    return found


def _restore_differences(record: InstanceCalls) -> list[str]:
    """The FMU states restored to another time, and the rewinds no restore explains."""
    found = [
        f"call {number}: an FMU state restored to t = {after:.17g} at t = {before:.17g}"
        for number, before, after in record.restores
        if before is not None and after is not None and not math.isclose(before, after, abs_tol=TIME_TOLERANCE)
    ]
    if not any(before is not None for _, before, _ in record.restores):
        found.extend(
            f"call {number}: the master went back from t = {reached:.17g} to t = "
            f"{time:.17g} (an FMU state restored to another time)"
            for number, reached, time in record.rewinds
        )
    return found


def _torque_differences(applied: np.ndarray, intended: np.ndarray, times: np.ndarray) -> list[str]:
    """The first step whose torque is not the intended one: a shift (late, early) or another value."""
    first = _first_mismatch(applied, intended)
    if first is None:
        return []
    shift = _shift(applied, intended, first)
    at = f"from step {first} (t = {times[first]:.17g})"
    if shift is not None and shift > 0:
        return [
            f"input applied {shift} step{'s' * (shift > 1)} late {at}: step n holds the torque "
            f"meant for step n-{shift} (set after the step it was meant for)"
        ]
    if shift is not None:
        return [
            f"input applied {-shift} step{'s' * (shift < -1)} early {at}: step n holds the torque "
            f"meant for step n+{-shift}"
        ]
    return [f"torque differs {at}: {applied[first]:.17g} N.m applied, {intended[first]:.17g} N.m intended"]


def _ramp_differences(rate: np.ndarray, intended_rate: np.ndarray, times: np.ndarray) -> list[str]:
    """Steps that ramp where they should hold, hold where they should ramp, or ramp at another rate."""
    found = []
    ramps, should_ramp = rate != 0, intended_rate != 0
    if (ramps & ~should_ramp).any():
        k = int(np.flatnonzero(ramps & ~should_ramp)[0])
        found.append(
            f"ramped where it should hold from step {k} (t = {times[k]:.17g}): der(torque) = {rate[k]:.17g} N.m/s"
        )
    if (~ramps & should_ramp).any():
        k = int(np.flatnonzero(~ramps & should_ramp)[0])
        found.append(
            f"held where it should ramp from step {k} (t = {times[k]:.17g}): intended "
            f"der(torque) = {intended_rate[k]:.17g} N.m/s"
        )
    elif (ramps & should_ramp).any():
        wrong = np.flatnonzero(ramps & should_ramp & ~np.isclose(rate, intended_rate, rtol=1e-9))
        if len(wrong):
            k = int(wrong[0])
            found.append(
                f"ramp rate differs from step {k} (t = {times[k]:.17g}): {rate[k]:.17g} "
                f"N.m/s applied, {intended_rate[k]:.17g} intended"
            )
    return found


def _plan(record: InstanceCalls, intended: IntendedRun):
    """The intended run's schedule on the master's first step size, to where its steps end."""
    last = record.steps[-1]
    return schedule(
        intended.torque,
        start_time=intended.start_time,
        stop_time=last.time + last.size,
        step_size=record.steps[0].size,
        ramp=intended.ramp,
    )


def _run_as_done(record: InstanceCalls, intended: IntendedRun) -> list[dict] | None:
    """What regression tools would say about the master's run, reconstructed from its calls.

    The run the steps made (their times, torques and derivatives, with the parameters and
    start values the master set) and the intended run, both integrated exactly
    (reference_schedule) at the master's communication points, compared on theta by
    regression_tools. None where the steps do not make one run forward in time (a state
    restored, a reset, steps that skip or overlap) or use second derivatives of the input.
    """
    steps = record.steps
    contiguous = all(abs(b.time - (a.time + a.size)) <= TIME_TOLERANCE for a, b in pairwise(steps))
    if len(steps) < 2 or not contiguous or any(step.torque_acceleration for step in steps):
        return None
    times = np.array([step.time for step in steps] + [steps[-1].time + steps[-1].size])
    done = TorqueSchedule(
        times, np.array([step.torque for step in steps]), np.array([step.torque_rate for step in steps])
    )
    set_by_master = record.set_before_start
    parameters = {name: value for name, value in set_by_master.items() if name in default_parameters()}
    as_done = reference_schedule(
        done, parameters=parameters, theta0=set_by_master.get("theta", 0.0), omega0=set_by_master.get("omega", 0.0)
    )
    start = intended.start_values
    meant = reference_schedule(
        _plan(record, intended),
        parameters=intended.parameters,
        at=times,
        theta0=start.get("theta0") or 0.0,
        omega0=start.get("omega0") or 0.0,
    )
    return regression_verdicts(times, meant["theta"], as_done["theta"])


def _model_exchange(record: InstanceCalls) -> list[str]:
    """What a Model Exchange master's integrator was, from its calls.

    Explicit Euler when each state it set is the previous one plus the time between them times
    the derivatives there, exactly.
    """
    times = np.unique(np.array(record.model_exchange_times))
    if len(times) < 2:
        return ["Model Exchange master: fewer than two time points set"]
    points = np.diff(times)
    summary = (
        f"{len(record.model_exchange_times)} fmi2SetTime calls at {len(times)} distinct "
        f"times, {float(times[0]):.17g} to {float(times[-1]):.17g} s, "
        f"{len(record.evaluations)} derivative evaluations"
    )
    pairs = list(zip(record.evaluations, record.evaluations[1:], strict=False))
    euler = bool(pairs) and all(
        t1 > t0 and np.allclose(x1, np.array(x0) + (t1 - t0) * np.array(dx0), rtol=1e-12, atol=1e-15)
        for (t0, x0, dx0), (t1, x1, _) in pairs
    )
    if euler:
        sizes = np.diff([t for t, _, _ in record.evaluations])
        step = (
            f"step {sizes[0]:.17g} s"
            if np.allclose(sizes, sizes[0], rtol=TIME_TOLERANCE, atol=0)
            else f"steps {sizes.min():.17g} to {sizes.max():.17g} s"
        )
        return [
            f"Model Exchange master: explicit Euler at {step}, one derivative evaluation per "
            f"step ({summary}); its error grows with the step, unlike the co-simulation FMU's "
            "own integrator"
        ]
    return [
        f"Model Exchange master: not explicit Euler: {summary}, time points {points.min():.3g} "
        f"to {points.max():.3g} s apart (a multi-stage or variable-step integrator)"
    ]


def judge_calls(log: str | Path, intended: IntendedRun | None, variable_names: dict[int, str]) -> dict:
    """Read a log and judge each instance in it.

    Parameters
    ----------
    log : str or Path
    intended : IntendedRun or None
        None: the timeline only.
    variable_names : dict
        {value reference: name}, for a master's own call log.

    Returns
    -------
    dict
        {instance: {"steps": [...], "set_before_start": {...}, "events": [...],
        "differences": [...] or None, "intended_torque": the torque each step of the intended
        run holds at its start, or None, "regression_tools": csv-compare's tube and the FMI
        cross-check's band on the run the steps made against the intended one
        (regression_tools.regression_verdicts), or None}}.

    Raises
    ------
    MissingFile, InvalidInput
        As read_calls.

    Examples
    --------
    >>> judge_calls("run.log", IntendedRun(torque=20.0), {0: "torque"})  # doctest: +SKIP
    """
    instances = reconstruct(read_calls(log, variable_names))
    return {
        name: {
            **asdict(record),
            "timeline": timeline(record),
            "differences": None if intended is None else differences(record, intended),
            "intended_torque": None
            if intended is None or not record.steps
            else _plan(record, intended).torque.tolist(),
            "regression_tools": None if intended is None else _run_as_done(record, intended),
        }
        for name, record in instances.items()
    }


def format_calls(judged: dict, steps_shown: int = 20) -> str:
    """The report a user reads: per instance, the differences (or the timeline).

    Parameters
    ----------
    judged : dict
        As judge_calls returns it.
    steps_shown : int
        Steps of the timeline printed when there is no intended run.

    Returns
    -------
    str
    """
    lines = []
    for name, result in judged.items():
        found = result["differences"]
        if found is None:
            shown = result["timeline"]
            step_lines = [line for line in shown if line.startswith("  step ")]
            if len(step_lines) > steps_shown:
                hidden = set(step_lines[steps_shown:])
                shown = [line for line in shown if line not in hidden] + [
                    f"  ... {len(step_lines) - steps_shown} more steps (--json has them all)"
                ]
            lines.extend(shown)
        elif found:
            lines.append(f"instance {name}: {len(found)} difference{'s' * (len(found) > 1)} from the intended run")
            lines.extend(f"  {line}" for line in found)
        else:
            lines.append(f"instance {name}: the master did what the intended run asks ({len(result['steps'])} steps)")
        if result.get("regression_tools"):
            lines.append(
                "  what regression tools would say, on theta of the run these steps make against the intended one:"
            )
            lines.extend(f"    {line}" for line in format_verdicts(result["regression_tools"]))
    return "\n".join(lines)


def write_calls_json(judged: dict, path: str | Path) -> Path:
    """Write judge_calls's result as JSON, through a temporary file renamed into place.

    Parameters
    ----------
    judged : dict
    path : str or Path

    Returns
    -------
    Path
    """
    with replacing(path) as file:
        json.dump(judged, file, indent=1)
    return Path(path)
