"""One torque signal through several tools, each judged against the independent oracle.

Every tool is fed the schedule that `torque_schedule.schedule` makes of the user's signal. The
reference (`reference.reference`) reads the signal itself and shares no code with that schedule,
so a schedule that does not carry the signal shows as a difference: in theta and omega, and in
the torque each tool received against the signal's value at the start of each step.

The run is walked a window of the schedule at a time (_walk.py), the reference restarted from
its own state at each window, so that a comparison of the tools that can run that way takes the
memory of a window however long the run.
"""

from __future__ import annotations

import csv
import math
import os
import time as clock
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .._atomic_files import check_writable, replacing
from .._errors import InvalidInput, WrongType
from ..figures._plot import case_title, plot_comparison
from ..fmu._model import fmu_model
from ..fmu._simulate import resolve_parameters
from ..oracle._reference import reference_windows
from ..signals._time_grid import WINDOW_STEPS
from ..signals._torque_schedule import TorqueSchedule, TorqueSignal, schedule, schedule_windows
from ._compare_tools import ToolSpecError, installed_defaults, parse_tools
from ._walk import REFERENCE, walk

# The torque a tool received may differ from the signal by rounding only (relative to the
# signal's size; on a steep ramp an ulp of time is more than an ulp of torque).
TORQUE_ROUNDING = 1e-9


def run_tools(
    plan: TorqueSchedule,
    tools,
    *,
    parameters: dict | None = None,
    theta0: float = 0.0,
    omega0: float = 0.0,
    fmu_path: str | Path | None = None,
    mapping: str | dict | None = None,
) -> dict[str, np.ndarray]:
    """{tool label: result array} for the same schedule, parameters and start values; tools as
    --tools gives them (see _compare_tools.py), mapping the --map of other FMUs. "reference" here is
    reference_schedule: the schedule's own torques, integrated on their own.
    """
    model = fmu_model(fmu_path)  # read once, passed to every tool
    parsed = parse_tools(tools, mapping=mapping, fmu_path=model)
    # Every tool gets the whole set, so the defaults are fmu_path's for all of them.
    parameters = resolve_parameters(parameters, model)
    return {tool.label: tool.run(plan, parameters=parameters, theta0=theta0, omega0=omega0) for tool in parsed}


def check_tolerance(tolerance: float) -> float:
    """The tolerance as a float; InvalidInput unless it is a positive finite number."""
    if not (math.isfinite(tolerance) and tolerance > 0):
        raise InvalidInput(f"the tolerance {tolerance} must be a positive finite number (rad, rad/s)")
    return float(tolerance)


COLUMNS = (
    "tool",
    "against",
    "theta_max",
    "theta_rms",
    "omega_max",
    "omega_rms",
    "alpha_max",
    "alpha_rms",
    "torque_max",
    "seconds_per_step",
)  # and the differences of any other output


def format_table(rows: list[dict]) -> str:
    """The differences of a comparison as the table compare's command line prints.

    Parameters
    ----------
    rows : list of dict
        Rows as in Comparison.differences: tool, against, theta_max, theta_rms, omega_max,
        alpha_max, torque_max and, optionally, seconds_per_step (None or absent: left blank).

    Returns
    -------
    str
        A header line, then one line per row.

    Raises
    ------
    KeyError
        A row without one of the columns.

    Examples
    --------
    >>> from pendulum_fmu import format_table
    >>> row = {"tool": "fmu", "against": "reference", "theta_max": 8.9e-13, "theta_rms": 3.9e-13,
    ...        "omega_max": 1.8e-13, "alpha_max": 5.8e-12, "torque_max": 0.0, "seconds_per_step": 2.1e-05}
    >>> print(format_table([row]))
    tool         against      max|dtheta| rad rms dtheta max|domega| rad/s max|dalpha| max|dtorque| N.m   s/step
    fmu          reference          8.900e-13   3.90e-13         1.800e-13    5.80e-12         0.00e+00  2.1e-05
    """
    width = max([12, *(len(row["tool"]) + 1 for row in rows), *(len(row["against"]) + 1 for row in rows)])
    lines = [
        f"{'tool':<{width}} {'against':<{width}} {'max|dtheta| rad':>15} {'rms dtheta':>10} "
        f"{'max|domega| rad/s':>17} {'max|dalpha|':>11} {'max|dtorque| N.m':>16} {'s/step':>8}"
    ]
    for row in rows:
        per_step = row.get("seconds_per_step")
        lines.append(
            f"{row['tool']:<{width}} {row['against']:<{width}} {row['theta_max']:>15.3e} "
            f"{row['theta_rms']:>10.2e} {row['omega_max']:>17.3e} {row['alpha_max']:>11.2e} "
            f"{row['torque_max']:>16.2e} {'' if per_step is None else f'{per_step:8.1e}':>8}"
        )
    return "\n".join(lines)


