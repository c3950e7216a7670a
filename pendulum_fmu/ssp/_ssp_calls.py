"""Which coupling a master used on ClosedLoop.ssp, read from the pendulum's own record of its calls.

    pendulum-fmu judge --calls LOG --ssp ClosedLoop.ssp

LOG is the pendulum's call record (its callRecordFile, export-ssp --call-record) or any master's
log holding it (docs/calls.md). The record shows what reached the pendulum: the parameters set
before initialization ended, and each step's time, size and the torque held over it. The torques
are the controller's, so they carry what the record cannot show directly: each is held against
the closed loop's reference of every coupling (_closed_loop.COUPLINGS), run with the pendulum's
parameters as the record shows them and with the SSP's controller set, or with any of the set's
values the controller's own default instead (a value that did not arrive). The candidate most
of whose torques agree names the coupling and the controller parameters that arrived; each step
whose torque it does not give is named, a step late or early where the coupling's torque of the
neighbouring step is what it holds.
"""

from __future__ import annotations

import itertools
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._errors import InvalidInput
from ..fmu._parameters import default_parameters, variables
from ..judging._call_record import Call, InstanceCalls, printable, read_calls, reconstruct
from ._closed_loop import COUPLINGS, controller_defaults
from ._ssp import SspSettings, read_ssp
from ._ssp_judge import reference_run

# A torque the master passed agrees with the coupling's reference to this, relative to
# max(1 N.m, |torque|): the record holds doubles at round-trip precision, the reference is integrated
# at 1e-12 per step, and the couplings' torques differ by 1e-4 N.m and more from the first steps.
TORQUE_TOLERANCE = 1e-8
# Step sizes and times a master computed in its own arithmetic (libcosim counts nanoseconds)
# agree with the SSP's to this, relative to the step.
TIME_TOLERANCE = 1e-6


@dataclass(frozen=True)
class SspCallsVerdict:
    """What the judge found in the pendulum's record of one master's closed-loop run.

    Attributes
    ----------
    instance : str
        The pendulum's instance in the record.
    coupling : str
        The key of COUPLINGS whose torques most steps hold.
    controller_missing : tuple of str
        The SSP's controller parameters the torques show did not arrive (the controller ran on
        its own default for each); only those whose value in the set differs from the default
        can show.
    pendulum_set : dict
        The pendulum's parameters the record shows set before initialization ended.
    steps : int
        Communication steps taken.
    step_size, end_time : float
        The first step's size and the time the last step reached, in s.
    max_difference : float
        Largest torque difference (N.m) from the coupling's reference over the steps that agree.
    problems : list of str
        Everything the run does other than what the SSP asks, one sentence each.
    """

    instance: str
    coupling: str
    controller_missing: tuple
    pendulum_set: dict
    steps: int
    step_size: float
    end_time: float
    max_difference: float
    problems: list = field(default_factory=list)

    @property
    def passed(self) -> bool:
        """Whether every torque is right for its coupling and the run honours the SSP."""
        return not self.problems


def _pendulum(calls: list[Call], log: Path) -> InstanceCalls:
    """The one instance the torque was set on and stepped (a log may hold the controller's record too)."""
    torqued = {call.instance for call in calls if call.name in ("SetReal", "SetFloat64") and "torque" in call.values}
    found = [record for name, record in reconstruct(calls).items() if name in torqued and record.steps]
    if len(found) != 1:
        raise InvalidInput(
            f"{log}: {'no instance' if not found else f'{len(found)} instances'} of the pendulum stepped with "
            "a torque set: give the pendulum's record of one closed-loop run (callRecordFile, or the master's "
            "log with logging on)"
        )
    return found[0]


def _agreeing(applied: np.ndarray, reference: np.ndarray) -> np.ndarray:
    return np.abs(applied - reference) <= TORQUE_TOLERANCE * np.maximum(1.0, np.abs(reference))


def _torque_problems(applied: np.ndarray, reference: np.ndarray, times: np.ndarray, coupling: str) -> list[str]:
    """The first step whose torque the coupling does not give, named, and how many more there are."""
    wrong = np.flatnonzero(~_agreeing(applied, reference))
    if not len(wrong):
        return []
    k = int(wrong[0])
    at = f"step {k} (t = {times[k]:.17g}) holds {applied[k]:.17g} N.m"
    if k > 0 and _agreeing(applied[k : k + 1], reference[k - 1 : k])[0]:
        found = f"{at}, the torque {coupling} gives step {k - 1}: set a step late"
    elif k + 1 < len(reference) and _agreeing(applied[k : k + 1], reference[k + 1 : k + 2])[0]:
        found = f"{at}, the torque {coupling} gives step {k + 1}: set a step early"
    else:
        found = f"{at} where {coupling} gives {reference[k]:.17g} N.m"
    more = len(wrong) - 1
    return [found + (f"; {more} later step{'s' * (more > 1)} differ too" if more else "")]


