"""Parameter studies as a grid of cases, run on dask.

A local cluster by default; with a scheduler address, an existing dask.distributed cluster,
which is how a study grows past one machine (every worker needs this package and the FMU path).
Cases go out in chunks so each task amortizes its scheduling over several simulations.
"""

from __future__ import annotations

import itertools
import logging
import math
import time
from pathlib import Path

import numpy as np

from .build import default_fmu
from .parameters import default_parameters
from .plot import plot_cases
from .simulate import simulate

START_VALUES = ("theta0", "omega0")
# Enough chunks per worker to balance the load, few enough that scheduling stays cheap.
CHUNKS_PER_WORKER = 4


def sweep_grid(torques, gravities=(9.81,), extra: dict[str, list[float]] | None = None) -> list[dict]:
    """Every combination of torque, gravity and the extra values (parameters mass, length,
    inertia, damping, or start values theta0, omega0) as a list of case dicts."""
    axes = {"torque": list(torques), "gravity": list(gravities), **(extra or {})}
    allowed = set(default_parameters()) | set(START_VALUES) | {"torque"}
    for name, values in axes.items():
        if name not in allowed:
            raise ValueError(f"cannot sweep {name!r}: choose from {', '.join(sorted(allowed))}")
        if not values:
            raise ValueError(f"no values given for {name}")
        if not all(math.isfinite(float(v)) for v in values):
            raise ValueError(f"{name} values must be finite, got {values}")
    return [dict(zip(axes, map(float, combination))) for combination in itertools.product(*axes.values())]


def _run_case(case: dict, fmu_path: str, stop_time: float, step_size: float) -> np.ndarray:
    parameters = {k: v for k, v in case.items() if k not in START_VALUES and k != "torque"}
    return simulate(case["torque"], parameters=parameters, theta0=case.get("theta0", 0.0),
                    omega0=case.get("omega0", 0.0), stop_time=stop_time, step_size=step_size,
                    fmu_path=fmu_path)


def _run_chunk(cases: list[dict], fmu_path: str, stop_time: float, step_size: float) -> list[np.ndarray]:
    return [_run_case(case, fmu_path, stop_time, step_size) for case in cases]


def _write_tidy(path: Path, cases: list[dict], runs: list[np.ndarray]) -> Path:
    """One row per case and communication point: case, the case's values, the result fields."""
    names = list(cases[0])
    fields = ("time", "theta", "omega", "alpha")
    blocks = [np.column_stack([np.full(len(run), number), np.tile([case[n] for n in names], (len(run), 1)),
                               *(run[field] for field in fields)])
              for number, (case, run) in enumerate(zip(cases, runs))]
    header = ",".join(["case", *names, *fields])
    formats = ["%d"] + ["%.17g"] * (len(names) + len(fields))
    np.savetxt(path, np.vstack(blocks), delimiter=",", header=header, comments="", fmt=formats)
    return path


def _label(case: dict) -> str:
    return ", ".join(f"{name} = {value:g}" for name, value in case.items())


def run_sweep(cases: list[dict], *, output_dir: str | Path, stop_time: float = 3.0,
              step_size: float = 1e-3, scheduler: str | None = None, workers: int | None = None,
              progress: bool = True, fmu_path: str | Path | None = None) -> dict:
    """Run the cases on dask; write output_dir/sweep.csv (tidy) and sweep.png.

    Returns {'results', 'figure', 'cases', 'seconds'}.
    """
    from dask.distributed import Client, LocalCluster
    from dask.distributed import progress as progress_bar

    if not cases:
        raise ValueError("no cases to run")
    if workers is not None and workers < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    output_dir = Path(output_dir)
    output_dir.mkdir(parents=True, exist_ok=True)
    # Built once here, so workers only read it.
    fmu = str(Path(fmu_path).resolve() if fmu_path else default_fmu())
    started = time.perf_counter()
    cluster = None
    if scheduler:
        client = Client(scheduler)
    else:
        cluster = LocalCluster(n_workers=workers or 2, threads_per_worker=1, processes=True,
                               dashboard_address=None, silence_logs=logging.WARNING)
        client = Client(cluster)
    try:
        n_workers = max(len(client.scheduler_info()["workers"]), 1)
        chunk_size = max(1, math.ceil(len(cases) / (n_workers * CHUNKS_PER_WORKER)))
        chunks = [cases[i:i + chunk_size] for i in range(0, len(cases), chunk_size)]
        futures = client.map(_run_chunk, chunks, fmu_path=fmu, stop_time=stop_time,
                             step_size=step_size, pure=False)
        if progress:
            progress_bar(futures)
            print()
        runs = [run for chunk in client.gather(futures) for run in chunk]
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    seconds = time.perf_counter() - started
    table = _write_tidy(output_dir / "sweep.csv", cases, runs)
    figure = plot_cases({_label(case): run for case, run in zip(cases, runs)}, output_dir / "sweep.png",
                        "Parameter study: torque-driven pendulum")
    return {"results": table, "figure": figure, "cases": len(cases), "seconds": seconds}
