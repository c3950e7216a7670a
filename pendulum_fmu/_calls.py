"""Read what a master did to the FMU from its calls, and name where it differs from the intended run.

    pendulum-fmu judge --calls LOG [--torque N | --torque-file F.csv] [--ramp] [--set NAME=VALUE ...]

LOG is any text holding calls, one per line, in any of these forms (other lines are ignored):

- the FMU's own call record (category logCalls, on when the master turns logging on), found by
  its marker anywhere in a line, so inside any master's log format::

      [OK] [pendulum-calls] instance="Pendulum" fmi2SetReal(torque=20) time=0->0 status=OK

- fmpy's call logger (``fmpy simulate --fmi-logging``, ``simulate_fmu(fmi_call_logger=print)``)
  and fmusim's (``--log-fmi-calls``), which need no option of the FMU::

      fmi2SetReal(c=0x55d0, vr=[0], nvr=1, value=[20.0]) -> OK
      fmi2SetReal(vr={0}, nvr=1, value={20}) -> OK

When a log holds the FMU's record, only the record is read (a master's own call log beside it
says the same). What the reading gives, per instance: each communication step's start, size,
the torque in force over it and its input derivatives, parameters and start values set, FMU
states saved, restored and serialized, resets, and a Model Exchange master's time points.
Given the intended run (the simulate options) it names each difference exactly, step by step.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import asdict, dataclass, field
from itertools import pairwise
from pathlib import Path

import numpy as np

from ._atomic_files import replacing
from ._errors import InvalidInput, MissingFile
from ._parameters import default_parameters
from ._reference import reference_schedule
from ._regression_tools import format_verdicts, regression_verdicts
from ._torque_schedule import TorqueSchedule, TorqueSignal, schedule

MARKER = "[pendulum-calls]"
INPUT = "torque"
# Start values the simulate options name theta0 and omega0.
START_VALUES = {"theta0": "theta", "omega0": "omega"}
# Calls a master makes before the first step, in which a parameter or start value is set.
BEFORE_INITIALIZATION_ENDS = ("Instantiate", "SetupExperiment", "EnterInitializationMode")
# Two doubles a master computed in different ways (t += h against t = t0 + k*h) agree to this.
TIME_TOLERANCE = 1e-9
# A value a master passed agrees with the intended one to this (relative): both are doubles
# printed at round-trip precision, or at fmpy's repr, so only the master's arithmetic differs.
VALUE_TOLERANCE = 1e-12
# How many steps late or early the reading looks for.
MAX_SHIFT = 10

_RECORD = re.compile(
    r'\[pendulum-calls\] instance="(?P<instance>[^"]*)" (?P<function>fmi[23]\w+)'
    r"\((?P<arguments>.*)\) time=(?P<before>\S+)->(?P<after>\S+) status=(?P<status>\w+)"
)
_MASTER = re.compile(r"(?P<function>fmi[23][A-Z]\w+)\((?P<arguments>.*)\)(?:\s*->\s*(?P<result>\S+))?\s*$")
# One argument of a master's call log: name=value, the value a list ([...] or {...}), a quoted
# string or one token.
_ARGUMENT = re.compile(r'(\w+)=(\[[^\]]*\]|\{[^}]*\}|"[^"]*"|[^,]*)')


@dataclass
class Call:
    """One call a master made, as the log tells it.

    Parameters
    ----------
    instance : str
        The instance's name (the FMU's record), or the master's handle for it (fmpy's ``c=``).
    function : str
        The FMI function, e.g. ``fmi2DoStep``.
    values : dict
        Variables set or read, by name (input derivatives as ``der(torque,1)``).
    arguments : dict
        The other arguments, as text.
    time_before, time_after : float or None
        The FMU's time around the call (the record only).
    status : str
        What the call returned.
    """

    instance: str
    function: str
    values: dict = field(default_factory=dict)
    arguments: dict = field(default_factory=dict)
    time_before: float | None = None
    time_after: float | None = None
    status: str = "OK"

    @property
    def name(self) -> str:
        """The function without its standard's prefix: ``DoStep``."""
        return self.function[4:]


@dataclass
class Step:
    """One communication step as the FMU received it.

    Parameters
    ----------
    index : int
        0 for the first step.
    time, size : float
        currentCommunicationPoint and communicationStepSize.
    torque, torque_rate, torque_acceleration : float
        The input at the step's start and its first and second derivatives in force.
    status : str
        What fmi*DoStep returned.
    """

    index: int
    time: float
    size: float
    torque: float
    torque_rate: float
    torque_acceleration: float
    status: str


