"""One torque signal through several tools, each judged against the independent oracle.

Every tool is fed the schedule that `signal.schedule` makes of the user's signal. The
reference (`reference.reference`) reads the signal itself and shares no code with that schedule,
so a schedule that does not carry the signal shows as a difference: in theta and omega, and in
the torque each tool received against the signal's value at the start of each step.
"""

from __future__ import annotations

import csv
import itertools
import math
import time as clock
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import results
from .files import replacing
from .parameters import resolve_parameters
from .plot import plot_comparison
from .reference import reference
from .signal import TorqueSignal, schedule
from .simulate import open_fmu, run_schedule

REFERENCE = "reference"
TOOLS = ("fmu", REFERENCE, "opensim")
# The torque a tool received may differ from the signal by rounding only (relative to the
# signal's size; on a steep ramp an ulp of time is more than an ulp of torque).
TORQUE_ROUNDING = 1e-9


def _run_fmu(plan, parameters, theta0, omega0, fmu_path=None):
    slave = open_fmu(fmu_path, parameters=parameters, theta0=theta0, omega0=omega0,
                     start_time=float(plan.time[0]))
    try:
        return run_schedule(slave, plan)
    finally:
        slave.terminate()
        slave.freeInstance()


def _run_opensim(plan, parameters, theta0, omega0, fmu_path=None):
    from .opensim_model import opensim_simulate

    if np.any(plan.torque_rate):
        raise ValueError("opensim cannot ramp: overrideActuation holds the torque over each step; "
                         "leave opensim out of --tools, or compare held torques (no --ramp)")
    run = opensim_simulate(plan.time, plan.torque, theta0=theta0, omega0=omega0,
                           **resolve_parameters(parameters))
    out = results.empty(len(plan.time))
    for name in results.FIELDS:
        out[name] = run[name]
    return out


_RUNNERS = {"fmu": _run_fmu, "opensim": _run_opensim}


def check_tools(tools) -> list[str]:
    """The tools as a list; unknown names, repeats and fewer than two tools are refused."""
    tools = [str(tool).strip() for tool in tools]
    unknown = [tool for tool in tools if tool not in TOOLS]
    if unknown:
        raise ValueError(f"unknown tool(s) {', '.join(unknown)}: choose from {', '.join(TOOLS)}")
    repeated = sorted({tool for tool in tools if tools.count(tool) > 1})
    if repeated:
        raise ValueError(f"tool(s) {', '.join(repeated)} given more than once: name each tool once")
    if len(tools) < 2:
        raise ValueError(f"compare needs at least two tools, got {', '.join(tools) or 'none'}: "
                         f"e.g. --tools fmu,{REFERENCE}")
    return tools


def check_tolerance(tolerance: float) -> float:
    if not (math.isfinite(tolerance) and tolerance > 0):
        raise ValueError(f"the tolerance {tolerance} must be a positive finite number (rad, rad/s)")
    return float(tolerance)


def differences(run: np.ndarray, judge: np.ndarray) -> dict[str, float]:
    """max and RMS |run - judge| of theta, omega and alpha, and max |torque difference|."""
    row = {}
    for name in ("theta", "omega", "alpha"):
        difference = np.abs(run[name] - judge[name])
        row[f"{name}_max"] = float(np.max(difference))
        row[f"{name}_rms"] = float(np.sqrt(np.mean(difference ** 2)))
    row["torque_max"] = float(np.max(np.abs(run["torque"] - judge["torque"])))
    return row


COLUMNS = ("tool", "against", "theta_max", "theta_rms", "omega_max", "omega_rms", "alpha_max",
           "alpha_rms", "torque_max", "seconds_per_step")


def format_table(rows: list[dict]) -> str:
    lines = [f"{'tool':<12} {'against':<12} {'max|dtheta| rad':>15} {'rms dtheta':>10} "
             f"{'max|domega| rad/s':>17} {'max|dalpha|':>11} {'max|dtorque| N.m':>16} {'s/step':>8}"]
    for row in rows:
        per_step = row.get("seconds_per_step")
        lines.append(f"{row['tool']:<12} {row['against']:<12} {row['theta_max']:>15.3e} "
                     f"{row['theta_rms']:>10.2e} {row['omega_max']:>17.3e} {row['alpha_max']:>11.2e} "
                     f"{row['torque_max']:>16.2e} {'' if per_step is None else f'{per_step:8.1e}':>8}")
    return "\n".join(lines)


