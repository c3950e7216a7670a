"""Part 3: what accuracy costs. For each tolerance and communication step: the largest theta
error of the tutorial case against the oracle, and instructions per step.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .builds import BuiltFmu
from .c_master import theta_trajectory
from .callgrind import instructions_per_step, valgrind_missing
from .report import Row, Table, count, skipped
from .tutorial import ORACLE_TOLERANCE, SCIPY_MAX_STEP, SCIPY_TOLERANCE, STOP_TIME, oracle_error, oracle_theta

PART = "3 accuracy"
DEFAULT_TOLERANCE = 1e-10  # the FMU's, when fmi2SetupExperiment defines none
STEP_SIZES = (1e-4, 1e-3, 1e-2, 1e-1)
ALL_TOLERANCES = tuple(10.0**-n for n in range(4, 14))
QUICK_TOLERANCES = (1e-4, 1e-7, 1e-10, 1e-13)


@dataclass(frozen=True)
class Point:
    tolerance: float
    step_size: float
    max_theta_error: float
    instructions_per_step: float


def step_label(step_size: float) -> str:
    return f"{step_size * 1e3:g} ms"


def measure(master: Path, fmu: BuiltFmu, tolerances: tuple[float, ...]) -> list[Point]:
    oracle = {h: oracle_theta(h) for h in STEP_SIZES}

    def point(case):
        tolerance, h = case
        theta = theta_trajectory(master, fmu, round(STOP_TIME / h), h, tolerance)
        cost = instructions_per_step(master, fmu, h, tolerance)
        return Point(tolerance, h, float(np.max(np.abs(theta - oracle[h]))), cost.instructions_per_step)

    cases = [(tolerance, h) for h in STEP_SIZES for tolerance in tolerances]
    # Each case is a few valgrind processes, one after the other: a case per core keeps every
    # core busy, and instruction counts do not suffer from the load as timings would.
    with ThreadPoolExecutor(max_workers=os.cpu_count()) as pool:
        return list(pool.map(point, cases))


def error_label(error: float, resolution: float) -> str:
    """An error, or what bounds it where the oracle cannot resolve it."""
    return f"<= {resolution:.1e}" if error <= resolution else f"{error:.1e}"


def grid(points: list[Point], resolution: float) -> Table:
    """Tolerances down, step sizes across; each cell max |theta error| (rad) / instructions."""
    by_case = {(p.tolerance, p.step_size): p for p in points}
    header = ("tolerance", *(f"step {step_label(h)}" for h in STEP_SIZES))
    cells = []
    for tolerance in sorted({p.tolerance for p in points}, reverse=True):
        name = f"{tolerance:.0e}" + (" (default)" if tolerance == DEFAULT_TOLERANCE else "")
        cells.append(
            (
                name,
                *(
                    f"{error_label(by_case[(tolerance, h)].max_theta_error, resolution)} / "
                    f"{count(by_case[(tolerance, h)].instructions_per_step)}"
                    for h in STEP_SIZES
                ),
            )
        )
    return Table(
        f"Accuracy against cost: max |theta error| (rad) against the oracle (the reference's Taylor "
        f"series at {ORACLE_TOLERANCE:g}; <= its distance from scipy's DOP853 at {SCIPY_TOLERANCE:g} "
        f"with steps <= {SCIPY_MAX_STEP * 1e3:g} ms where it cannot resolve one) / instructions per step",
        header,
        cells,
    )


def plot(points: list[Point], resolution: float, figure_path: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")  # files only: the benchmark may run without a display
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(figsize=(7, 5))
    # Hollow markers of different shapes and sizes: small steps cost the same at every tolerance,
    # so their points pile up, and each must stay visible under the others.
    for h, marker, size in zip(STEP_SIZES, "soD^", (12, 9, 6, 4), strict=False):
        line = sorted((p for p in points if p.step_size == h), key=lambda p: p.tolerance)
        drawn = axes.loglog(
            [p.instructions_per_step for p in line],
            [p.max_theta_error for p in line],
            marker=marker,
            markersize=size,
            markerfacecolor="none",
            label=f"step {step_label(h)}",
        )
        default = [p for p in line if p.tolerance == DEFAULT_TOLERANCE]
        axes.loglog(
            [p.instructions_per_step for p in default],
            [p.max_theta_error for p in default],
            "*",
            markersize=15,
            color=drawn[0].get_color(),
            markeredgecolor="black",
            zorder=3,
        )
    axes.plot(
        [],
        [],
        "*",
        color="grey",
        markeredgecolor="black",
        markersize=15,
        label=f"default tolerance {DEFAULT_TOLERANCE:g}",
    )
    axes.axhline(resolution, color="grey", linestyle=":", label="the oracle's own error: nothing below it is resolved")
    axes.set_xlabel("instructions per communication step (callgrind, fmi2DoStep)")
    axes.set_ylabel(f"max |theta error| over {STOP_TIME:g} s (rad)")
    tolerances = sorted({p.tolerance for p in points})
    axes.set_title(
        f"Pendulum FMU, tutorial case: one point per tolerance, {tolerances[-1]:.0e} to {tolerances[0]:.0e}",
        fontsize=10,
    )
    axes.grid(True, which="both", alpha=0.3)
    axes.legend(fontsize=8)
    figure.tight_layout()
    figure.savefig(figure_path, dpi=120)
    plt.close(figure)
    return figure_path


def accuracy_cost_rows(master: Path, fmu: BuiltFmu, quick: bool, figure_path: Path) -> tuple[list[Row], Table | None]:
    """Rows for the main table (each step size at the default tolerance) and the full grid."""
    missing = valgrind_missing()
    if missing:
        return [skipped(PART, "accuracy against instructions per step", missing)], None
    points = measure(master, fmu, QUICK_TOLERANCES if quick else ALL_TOLERANCES)
    error_of_oracle = oracle_error()
    plot(points, error_of_oracle, figure_path)
    rows = [
        Row(
            PART,
            f"step {step_label(p.step_size)}, default tolerance: max |theta error| rad / instructions per step",
            f"{error_label(p.max_theta_error, error_of_oracle)} / {count(p.instructions_per_step)}",
        )
        for p in points
        if p.tolerance == DEFAULT_TOLERANCE
    ]
    rows.append(
        Row(
            PART,
            "the oracle's own error: against scipy's DOP853, max |theta difference| rad",
            f"{error_of_oracle:.1e}",
        )
    )
    rows.append(Row(PART, "figure", str(figure_path)))
    return rows, grid(points, error_of_oracle)
