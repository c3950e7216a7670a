"""Which coupling a master used on ClosedLoop.ssp, and what else it got wrong.

A master's result (time and the pendulum's theta) is held against the closed loop's reference of
every coupling (closed_loop.COUPLINGS), with the SSP's parameter sets applied and without them (the
FMUs' own defaults), and with its rows labelled by the communication point they were reached at or
by the start of the step that reached them (fmpy.ssp). The closest names the coupling; the result's
step and its last time are held against the SSP's fixed step and the DefaultExperiment's stop time.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

import numpy as np

from ..judging._result_file import ResultFileError, read_result
from ._closed_loop import COUPLINGS, sampled_loop_reference
from ._ssp import SspSettings, read_ssp

# The masters here match their coupling's reference to 1e-15 rad; the couplings differ from one
# another by 1e-4 rad and more at the tutorial's setpoints (5.5e-4 between Gauss-Seidel and Jacobi
# at 0.3 rad). 1e-9 leaves room for a result written with 10 significant digits.
MATCH_TOLERANCE = 1e-9


@dataclass(frozen=True)
class SspVerdict:
    """What the judge found in one master's result of the closed loop.

    Attributes
    ----------
    coupling : str
        The key of COUPLINGS whose reference is closest.
    parameter_set_applied : bool
        Whether the closest reference is the one with the SSP's parameter sets (False: the FMUs'
        own defaults).
    labelled_at_step_start : bool
        Whether each row holds the value at the end of the step that starts at its time.
    max_error : float
        Largest difference in theta (rad) from that reference.
    step_size, end_time : float
        The result's step and the time its last value belongs to, in s.
    problems : list of str
        Everything the result does other than what the SSP asks, one sentence each.
    """

    coupling: str
    parameter_set_applied: bool
    labelled_at_step_start: bool
    max_error: float
    step_size: float
    end_time: float
    problems: list = field(default_factory=list)

    @property
    def passed(self) -> bool:
        """Whether the result is right for its coupling and honours the SSP."""
        return not self.problems


@lru_cache(maxsize=32)
def reference_run(stop_time: float, step_size: float, coupling: str, controller: tuple, pendulum: tuple) -> np.ndarray:
    """sampled_loop_reference, kept for the next judgement; parameters as sorted (name, value) pairs."""
    return sampled_loop_reference(
        stop_time, step_size, controller=dict(controller), parameters=dict(pendulum), coupling=coupling
    )


def judge_coupling(time, theta, settings: SspSettings, *, tolerance: float = MATCH_TOLERANCE) -> SspVerdict:
    """Name the coupling a master used from its theta, and check step, stop time and parameters.

    Parameters
    ----------
    time, theta : array_like
        The result's times (s) and the pendulum's angle (rad), one value per communication step.
    settings : SspSettings
        What the SSP asks (read_ssp).
    tolerance : float, optional
        Largest difference from the coupling's reference (rad) that counts as matching it.

    Returns
    -------
    SspVerdict

    Raises
    ------
    ResultFileError
        Fewer than two rows, or times that are not one fixed step apart.

    Examples
    --------
    >>> verdict = judge_coupling(time, theta, read_ssp("ClosedLoop.ssp"))  # doctest: +SKIP
    >>> verdict.coupling  # doctest: +SKIP
    'jacobi'
    """
    time, theta = np.asarray(time, dtype=float), np.asarray(theta, dtype=float)
    if len(time) < 2:
        raise ResultFileError("the result has fewer than two rows: a fixed-step result needs one per step")
    step_size = float(np.median(np.diff(time)))
    index = np.rint(time / step_size).astype(int)
    if np.max(np.abs(time - index * step_size)) > 1e-6 * step_size:
        raise ResultFileError(
            f"the result's times are not multiples of one step ({step_size:.9g} s): "
            "give the rows of a fixed-step run, one per communication point"
        )
    steps = int(index[-1]) + 1  # one more than the last row: a row may hold the end of its step
    sets = {
        True: (tuple(sorted(settings.controller.items())), tuple(sorted(settings.pendulum.items()))),
        False: ((), ()),
    }
    scores = {}
    for coupling in COUPLINGS:
        for applied, (controller, pendulum) in sets.items():
            reference = reference_run(steps * step_size, step_size, coupling, controller, pendulum)["theta"]
            for shift in (0, 1):
                scores[coupling, applied, shift] = float(np.max(np.abs(theta - reference[index + shift])))
    (coupling, applied, shift), error = min(scores.items(), key=lambda item: item[1])
    end_time = float(time[-1] + shift * step_size)
    problems = []
    if error > tolerance:
        problems.append(f"matches no coupling: nearest {coupling}, {error:.3g} rad off its reference")
    if not applied:
        problems.append("the SSP's parameter sets were not applied: the FMUs ran on their own defaults")
    if abs(step_size - settings.step_size) > 1e-9 * settings.step_size:
        problems.append(f"step {step_size:.9g} s where the SSP asks {settings.step_size:.9g} s")
    if abs(end_time - settings.stop_time) > 0.5 * step_size:
        problems.append(f"ran to {end_time:.9g} s where the DefaultExperiment stops at {settings.stop_time:.9g} s")
    if shift:
        problems.append(
            "each row holds the value at the end of the step that starts at its time (labelled one step early)"
        )
    return SspVerdict(coupling, applied, bool(shift), error, step_size, end_time, problems)


def judge_ssp_result(
    result: str | os.PathLike,
    ssp: str | os.PathLike,
    *,
    mapping: str | dict | None = None,
    tolerance: float = MATCH_TOLERANCE,
) -> SspVerdict:
    """judge_coupling on a result CSV against the SSP it ran.

    Parameters
    ----------
    result : str or PathLike
        A CSV with time and theta columns (judge.read_result).
    ssp : str or PathLike
        The ClosedLoop.ssp the master ran.
    mapping : str or dict, optional
        The result's column names and unit factors, as --map: "time=t,theta=pendulum.theta".
    tolerance : float, optional
        As judge_coupling.

    Returns
    -------
    SspVerdict

    Raises
    ------
    ResultFileError, SspFileError, MissingFile
        A result or an SSP that cannot be read.

    Examples
    --------
    >>> judge_ssp_result("out.csv", "ClosedLoop.ssp", mapping="theta=pendulum.theta")  # doctest: +SKIP
    """
    rows = read_result(Path(result), mapping)
    return judge_coupling(rows["time"], rows["theta"], read_ssp(ssp), tolerance=tolerance)


def format_ssp_verdict(verdict: SspVerdict) -> str:
    """The verdict as lines for a terminal.

    Parameters
    ----------
    verdict : SspVerdict

    Returns
    -------
    str

    Examples
    --------
    >>> print(format_ssp_verdict(verdict))  # doctest: +SKIP
    coupling: jacobi ...
    """
    lines = [
        f"coupling: {verdict.coupling} ({COUPLINGS[verdict.coupling]})",
        f"parameter set applied: {'yes' if verdict.parameter_set_applied else 'no'}",
        f"step {verdict.step_size:.9g} s, last value at {verdict.end_time:.9g} s, "
        f"{verdict.max_error:.3g} rad from the coupling's reference",
        *(f"problem: {problem}" for problem in verdict.problems),
        "PASS: right for its coupling and the SSP" if verdict.passed else "FAIL",
    ]
    return "\n".join(lines)