def _closest(
    applied: np.ndarray, step_size: float, controller: dict, controller_default: dict, pendulum: tuple
) -> tuple[str, tuple, np.ndarray]:
    """The coupling and the controller parameters missing whose reference torques most steps hold.

    Every coupling, with the SSP's controller set and with each subset of its values that differ
    from the controller's defaults at those defaults; ties go to the smaller median difference.
    Returns the coupling, the missing parameters and that reference's torque per step.
    """
    showing = [name for name, value in controller.items() if value != controller_default.get(name)]
    scores = {}
    for coupling in COUPLINGS:
        for count in range(len(showing) + 1):
            for missing in itertools.combinations(showing, count):
                gains = {**controller, **{name: controller_default[name] for name in missing}}
                reference = reference_run(
                    len(applied) * step_size, step_size, coupling, tuple(sorted(gains.items())), pendulum
                )["torque"][: len(applied)]
                agreeing = int(_agreeing(applied, reference).sum())
                scores[coupling, missing] = (-agreeing, float(np.median(np.abs(applied - reference))), reference)
    (coupling, missing), (_, _, reference) = min(scores.items(), key=lambda item: item[1][:2])
    return coupling, missing, reference


def judge_ssp_calls(log: str | os.PathLike, ssp: str | os.PathLike | SspSettings) -> SspCallsVerdict:
    """Name the coupling, the parameters that arrived and each wrong torque from the pendulum's record.

    Parameters
    ----------
    log : str or PathLike
        The pendulum's call record of one run of the closed loop, or a master's log holding it.
    ssp : str, PathLike or SspSettings
        The ClosedLoop.ssp the master ran (or read_ssp's reading of it).

    Returns
    -------
    SspCallsVerdict

    Raises
    ------
    MissingFile, InvalidInput
        No log, no call in it, or not exactly one pendulum instance stepped with a torque.
    SspFileError
        An SSP that cannot be read.

    Examples
    --------
    >>> verdict = judge_ssp_calls("calls.log", "ClosedLoop.ssp")  # doctest: +SKIP
    >>> verdict.coupling, verdict.controller_missing  # doctest: +SKIP
    ('jacobi', ())
    """
    log = Path(log)
    names = {variable.valueReference: name for name, variable in variables().items()}
    record = _pendulum(read_calls(log, names), log)
    settings = ssp if isinstance(ssp, SspSettings) else read_ssp(ssp)
    steps = record.steps
    times = np.array([step.time for step in steps])
    applied = np.array([step.torque for step in steps])
    step_size = steps[0].size
    end_time = steps[-1].time + steps[-1].size
    defaults = default_parameters()
    pendulum_set = {name: value for name, value in record.set_before_start.items() if name in defaults}
    pendulum_used = tuple(sorted({**defaults, **pendulum_set}.items()))
    controller_default = controller_defaults()
    coupling, missing, reference = _closest(applied, step_size, settings.controller, controller_default, pendulum_used)
    agree = _agreeing(applied, reference)
    problems = _torque_problems(applied, reference, times, coupling)
    problems += [
        f"the controller's {name} did not arrive: the torques are those of its default "
        f"{controller_default[name]!r}, the SSP's set has {settings.controller[name]!r}"
        for name in missing
    ]
    unset = [name for name in settings.pendulum if name not in pendulum_set]
    if unset:
        problems.append(
            f"the pendulum's parameter set did not arrive: the record shows no {', '.join(unset)} set before "
            "initialization ended (the FMU ran on its start values)"
        )
    problems += [
        f"the pendulum's {name} set to {pendulum_set[name]!r}, the SSP's set has {value!r}"
        for name, value in settings.pendulum.items()
        if name in pendulum_set and abs(pendulum_set[name] - value) > 1e-12 * max(1.0, abs(value))
    ]
    sizes = np.array([step.size for step in steps])
    if np.max(np.abs(sizes - settings.step_size)) > TIME_TOLERANCE * settings.step_size:
        problems.append(
            f"steps of {sizes.min():.9g} to {sizes.max():.9g} s where the SSP asks {settings.step_size:.9g} s"
        )
    if abs(end_time - settings.stop_time) > TIME_TOLERANCE * settings.step_size + 1e-12:
        problems.append(f"ran to {end_time:.9g} s where the DefaultExperiment stops at {settings.stop_time:.9g} s")
    max_difference = float(np.max(np.abs(applied - reference)[agree])) if agree.any() else float("nan")
    return SspCallsVerdict(
        record.instance,
        coupling,
        missing,
        pendulum_set,
        len(steps),
        step_size,
        end_time,
        max_difference,
        problems,
    )


def format_ssp_calls_verdict(verdict: SspCallsVerdict) -> str:
    """The verdict as lines for a terminal.

    Parameters
    ----------
    verdict : SspCallsVerdict

    Returns
    -------
    str

    Examples
    --------
    >>> print(format_ssp_calls_verdict(verdict))  # doctest: +SKIP
    instance pendulum: 2000 steps of 0.001 s, to 2 s ...
    """
    arrived = (
        f"no: {', '.join(verdict.controller_missing)} at the controller's default"
        if verdict.controller_missing
        else "yes, as the torques show"
    )
    shown = ", ".join(f"{name}={value!r}" for name, value in verdict.pendulum_set.items()) or "none"
    lines = [
        f"instance {printable(verdict.instance)}: {verdict.steps} steps of {verdict.step_size:.9g} s, "
        f"to {verdict.end_time:.9g} s",
        f"coupling: {verdict.coupling} ({COUPLINGS[verdict.coupling]})",
        f"controller's parameter set arrived: {arrived}",
        f"pendulum's parameters set before initialization ended: {shown}",
        f"torques agreeing with the coupling's reference: largest difference {verdict.max_difference:.3g} N.m",
        *(f"problem: {problem}" for problem in verdict.problems),
        "PASS: every torque right for its coupling, and the SSP honoured" if verdict.passed else "FAIL",
    ]
    return "\n".join(lines)