@dataclass
class InstanceCalls:
    """What a master did to one instance.

    Parameters
    ----------
    instance : str
        Its name or handle.
    interface : str
        CoSimulation, ModelExchange, or '' when the log does not say.
    steps : list of Step
    set_before_start : dict
        Variables set before initialization ended, by name (the last value set).
    events : list of str
        The timeline's lines other than steps: states saved, restored, serialized, resets,
        refused calls.
    restores : list of tuple
        (call number, time before, time after) of each FMU state set (times None in a master's
        call log, which does not show them).
    rewinds : list of tuple
        (call number, time the FMU had reached, time the next step starts) of each step that
        starts before the previous one ended: the steps from there on are redone, and only the
        redone ones are kept in steps.
    model_exchange_times : list of float
        The times a Model Exchange master set.
    evaluations : list of tuple
        (time, states, derivatives) of each fmi2GetDerivatives in the record, the states those
        a Model Exchange master last set.
    """

    instance: str
    interface: str = ""
    steps: list = field(default_factory=list)
    set_before_start: dict = field(default_factory=dict)
    events: list = field(default_factory=list)
    restores: list = field(default_factory=list)
    rewinds: list = field(default_factory=list)
    model_exchange_times: list = field(default_factory=list)
    evaluations: list = field(default_factory=list)


def _number(text: str) -> float:
    return float(text.strip().strip('"'))


def _record_call(match: re.Match, variables: frozenset) -> Call:
    values, arguments = {}, {}
    for part in filter(None, (piece.strip() for piece in _split_arguments(match["arguments"]))):
        name, _, value = part.partition("=")
        if name in variables or name.startswith(("der(", "x[")):
            values[name] = float(value)
        else:
            arguments[name] = value
    return Call(
        match["instance"],
        match["function"],
        values,
        arguments,
        float(match["before"]),
        float(match["after"]),
        match["status"],
    )


def _split_arguments(text: str) -> list[str]:
    """Split at ', ' outside parentheses (der(torque,1)=5 holds a comma)."""
    parts, depth, start = [], 0, 0
    for position, character in enumerate(text):
        if character == "(":
            depth += 1
        elif character == ")":
            depth -= 1
        elif character == "," and depth == 0:
            parts.append(text[start:position])
            start = position + 1
    parts.append(text[start:])
    return parts


def _list(text: str) -> list[str]:
    return [item.strip() for item in text.strip("[]{}").split(",") if item.strip()]


def _master_call(match: re.Match, names: dict[int, str], handles: dict[str, str]) -> Call:
    arguments = {name: value.strip() for name, value in _ARGUMENT.findall(match["arguments"])}
    function = match["function"]
    if "Instantiate" in function:
        handle = match["result"] or ""
        instance = arguments.get("instanceName", "").strip('"') or handle or "instance"
        handles[handle] = instance
    else:
        instance = handles.get(arguments.get("c", arguments.get("instance", "")), "")
        instance = instance or next(iter(handles.values()), "instance")
    values = {}
    references = arguments.pop("vr", arguments.pop("valueReferences", None))
    numbers = arguments.pop("value", arguments.pop("values", None))
    if "String" in function:  # callRecordFile: a file name, kept as the call's argument
        arguments["file"] = numbers or ""
    elif references is not None and numbers is not None:
        orders = _list(arguments.pop("order", "")) or None
        for position, (reference, value) in enumerate(zip(_list(references), _list(numbers), strict=False)):
            name = names.get(int(reference), f"vr{reference}")
            if orders:
                name = f"der({name},{orders[position]})"
            values[name] = float(value)
    status = match["result"] or "OK"
    return Call(instance, function, values, arguments, status=status if status.isalpha() else "OK")


def read_calls(path: str | Path, variable_names: dict[int, str]) -> list[Call]:
    """Every call a log holds, in order.

    Parameters
    ----------
    path : str or Path
        The FMU's record file, or a master's whole output with the calls inside it.
    variable_names : dict
        {value reference: name} of the FMU, to name the variables of a master's call log.

    Returns
    -------
    list of Call

    Raises
    ------
    MissingFile
        When there is no such file.
    InvalidInput
        When the file holds no call.

    Examples
    --------
    >>> calls = read_calls("run.log", {0: "torque"})  # doctest: +SKIP
    """
    path = Path(path)
    if not path.is_file():
        raise MissingFile(f"{path}: no such file (give the FMU's call record, or the master's log)")
    lines = path.read_text(encoding="utf-8", errors="replace").splitlines()
    records = [match for line in lines if MARKER in line and (match := _RECORD.search(line))]
    if records:
        variables = frozenset(variable_names.values())
        return [_record_call(match, variables) for match in records]
    handles: dict[str, str] = {}
    calls = [_master_call(match, variable_names, handles) for line in lines if (match := _MASTER.search(line))]
    if not calls:
        raise InvalidInput(
            f"{path}: no FMI call in it; turn on the FMU's call record (loggingOn, "
            "docs/calls.md) or the master's call logging (fmpy --fmi-logging, "
            "fmusim --log-fmi-calls)"
        )
    return calls