def write_trajectories(runs: dict[str, np.ndarray], path: str | Path) -> Path:
    """One CSV: time, then torque, theta, omega, alpha of each tool (torque_fmu, theta_fmu, ...)."""
    columns = {"time": next(iter(runs.values()))["time"]}
    for tool, run in runs.items():
        for name in ("torque", "theta", "omega", "alpha"):
            columns[f"{name}_{tool}"] = run[name]
    with replacing(path, newline="") as file:
        writer = csv.writer(file)
        writer.writerow(columns)
        writer.writerows(zip(*(map(repr, np.asarray(values, dtype=float).tolist())
                               for values in columns.values())))
    return Path(path)


def write_differences(rows: list[dict], path: str | Path) -> Path:
    with replacing(path, newline="") as file:
        writer = csv.DictWriter(file, fieldnames=COLUMNS)
        writer.writeheader()
        writer.writerows(rows)
    return Path(path)


@dataclass
class Comparison:
    runs: dict[str, np.ndarray]
    differences: list[dict]
    tolerance: float
    trajectories: Path
    table: Path
    figure: Path

    @property
    def worst(self) -> float:
        """The largest difference in theta or omega of any row of the table."""
        return max((max(row["theta_max"], row["omega_max"]) for row in self.differences), default=0.0)

    @property
    def torque_worst(self) -> float:
        """The largest difference between the torque a tool received and the signal."""
        return max((row["torque_max"] for row in self.differences if row["against"] == REFERENCE),
                   default=0.0)

    @property
    def torque_limit(self) -> float:
        return TORQUE_ROUNDING * (1.0 + float(np.max(np.abs(self.runs[REFERENCE]["torque"]))))

    @property
    def agree(self) -> bool:
        return self.worst <= self.tolerance and self.torque_worst <= self.torque_limit


def compare(torque: TorqueSignal, tools=TOOLS, *, output_dir: str | Path, step_size: float = 1e-3,
            start_time: float = 0.0, stop_time: float | None = None, ramp: bool = False,
            parameters: dict | None = None, theta0: float = 0.0, omega0: float = 0.0,
            tolerance: float = 1e-9, title: str | None = None,
            fmu_path: str | Path | None = None, max_steps: int | None = None) -> Comparison:
    """Run one signal through each tool and judge each against the reference.

    The reference is always run, as the judge, whether or not `tools` names it. Writes to
    output_dir:
    - trajectories.csv: every tool's torque, theta, omega, alpha;
    - differences.csv: each tool against the reference (max and RMS of theta, omega, alpha;
      max |torque received - signal|; wall time per step) and every pair of other tools;
    - comparison.png: the tools overlaid, and their differences on a log scale.

    ramp=True ramps the torque over each step in every tool that can; a tool that cannot says so.
    """
    tools = check_tools(tools)
    tolerance = check_tolerance(tolerance)
    resolve_parameters(parameters)  # a bad parameter is refused before any tool runs
    plan = schedule(torque, start_time=start_time, stop_time=stop_time, step_size=step_size, ramp=ramp,
                    max_steps=max_steps)
    runs, seconds = {}, {}
    for tool in [REFERENCE] + [tool for tool in tools if tool != REFERENCE]:
        started = clock.perf_counter()
        if tool == REFERENCE:
            runs[tool] = reference(torque, start_time=start_time, stop_time=stop_time,
                                   step_size=step_size, ramp=ramp, parameters=parameters,
                                   theta0=theta0, omega0=omega0, at=plan.time)
        else:
            runs[tool] = _RUNNERS[tool](plan, parameters, theta0, omega0, fmu_path)
        seconds[tool] = (clock.perf_counter() - started) / (len(plan.time) - 1)
    judge = runs[REFERENCE]
    others = [tool for tool in runs if tool != REFERENCE]
    rows = [{"tool": tool, "against": REFERENCE, **differences(runs[tool], judge),
             "seconds_per_step": seconds[tool]} for tool in others]
    rows += [{"tool": a, "against": b, **differences(runs[a], runs[b]), "seconds_per_step": None}
             for a, b in itertools.combinations(others, 2)]
    output_dir = Path(output_dir)
    return Comparison(
        runs=runs, differences=rows, tolerance=tolerance,
        trajectories=write_trajectories(runs, output_dir / "trajectories.csv"),
        table=write_differences(rows, output_dir / "differences.csv"),
        figure=plot_comparison(runs, output_dir / "comparison.png",
                               title or f"Torque-driven pendulum: {', '.join(runs)}"),
    )

