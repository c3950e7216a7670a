"""The verdict on one result: the Judgement, the candidates' scores, and what the command prints
and writes (--json) of it.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._atomic_files import replacing
from ._regression_tools import format_verdicts


@dataclass
class Judgement:
    """The verdict on one result and its diagnosis (see the module's docstring).

    Attributes
    ----------
    verdict : {"pass", "fail"}
        Whether max |dtheta| is within the tolerance; ``passed`` says the same as a bool.
    diagnosis : str
        The mistake that explains the difference, "agrees" or "unexplained".
    residual, max_abs_dtheta, worst_time, tolerance : float
        What is left once the diagnosis is explained (rad); the largest |dtheta| (rad) and its time
        (s); the tolerance (rad).
    candidates : dict
        Per candidate mistake, the residual of its best variant (rad); None where it does not apply.
    smallest_input_effect : float or None
        The smallest difference an input-timing variant makes to this run (rad).
    points : int
        The result's rows.
    exact_zeros : int
        The rows where theta equals the reference's exactly.
    optional_differences : dict
        ``max |domega|`` (rad/s) and ``max |dalpha|`` (rad/s2), of those the result gives at every row.
    drawn : numpy.ndarray
        The points a figure draws: every row of a short result; of a long one, every extreme per
        column of time (drawn_points). Fields time, torque (the run's, N.m), reference and result
        (theta, rad), explained_torque and explained_theta (the variant that explains the result;
        NaN where none does: agrees, unexplained, an integration error without an integrator).
    source : str
        The result file's name, as reports show it.
    integrator : str or None
        For an integration error that one of its variants explains, the integrator the result is
        (INTEGRATORS: explicit or semi-implicit Euler at the communication step); else None.

    Examples
    --------
    A run whose torque steps 1 ms after the signal's step, and the mistake it is given:

    >>> import tempfile
    >>> from pathlib import Path
    >>> from pendulum_fmu import judge, simulate
    >>> from pendulum_fmu.fmu._results import write_csv
    >>> late = simulate(lambda t: 0.0 if t < 0.251 else 20.0, stop_time=0.5)
    >>> judgement = judge(write_csv(late, Path(tempfile.mkdtemp()) / "late.csv"),
    ...                   lambda t: 0.0 if t < 0.25 else 20.0, stop_time=0.5)
    >>> judgement.verdict, judgement.diagnosis, f"{judgement.max_abs_dtheta:.2e} rad"
    ('fail', 'input one step late', '1.55e-04 rad')
    """

    verdict: str
    diagnosis: str
    residual: float
    max_abs_dtheta: float
    worst_time: float
    tolerance: float
    # Per candidate: the residual of its best variant and how far that variant is from the
    # reference (rad); None where the candidate does not apply to this run.
    candidates: dict[str, dict | None]
    # The smallest difference from the reference an input-timing variant that changes this run
    # makes (rad; None when none does): an integration error must be small beside it.
    smallest_input_effect: float | None
    points: int
    exact_zeros: int
    optional_differences: dict[str, float]
    drawn: np.ndarray = field(repr=False)
    source: str = "result"
    integrator: str | None = None
    # csv-compare's tube and the FMI cross-check's band on theta (regression_tools.regression_verdicts).
    regression_tools: list[dict] = field(default_factory=list)

    @property
    def passed(self) -> bool:
        """Whether the verdict is pass."""
        return self.verdict == "pass"

    def summary(self) -> dict:
        """What --json writes: plain numbers, rad and s."""
        return {
            "result": self.source,
            "verdict": self.verdict,
            "diagnosis": self.diagnosis,
            "integrator": self.integrator,
            "residual": self.residual,
            "max_abs_dtheta": self.max_abs_dtheta,
            **self.optional_differences,
            "worst_time": self.worst_time,
            "tolerance": self.tolerance,
            "points": self.points,
            "candidates": self.candidates,
            "smallest_input_effect": self.smallest_input_effect,
            "regression_tools": self.regression_tools,
            "units": {
                "residual": "rad",
                "max_abs_dtheta": "rad",
                "max_abs_domega": "rad/s",
                "max_abs_dalpha": "rad/s2",
                "worst_time": "s",
                "tolerance": "rad",
                "candidates": "rad",
                "smallest_input_effect": "rad",
            },
        }


def format_judgement(judgement: Judgement) -> str:
    """The lines the command prints for one result: verdict and diagnosis, max |dtheta| and
    where, and every candidate's residual and effect.

    Parameters
    ----------
    judgement : Judgement
        What judge() returned.

    Returns
    -------
    str
        The lines, joined.
    """
    named = f"{judgement.diagnosis}: {judgement.integrator}" if judgement.integrator else judgement.diagnosis
    lines = [
        f"{judgement.source}: {judgement.verdict}: {named} (residual {judgement.residual:.2e} rad)",
        f"max |dtheta| = {judgement.max_abs_dtheta:.3e} rad at t = {judgement.worst_time!r} s "
        f"(tolerance {judgement.tolerance:g} rad; {judgement.points} points)",
        f"{'candidate':<28} {'residual rad':>12} {'effect rad':>11}",
    ]
    for name, score in judgement.candidates.items():
        if score is None:
            lines.append(f"{name:<28} {'does not apply to this run':>24}")
        else:
            lines.append(f"{name:<28} {score['residual']:>12.2e} {score['effect']:>11.2e}")
    if judgement.regression_tools:
        lines.append("what regression tools would say, on theta against the reference:")
        lines.extend(f"  {line}" for line in format_verdicts(judgement.regression_tools))
    return "\n".join(lines)


def format_kit(verdicts: dict[str, Judgement | None]) -> str:
    """The lines the command prints for a kit: one per scenario, then how many pass.

    Parameters
    ----------
    verdicts : dict
        What judge_kit() returned: {scenario: Judgement, or None where it was not run}.

    Returns
    -------
    str
        The lines, joined.
    """
    lines = []
    for name, judgement in verdicts.items():
        if judgement is None:
            lines.append(f"{name:<18} not run: no {name}_out.csv")
        else:
            lines.append(
                f"{name:<18} {judgement.verdict:<4}  {judgement.diagnosis:<28} max|dtheta| "
                f"{judgement.max_abs_dtheta:.2e} rad at t = {judgement.worst_time:.6g} s, "
                f"residual {judgement.residual:.1e} rad"
            )
    judged = [judgement for judgement in verdicts.values() if judgement is not None]
    not_run = len(verdicts) - len(judged)
    lines.append(
        f"{sum(j.passed for j in judged)} of {len(judged)} results pass"
        + (f"; {not_run} scenarios not run" if not_run else "")
    )
    return "\n".join(lines)


def write_json(verdicts: dict[str, Judgement | None] | Judgement | list[Judgement | dict], path: str | Path) -> Path:
    """Write --json whole or not at all: one judgement's summary (Judgement.summary),
    {"scenarios": {name: summary or null}} for a kit, or {"results": [summary, ...]} for many
    results of one run.

    Parameters
    ----------
    verdicts : Judgement, dict or list
        What judge(), judge_kit() or judge_results() returned; a list may also hold, for a result
        that could not be judged, {"result": its name, "error": the one line saying why}.
    path : str or Path
        The JSON file.

    Returns
    -------
    Path
        path.
    """
    content: dict
    if isinstance(verdicts, Judgement):
        content = verdicts.summary()
    elif isinstance(verdicts, list):
        content = {"results": [j.summary() if isinstance(j, Judgement) else j for j in verdicts]}
    else:
        content = {"scenarios": {name: j.summary() if j else None for name, j in verdicts.items()}}
    with replacing(path) as file:
        json.dump(content, file, indent=2)
        file.write("\n")
    return Path(path)


__all__ = ["Judgement", "format_judgement", "format_kit", "write_json"]