def reconstruct(calls: list[Call]) -> dict[str, InstanceCalls]:
    """What the master did to each instance, from its calls.

    Parameters
    ----------
    calls : list of Call
        As read_calls returns them.

    Returns
    -------
    dict
        {instance: InstanceCalls}, in the order the instances first appear.

    Examples
    --------
    >>> reconstruct([Call("p", "fmi2DoStep", arguments={"currentCommunicationPoint": "0",
    ...     "communicationStepSize": "0.1"})])["p"].steps[0].size
    0.1
    """
    instances: dict[str, InstanceCalls] = {}
    state: dict[str, dict] = {}
    for number, call in enumerate(calls, start=1):
        record = instances.setdefault(call.instance, InstanceCalls(call.instance))
        now = state.setdefault(
            call.instance, {"torque": 0.0, "rate": 0.0, "acceleration": 0.0, "initialized": False, "time": 0.0}
        )
        name = call.name
        if call.status not in ("OK", "Warning") and name != "DoStep":
            record.events.append(f"call {number}: {call.function} returned {call.status}")
            continue
        if name.startswith("Instantiate"):
            record.interface = call.arguments.get("interface", "")
            if not record.interface and "fmuType" in call.arguments:
                record.interface = "CoSimulation" if call.arguments["fmuType"] == "1" else "ModelExchange"
        elif name in ("SetReal", "SetFloat64"):
            for variable, value in call.values.items():
                if not now["initialized"]:
                    record.set_before_start[variable] = value
                if variable == INPUT:
                    now["torque"] = value
        elif name == "SetRealInputDerivatives":
            for variable, value in call.values.items():
                if variable == f"der({INPUT},1)":
                    now["rate"] = value
                elif variable == f"der({INPUT},2)":
                    now["acceleration"] = value
        elif name == "ExitInitializationMode":
            now["initialized"] = True
        elif name == "DoStep":
            time = _number(call.arguments["currentCommunicationPoint"])
            size = _number(call.arguments["communicationStepSize"])
            if record.steps:
                reached = record.steps[-1].time + record.steps[-1].size
                if time < reached - TIME_TOLERANCE * max(1.0, abs(reached)):
                    record.rewinds.append((number, reached, time))
                    record.events.append(
                        f"call {number}: step from t = {time} after the FMU had "
                        f"reached t = {reached}: the steps from there are redone"
                    )
                    record.steps = [
                        step for step in record.steps if step.time < time - TIME_TOLERANCE * max(1.0, abs(time))
                    ]
            record.steps.append(
                Step(len(record.steps), time, size, now["torque"], now["rate"], now["acceleration"], call.status)
            )
            if call.status == "OK" and (now["rate"] or now["acceleration"]):
                # The FMU moves a ramped input along its polynomial to the step's end.
                now["torque"] += size * (now["rate"] + 0.5 * size * now["acceleration"])
                now["rate"] += size * now["acceleration"]
        elif name == "Reset":
            now.update(torque=0.0, rate=0.0, acceleration=0.0, initialized=False)
            record.events.append(f"call {number}: reset at t = {call.time_before}")
        elif name in ("SetFMUstate", "SetFMUState"):
            record.restores.append((number, call.time_before, call.time_after))
            record.events.append(f"call {number}: FMU state restored: t = {call.time_before} -> {call.time_after}")
        elif name in (
            "GetFMUstate",
            "GetFMUState",
            "SerializeFMUstate",
            "SerializeFMUState",
            "DeSerializeFMUstate",
            "DeSerializeFMUState",
        ):
            record.events.append(f"call {number}: {call.function} at t = {call.time_before}")
        elif name == "SetTime":
            record.model_exchange_times.append(_number(call.arguments["time"]))
        elif name == "SetContinuousStates":
            now["states"] = list(call.values.values())
        elif (
            name in ("GetDerivatives", "GetContinuousStateDerivatives")
            and "states" in now
            and call.time_before is not None
        ):
            record.evaluations.append((call.time_before, now["states"], list(call.values.values())))
    return instances


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
    for number, before, after in record.restores:
        if before is not None and after is not None and not math.isclose(before, after, abs_tol=TIME_TOLERANCE):
            found.append(f"call {number}: an FMU state restored to t = {after:.17g} at t = {before:.17g}")
    if not any(before is not None for _, before, _ in record.restores):
        found.extend(
            f"call {number}: the master went back from t = {reached:.17g} to t = "
            f"{time:.17g} (an FMU state restored to another time)"
            for number, reached, time in record.rewinds
        )
    steps = record.steps
    if record.interface == "ModelExchange" or (not steps and record.model_exchange_times):
        found.extend(_model_exchange(record))
        return found
    if not steps:
        return [*found, "no communication step taken"]
    sizes = np.array([step.size for step in steps])
    times = np.array([step.time for step in steps])
    size = float(sizes[0])
    if not np.allclose(sizes, size, rtol=TIME_TOLERANCE, atol=0):
        k = int(np.flatnonzero(~np.isclose(sizes, size, rtol=TIME_TOLERANCE, atol=0))[0])
        found.append(
            f"variable step sizes: {sizes.min():.17g} to {sizes.max():.17g} s (step {k} "
            f"at t = {times[k]:.17g} is {sizes[k]:.17g} s, step 0 {size:.17g} s)"
        )
        return found
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
    applied = np.array([step.torque for step in steps[:n]])
    rate = np.array([step.torque_rate for step in steps[:n]])
    first = _first_mismatch(applied, plan.torque[:n])
    if first is not None:
        shift = _shift(applied, plan.torque[:n], first)
        at = f"from step {first} (t = {times[first]:.17g})"
        if shift is not None and shift > 0:
            found.append(
                f"input applied {shift} step{'s' * (shift > 1)} late {at}: step n holds the torque "
                f"meant for step n-{shift} (set after the step it was meant for)"
            )
        elif shift is not None:
            found.append(
                f"input applied {-shift} step{'s' * (shift < -1)} early {at}: step n holds the torque "
                f"meant for step n+{-shift}"
            )
        else:
            found.append(
                f"torque differs {at}: {applied[first]:.17g} N.m applied, {plan.torque[first]:.17g} N.m intended"
            )
    ramps, should_ramp = rate != 0, plan.torque_rate[:n] != 0
    if (ramps & ~should_ramp).any():
        k = int(np.flatnonzero(ramps & ~should_ramp)[0])
        found.append(
            f"ramped where it should hold from step {k} (t = {times[k]:.17g}): der(torque) = {rate[k]:.17g} N.m/s"
        )
    if (~ramps & should_ramp).any():
        k = int(np.flatnonzero(~ramps & should_ramp)[0])
        found.append(
            f"held where it should ramp from step {k} (t = {times[k]:.17g}): intended "
            f"der(torque) = {plan.torque_rate[k]:.17g} N.m/s"
        )
    elif (ramps & should_ramp).any():
        wrong = np.flatnonzero(ramps & should_ramp & ~np.isclose(rate, plan.torque_rate[:n], rtol=1e-9))
        if len(wrong):
            k = int(wrong[0])
            found.append(
                f"ramp rate differs from step {k} (t = {times[k]:.17g}): {rate[k]:.17g} "
                f"N.m/s applied, {plan.torque_rate[k]:.17g} intended"
            )
    if len(steps) != len(plan.torque):
        found.append(f"{len(steps)} steps taken, {len(plan.torque)} intended")
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


def timeline(record: InstanceCalls) -> list[str]:
    """The lines a user reads: what was set before the start, each step, and each event.

    Parameters
    ----------
    record : InstanceCalls

    Returns
    -------
    list of str

    Examples
    --------
    >>> timeline(InstanceCalls("p"))
    ['instance p ()', '  0 steps']
    """
    lines = [f"instance {record.instance} ({record.interface})"]
    if record.set_before_start:
        lines.append(
            "  set before initialization ended: "
            + ", ".join(f"{name}={value:.17g}" for name, value in record.set_before_start.items())
        )
    lines.append(f"  {len(record.steps)} steps")
    for step in record.steps:
        ramp = (f", der(torque)={step.torque_rate:.17g}" if step.torque_rate else "") + (
            f", der(torque,2)={step.torque_acceleration:.17g}" if step.torque_acceleration else ""
        )
        lines.append(
            f"  step {step.index}: t={step.time:.17g} h={step.size:.17g} torque={step.torque:.17g}{ramp} {step.status}"
        )
    lines.extend(f"  {event}" for event in record.events)
    return lines


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