def write_differences(rows: list[dict], path: str | Path) -> Path:
    """Write differences.csv: the rows of COLUMNS, then any other output's differences."""
    with replacing(path, newline="") as file:
        fields = [*COLUMNS, *(key for key in (rows[0] if rows else {}) if key not in COLUMNS)]
        writer = csv.DictWriter(file, fieldnames=fields)
        writer.writeheader()
        writer.writerows(rows)
    return Path(path)


@dataclass
class Comparison:
    """What compare() ran and judged, and the files it wrote.

    Attributes
    ----------
    runs : dict of str to numpy.ndarray
        Each tool's results array (_results.py), by its label; "reference" (the judge) first.
        Every row where a tool ran the whole schedule at once (whole), or where the run is short
        (a few thousand rows); else, the run having been walked a window at a time, the rows its
        figure draws: in each of 2000 columns of time, the first and last row and where theta,
        omega or a tool's difference from the reference is least and greatest.
    differences : list of dict
        The rows of differences.csv: each tool against the reference, then each pair of tools.
    tolerance : float
        The largest difference in theta (rad) or omega (rad/s) for the tools to agree.
    trajectories, table, figure : Path
        trajectories.csv, differences.csv and comparison.png.
    largest_torque : float
        ``max |torque|`` of the signal over the run, in N.m, the scale of torque_limit.
    whole : tuple of str
        The tools that ran the whole schedule at once, holding the run in memory: those that
        cannot run it a window at a time (the engines, Pendulum-v1, a Model Exchange FMU through
        a --map).
    worst, torque_worst, torque_limit : float
        The largest difference in theta or omega; the largest difference between the torque a tool
        received and the signal, and the rounding allowed for it.
    agree : bool
        Whether every tool is within the tolerance and received the signal's torque.

    Examples
    --------
    >>> import tempfile
    >>> from pendulum_fmu import compare
    >>> comparison = compare(20.0, "fmu,reference", output_dir=tempfile.mkdtemp(), stop_time=0.5)
    >>> sorted(comparison.runs), bool(comparison.worst < comparison.tolerance)
    (['fmu', 'reference'], True)
    """

    runs: dict[str, np.ndarray]
    differences: list[dict]
    tolerance: float
    trajectories: Path
    table: Path
    figure: Path
    largest_torque: float
    whole: tuple[str, ...] = ()

    @property
    def worst(self) -> float:
        """The largest difference in theta or omega of any row of the table."""
        return max((max(row["theta_max"], row["omega_max"]) for row in self.differences), default=0.0)

    @property
    def torque_worst(self) -> float:
        """The largest difference between the torque a tool received and the signal."""
        return max((row["torque_max"] for row in self.differences if row["against"] == REFERENCE), default=0.0)

    @property
    def torque_limit(self) -> float:
        """The rounding allowed between the torque a tool received and the signal, in N.m."""
        return TORQUE_ROUNDING * (1.0 + self.largest_torque)

    @property
    def agree(self) -> bool:
        """Whether every tool is within the tolerance and received the signal's torque."""
        return self.worst <= self.tolerance and self.torque_worst <= self.torque_limit


