"""One torque signal through several tools: trajectories, pairwise differences, a figure."""

from __future__ import annotations

import csv
import itertools
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import results
from .parameters import resolve_parameters
from .plot import plot_comparison
from .reference import reference_schedule
from .signal import TorqueSchedule, TorqueSignal, schedule
from .simulate import open_fmu, run_schedule

TOOLS = ("fmu", "reference", "opensim")


def _run_fmu(plan, parameters, theta0, omega0, fmu_path=None):
    slave = open_fmu(fmu_path, parameters=parameters, theta0=theta0, omega0=omega0,
                     start_time=float(plan.time[0]))
    try:
        return run_schedule(slave, plan)
    finally:
        slave.terminate()
        slave.freeInstance()


def _run_reference(plan, parameters, theta0, omega0, fmu_path=None):
    return reference_schedule(plan, parameters=parameters, theta0=theta0, omega0=omega0,
                              fmu_path=fmu_path)


def _run_opensim(plan, parameters, theta0, omega0, fmu_path=None):
    from .opensim_model import opensim_simulate

    if np.any(plan.torque_rate):
        raise ValueError("OpenSim's overrideActuation holds the torque over a step: compare held "
                         "torques only (no ramp)")
    run = opensim_simulate(plan.time, plan.torque, theta0=theta0, omega0=omega0,
                           **resolve_parameters(parameters, fmu_path))
    out = results.empty(len(plan.time))
    for name in results.FIELDS:
        out[name] = run[name]
    return out


_RUNNERS = {"fmu": _run_fmu, "reference": _run_reference, "opensim": _run_opensim}


def run_tools(plan: TorqueSchedule, tools=TOOLS, *, parameters: dict | None = None,
              theta0: float = 0.0, omega0: float = 0.0,
              fmu_path: str | Path | None = None) -> dict[str, np.ndarray]:
    """{tool: result array} for the same schedule, parameters and start values."""
    unknown = [tool for tool in tools if tool not in _RUNNERS]
    if unknown:
        raise ValueError(f"unknown tool(s) {', '.join(unknown)}: choose from {', '.join(TOOLS)}")
    return {tool: _RUNNERS[tool](plan, parameters, theta0, omega0, fmu_path) for tool in tools}


def pairwise_differences(runs: dict[str, np.ndarray]) -> list[dict]:
    """max |dtheta|, |domega| for every pair of tools."""
    return [{"tool_a": a, "tool_b": b, **results.max_differences(runs[a], runs[b])}
            for a, b in itertools.combinations(runs, 2)]


def format_table(rows: list[dict]) -> str:
    lines = [f"{'tools':<24} {'max |dtheta| rad':>17} {'max |domega| rad/s':>19}"]
    lines += [f"{row['tool_a'] + ' vs ' + row['tool_b']:<24} {row['theta']:>17.3e} {row['omega']:>19.3e}"
              for row in rows]
    return "\n".join(lines)


def write_trajectories(runs: dict[str, np.ndarray], path: str | Path) -> Path:
    """One CSV: time and torque, then theta, omega, alpha of each tool (theta_fmu, ...)."""
    first = next(iter(runs.values()))
    columns = {"time": first["time"], "torque": first["torque"]}
    for tool, run in runs.items():
        for name in ("theta", "omega", "alpha"):
            columns[f"{name}_{tool}"] = run[name]
    path = Path(path)
    with open(path, "w", newline="") as file:
        writer = csv.writer(file)
        writer.writerow(columns)
        writer.writerows(zip(*(map(repr, map(float, values)) for values in columns.values())))
    return path


def write_differences(rows: list[dict], path: str | Path) -> Path:
    path = Path(path)
    with open(path, "w", newline="") as file:
        writer = csv.DictWriter(file, fieldnames=["tool_a", "tool_b", "theta", "omega", "alpha"])
        writer.writeheader()
        writer.writerows(rows)
    return path


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
        return max((max(row["theta"], row["omega"]) for row in self.differences), default=0.0)

    @property
    def agree(self) -> bool:
        return self.worst <= self.tolerance


def compare(torque: TorqueSignal, tools=TOOLS, *, output_dir: str | Path, step_size: float = 1e-3,
            stop_time: float | None = None, parameters: dict | None = None, theta0: float = 0.0,
            omega0: float = 0.0, tolerance: float = 1e-9, title: str | None = None,
            fmu_path: str | Path | None = None) -> Comparison:
    """Run one held-torque signal through each tool and write, to output_dir:
    trajectories.csv, differences.csv (max |dtheta|, |domega| for every pair) and comparison.png."""
    if len(tools) < 2:
        raise ValueError("compare needs at least two tools")
    plan = schedule(torque, stop_time=stop_time, step_size=step_size)
    runs = run_tools(plan, tools, parameters=parameters, theta0=theta0, omega0=omega0,
                     fmu_path=fmu_path)
    output_dir = Path(output_dir)
    output_dir.mkdir(parents=True, exist_ok=True)
    differences = pairwise_differences(runs)
    return Comparison(
        runs=runs, differences=differences, tolerance=tolerance,
        trajectories=write_trajectories(runs, output_dir / "trajectories.csv"),
        table=write_differences(differences, output_dir / "differences.csv"),
        figure=plot_comparison(runs, output_dir / "comparison.png",
                               title or f"Torque-driven pendulum: {', '.join(tools)}"),
    )
