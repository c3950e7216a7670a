"""Read what a master did to the FMU from its calls: the call record, or a master's call log.

LOG is any text holding calls, one per line, in any of these forms (other lines are ignored):

- the FMU's own call record (category logCalls, on when the master turns logging on), found by
  its marker anywhere in a line, so inside any master's log format::

      [OK] [pendulum-calls] instance="Pendulum" fmi2SetReal(torque=20) time=0->0 status=OK

- fmpy's call logger (``fmpy simulate --fmi-logging``, ``simulate_fmu(fmi_call_logger=print)``)
  and fmusim's (``--log-fmi-calls``), which need no option of the FMU::

      fmi2SetReal(c=0x55d0, vr=[0], nvr=1, value=[20.0]) -> OK
      fmi2SetReal(vr={0}, nvr=1, value={20}) -> OK

When a log holds the FMU's record, only the record is read (a master's own call log beside it
says the same). What the reading gives, per instance (reconstruct): each communication step's
start, size, the torque in force over it and its input derivatives, parameters and start values
set, FMU states saved, restored and serialized, resets, and a Model Exchange master's time
points. _call_judge.py compares that with the intended run.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from .._errors import InvalidInput, MissingFile
from .._received_files import bounded_lines

MARKER = "[pendulum-calls]"


INPUT = "torque"


# Two doubles a master computed in different ways (t += h against t = t0 + k*h) agree to this.
TIME_TOLERANCE = 1e-9


# The FMU escapes every string a master gave it (instance="...", file="...") as C does, \xHH for
# each byte outside printable ASCII and for '%', so that no line of a record starts with anything
# but the marker (fmu_src/src/record_file.c): a quoted field is a run of anything but a quote or
# a backslash, and of escapes.
_QUOTED = r'"(?:[^"\\]|\\.)*"'


_RECORD = re.compile(
    rf"\[pendulum-calls\] instance=(?P<instance>{_QUOTED}) (?P<function>fmi[23]\w+)"
    r"\((?P<arguments>.*)\) time=(?P<before>\S+)->(?P<after>\S+) status=(?P<status>\w+)"
)


_ESCAPE = re.compile(rb"\\(x[0-9a-fA-F]{2}|.)", re.DOTALL)


_ESCAPED_CHARACTERS = {b"n": b"\n", b"r": b"\r", b"t": b"\t"}


def unescape(quoted: str) -> str:
    r"""The string a master gave the FMU, from its escaped, quoted form in a record line.

    Parameters
    ----------
    quoted : str
        A quoted field of a record line, quotes included: ``"x\n\x25s"``.

    Returns
    -------
    str
        The string itself, its bytes read as UTF-8 (a byte that is not becomes U+FFFD).

    Examples
    --------
    >>> unescape(r'"pend\"ulum\n\xc3\xa9"')
    'pend"ulum\né'
    """

    def byte(match: re.Match) -> bytes:
        code = match[1]
        return bytes([int(code[1:], 16)]) if code[:1] == b"x" else _ESCAPED_CHARACTERS.get(code, code)

    return _ESCAPE.sub(byte, quoted[1:-1].encode("ascii", "backslashreplace")).decode("utf-8", "replace")


def printable(text: str) -> str:
    r"""Text as a terminal may show it: as it is when every character is printable, else with
    Python's escapes, so that a name from a record cannot start a line or steer a terminal.

    Examples
    --------
    >>> printable("x\ncurl")
    "'x\\ncurl'"
    """
    return text if text.isprintable() else repr(text)


# A master's logged call is FUNCTION(ARGUMENTS), then `-> RESULT` or nothing, at the end of its
# line: found by _master_call_parts, in one pass over the line.
_WORD = re.compile(r"\w+")
_FUNCTION = re.compile(r"fmi[23][A-Z]\w")
# The line's end read backwards, shortest first: the closing parenthesis of the arguments, or the
# result after it ("KO >- )" backwards).
_CALL_END_REVERSED = re.compile(r"\s*(?:(?P<result>\S+?)\s*>-\s*)??\)")


# One argument of a master's call log: name=value, the value a list ([...] or {...}), a quoted
# string or one token. The name starts a word (no value ends inside one): else each position of a
# long word would be tried, taking time in the square of its length.
_ARGUMENT = re.compile(r'(?<!\w)(\w+)=(\[[^\]]*\]|\{[^}]*\}|"[^"]*"|[^,]*)')


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
            arguments[name] = unescape(value) if value.startswith('"') else value
    return Call(
        unescape(match["instance"]),
        match["function"],
        values,
        arguments,
        float(match["before"]),
        float(match["after"]),
        match["status"],
    )


def _split_arguments(text: str) -> list[str]:
    """Split at ', ' outside parentheses (der(torque,1)=5 holds a comma) and quoted strings."""
    parts, depth, start = [], 0, 0
    for piece in re.finditer(rf"{_QUOTED}|[(),]", text):
        character = piece[0]
        if character == "(":
            depth += 1
        elif character == ")":
            depth -= 1
        elif character == "," and depth == 0:
            parts.append(text[start : piece.start()])
            start = piece.end()
    parts.append(text[start:])
    return parts


def _list(text: str) -> list[str]:
    return [item.strip() for item in text.strip("[]{}").split(",") if item.strip()]


def _master_call_parts(line: str) -> dict[str, str | None] | None:
    r"""The function, arguments and result (None without `->`) of the call a line of a master's
    log ends in, or None where it ends in none.

    The same as re.search(r"(fmi[23][A-Z]\w+)\((.*)\)(?:\s*->\s*(\S+))?\s*$", line) finds,
    in time linear in the line's length: a backtracking search takes the square of it, an hour on
    a crafted line of a few hundred kB. The first function name followed by `(` is the only start
    to try (the end found from a later one is one found from it), and the rightmost `)` that the
    end follows is found reading the line backwards.
    """
    for word in _WORD.finditer(line):
        name = _FUNCTION.search(word[0]) if line.startswith("(", word.end()) else None
        if name:
            break
    else:
        return None
    after = line[word.end() + 1 :]
    end = _CALL_END_REVERSED.match(after[::-1])
    if end is None:
        return None
    result = end["result"]
    return {
        "function": word[0][name.start() :],
        "arguments": after[: len(after) - end.end()],
        "result": None if result is None else result[::-1],
    }


def _master_call(match: dict, names: dict[int, str], handles: dict[str, str]) -> Call:
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
    records, parts = [], []
    with open(path, encoding="utf-8", errors="replace") as file:
        advice = "give the FMU's call record, or the master's log as it wrote it"
        for line in map(str.rstrip, bounded_lines(file, str(path), InvalidInput, advice)):
            # A record starts at its line's first marker (a master's log puts its own prefix
            # before it): tried from every marker, a crafted line took time in its length squared.
            start = line.find(MARKER)
            if start >= 0 and (match := _RECORD.match(line, start)):
                records.append(match)
            elif not records and (found := _master_call_parts(line)):
                parts.append(found)
    if records:
        variables = frozenset(variable_names.values())
        return [_record_call(match, variables) for match in records]
    handles: dict[str, str] = {}
    calls = [_master_call(found, variable_names, handles) for found in parts]
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
    lines = [f"instance {printable(record.instance)} ({record.interface})"]
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