def compare(
    torque: TorqueSignal,
    tools=None,
    *,
    output_dir: str | Path,
    step_size: float = 1e-3,
    start_time: float = 0.0,
    stop_time: float | None = None,
    ramp: bool = False,
    parameters: dict | None = None,
    theta0: float = 0.0,
    omega0: float = 0.0,
    tolerance: float = 1e-9,
    title: str | None = None,
    fmu_path: str | Path | None = None,
    mapping: str | dict | None = None,
    max_steps: int | None = None,
    window_steps: int = WINDOW_STEPS,
) -> Comparison:
    """Run one signal through each tool and judge each against the reference.

    The reference is the independent oracle reading the signal itself; it always runs, as the
    judge, whether or not `tools` names it. Every tool gets the same schedule, parameters and
    start values.

    Parameters
    ----------
    torque : float, callable, sequence of float, str or Path
        The signal, as simulate() takes it.
    tools : str or sequence of str, optional
        As --tools gives them (_compare_tools.py): fmu, reference, opensim, mujoco, drake,
        pybullet (NAME:default for an engine's own defaults), LABEL=path/to/Their.fmu. By default
        fmu, reference and opensim, those of them that are installed; the others are left out
        with a warning (errors.Skipped) that says how to install them.
    output_dir : str or Path
        Where to write trajectories.csv (every tool's torque, theta, omega, alpha),
        differences.csv (each tool against the reference: max and RMS of theta, omega, alpha,
        ``max |torque received - signal|``, wall time per step; and every pair of other tools) and
        comparison.png (the tools overlaid, and their differences on a log scale).
    step_size, start_time, stop_time, parameters, theta0, omega0, max_steps, fmu_path
        As simulate() takes them; fmu_path's parameters and defaults apply to every tool.
    ramp : bool, optional
        Ramp the torque over each step in every tool that can; a tool that cannot says so.
    tolerance : float, optional
        The largest difference in theta (rad) or omega (rad/s) for the tools to agree.
    title : str, optional
        The figure's title.
    mapping : str or dict, optional
        The --map of the tools given as LABEL=path, as its text or as a dict such as
        {"theta": "phi*0.0174532925"} (mapped_fmu.as_map).
    window_steps : int, optional
        Grid steps walked at a time (default WINDOW_STEPS): the reference is integrated, and the
        FMU's binaries (fmu, wasm) run, a window at a time, their state carried on, and each
        window's rows written to trajectories.csv as they come, as is a Co-Simulation FMU through
        a --map. A comparison of those tools only takes memory bounded by a window, however long
        the run; the engines, Pendulum-v1 and a Model Exchange FMU through a --map run the whole
        schedule at once first (Comparison.whole).

    Returns
    -------
    Comparison
        The runs, the table of differences, the verdict (agree, worst) and the files written.

    Raises
    ------
    ToolSpecError
        A tools list that names no two runnable tools, or a tool that is not installed.
    MapError
        A mapping, or an FMU that does not fit it.
    InvalidInput
        A tolerance, signal, time or parameter the package refuses; a ramp given to a tool
        that holds the torque (ToolCannotRamp).
    FmuError
        An FMU refused a step.
    CannotWrite
        output_dir cannot be written.

    Examples
    --------
    >>> import tempfile
    >>> from pendulum_fmu import compare
    >>> comparison = compare(20.0, "fmu,reference", output_dir=tempfile.mkdtemp(), stop_time=1.0)
    >>> comparison.agree, [row["tool"] for row in comparison.differences]
    (True, ['fmu'])
    >>> comparison.trajectories.name, comparison.table.name, comparison.figure.name
    ('trajectories.csv', 'differences.csv', 'comparison.png')
    """
    if not isinstance(output_dir, str | os.PathLike):
        raise WrongType(f"output_dir is a folder's path, not {output_dir!r}")
    model = fmu_model(fmu_path)  # read once, passed to every tool
    parsed = parse_tools(installed_defaults() if tools is None else tools, mapping=mapping, fmu_path=model)
    if len(parsed) < 2:
        raise ToolSpecError(f"compare needs at least two tools, got {parsed[0].label}: e.g. --tools fmu,{REFERENCE}")
    tolerance = check_tolerance(tolerance)
    shown = case_title(torque, parameters, theta0, omega0, model)  # the user's own parameters
    # Refused here before any tool runs; and every tool gets the whole set, so the defaults are
    # fmu_path's for all of them.
    parameters = resolve_parameters(parameters, model)
    times: dict[str, Any] = dict(
        start_time=start_time, stop_time=stop_time, step_size=step_size, ramp=ramp, max_steps=max_steps
    )
    windows = schedule_windows(torque, **times, window_steps=window_steps)
    output_dir = Path(output_dir)
    outputs = {name: output_dir / name for name in ("trajectories.csv", "differences.csv", "comparison.png")}
    check_writable(*outputs.values())
    start: dict[str, Any] = dict(parameters=parameters, theta0=theta0, omega0=omega0)
    # The judge's work estimated, and refused past its bound, before any tool runs.
    oracle = reference_windows(torque, **times, **start, fmu_path=model, window_steps=window_steps)
    others = [tool for tool in parsed if tool.label != REFERENCE]  # the judge takes the reference's place
    whole = [tool for tool in others if tool.windowed is None]
    runs, seconds = {}, {}
    if whole:
        plan = schedule(torque, **times)  # held whole, as those tools take it: memory is checked
        for tool in whole:
            started = clock.perf_counter()
            runs[tool.label] = tool.run(plan, **start)
            seconds[tool.label] = clock.perf_counter() - started
        del plan  # the walk makes its own windows of it
    tally, walked = walk(windows, oracle, others, runs, outputs["trajectories.csv"], start)
    seconds.update(walked)
    steps = tally.differences.rows - 1
    rows = tally.differences.table({label: spent / steps for label, spent in seconds.items()})
    runs = tally.runs()
    return Comparison(
        runs=runs,
        differences=rows,
        tolerance=tolerance,
        trajectories=outputs["trajectories.csv"],
        table=write_differences(rows, outputs["differences.csv"]),
        figure=plot_comparison(runs, outputs["comparison.png"], title or f"{shown}; tools {', '.join(runs)}"),
        largest_torque=tally.largest_torque,
        whole=tuple(tool.label for tool in whole),
    )


def format_comparison(comparison: Comparison) -> str:
    """The table of differences and the verdict, as the command line prints them."""
    verdict = "agree" if comparison.agree else "DIFFER"
    return (
        f"{format_table(comparison.differences)}\n"
        f"tools {verdict}: worst difference {comparison.worst:.3e} against tolerance "
        f"{comparison.tolerance:g}; torque received vs the signal: {comparison.torque_worst:.3e} "
        f"N.m (allowed {comparison.torque_limit:.1e})"
    )
