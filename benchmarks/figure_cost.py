"""What drawing a sweep's figure costs the client, at 4,096 and 100,000 cases.

    .venv/bin/python -m benchmarks.figure_cost

Every run_sweep ends by drawing sweep.png from the cases table (pendulum_fmu/sweep/figure.py's
draw): a serial tail on the client after the workers are done. Two studies of short cases
(10 ms, no trajectories) are run once on one local worker, with the pendulum FMU built from this
checkout (their runs import matplotlib, which a client pays once); then draw is timed on each
study's cases table, CPU (time.process_time) and wall, the least of REPEATS. The comparison
figure of a 3-s run, which _plot.py finishes the same way, is timed alike. The machine's load
average is printed before and after: run the benchmark of two checkouts in turn to compare them.
"""

from __future__ import annotations

import os
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import fsspec
import numpy as np

from .builds import build_pendulum_fmu
from .report import cpu_model

REPEATS = 5
# (torques, gravities) of each study: 64 x 64 = 4,096 and 500 x 200 = 100,000 cases.
STUDIES = ((64, 64), (500, 200))


def cpu_and_wall(call: Callable[[], object]) -> tuple[float, float]:
    """CPU and wall seconds of one call."""
    cpu, wall = time.process_time(), time.perf_counter()
    call()
    return time.process_time() - cpu, time.perf_counter() - wall


def least(call: Callable[[], object]) -> tuple[float, float]:
    """The least CPU and the least wall seconds of REPEATS calls."""
    timings = [cpu_and_wall(call) for _ in range(REPEATS)]
    return min(cpu for cpu, _ in timings), min(wall for _, wall in timings)


def sweep_figure(scratch: Path, fmu: Path, torques: int, gravities: int) -> Callable[[], object]:
    """Run a study of torques x gravities cases of 10 ms once; return a call that draws its figure
    from its cases table, as run_sweep does at its end.
    """
    from pendulum_fmu.sweep import Study, run_sweep, sweep_grid
    from pendulum_fmu.sweep.figure import draw
    from pendulum_fmu.sweep.store import Store

    study = Study(
        sweep_grid(np.linspace(0.0, 40.0, torques), np.linspace(0.0, 20.0, gravities)),
        stop_time=0.01,
        outputs=(),
        fmu_path=fmu,
    )
    folder = scratch / f"study_{torques * gravities}"
    run_sweep(study, output_dir=folder, workers=1, progress=False)
    store = Store(fsspec.filesystem("file"), str(folder), study.format)
    table = store.read_cases(study.names)
    return lambda: draw(store, table, study.names, study.outputs, str(fmu), str(folder / "sweep.png"))


def comparison_figure(scratch: Path, fmu: Path) -> Callable[[], object]:
    """A call that draws the comparison figure of the FMU against the reference, 3 s at 20 N.m."""
    from pendulum_fmu import reference, simulate
    from pendulum_fmu.figures._plot import plot_comparison

    runs = {"reference": reference(20.0, stop_time=3.0), "fmu": simulate(20.0, stop_time=3.0, fmu_path=fmu)}
    return lambda: plot_comparison(runs, scratch / "compare.png", "20 N.m from rest")


def main() -> None:
    with tempfile.TemporaryDirectory(prefix="pendulum-figure-cost-") as scratch_name:
        scratch = Path(scratch_name)
        fmu = build_pendulum_fmu(scratch).path
        figures = {
            f"sweep.png, {torques * gravities:,} cases": sweep_figure(scratch, fmu, torques, gravities)
            for torques, gravities in STUDIES
        }
        print(f"{cpu_model()}, {os.cpu_count()} cores; load average {os.getloadavg()[0]:.2f} before")
        figures["comparison figure, 3-s run"] = comparison_figure(scratch, fmu)
        print(f"{'figure':32} {'CPU s':>7} {'wall s':>7}   (least of {REPEATS})")
        for name, draw in figures.items():
            cpu, wall = least(draw)
            print(f"{name:32} {cpu:7.3f} {wall:7.3f}")
        print(f"load average {os.getloadavg()[0]:.2f} after")


if __name__ == "__main__":
    main()
