"""Parameter studies: a grid of cases run on dask.distributed.

A local cluster by default; with a scheduler address, an existing cluster, which is how a study
grows past one machine (every worker needs this package installed and the FMU path readable).
Cases go out in chunks, so a task amortizes its scheduling over several simulations, and each
worker formats its chunk's CSV rows: printing floats exactly costs over half as much as
simulating them, so the client only concatenates.
"""

from __future__ import annotations

import itertools
import logging
import math
import numbers
import sys
import time
from pathlib import Path

import numpy as np

from . import default_fmu
from .parameters import default_parameters
from .plot import plot_cases
from .signal import communication_points
from .simulate import FmuError, simulate

START_VALUES = ("theta0", "omega0")
OUTPUTS = ("time", "theta", "omega", "alpha")
# Enough chunks per worker to even out the load and show progress, few enough that per-task
# overhead stays small next to the simulations.
CHUNKS_PER_WORKER = 4


def _sweepable(fmu_path=None) -> list[str]:
    return ["torque", *default_parameters(fmu_path), *START_VALUES]


def _extra_names() -> list[str]:
    return [name for name in _sweepable() if name not in ("torque", "gravity")]


def _values(name: str, values) -> list[float]:
    try:
        array = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} values must be numbers, got {values!r}") from None
    if array.ndim != 1:
        raise ValueError(f"{name} values must be a flat list of numbers, got {values!r}")
    if array.size == 0:
        raise ValueError(f"no values given for {name}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} values must be finite, got {array[~np.isfinite(array)][0]}")
    if len(np.unique(array)) < array.size:
        raise ValueError(f"{name} values repeat: {values!r}")
    return array.tolist()


def sweep_grid(torques, gravities=(9.81,), extra: dict | None = None) -> list[dict]:
    """Every combination of the torques, gravities and extra values as a list of cases.

    extra: {name: [values, ...]} for the parameters mass, length, inertia, damping and the start
    values theta0, omega0. A case is a dict {'torque': .., 'gravity': .., <extra names>: ..}.
    """
    extra = dict(extra or {})
    for name in extra:
        if name in ("torque", "gravity"):
            argument = {"torque": "torques", "gravity": "gravities"}[name]
            raise ValueError(f"give {name} values as the {argument} argument, not in extra")
        if name not in _extra_names():
            raise ValueError(f"cannot sweep {name!r}: extra takes {', '.join(_extra_names())}")
    axes = {"torque": torques, "gravity": gravities, **extra}
    axes = {name: _values(name, values) for name, values in axes.items()}
    return [dict(zip(axes, combination)) for combination in itertools.product(*axes.values())]


def _check_cases(cases, fmu_path=None) -> list[str]:
    """The cases' common keys, which become the CSV's case columns."""
    if not cases:
        raise ValueError("no cases to run")
    names = list(cases[0])
    if "torque" not in names:
        raise ValueError("every case needs a 'torque'")
    seen = {}
    for number, case in enumerate(cases):
        if list(case) != names:
            raise ValueError(f"case {number} has keys {list(case)}; every case needs {names}")
        for name, value in case.items():
            if name not in _sweepable(fmu_path):
                raise ValueError(f"cannot sweep {name!r}: choose from {', '.join(_sweepable(fmu_path))}")
            if not isinstance(value, numbers.Real) or not math.isfinite(value):
                raise ValueError(f"case {number}: {name} = {value!r} must be a finite number")
        # A repeat would only cost time, and share the first one's line in the figure.
        first = seen.setdefault(tuple(case.values()), number)
        if first != number:
            raise ValueError(f"case {number} repeats case {first}")
    return names


def _label(case: dict) -> str:
    return ", ".join(f"{name} = {value:g}" for name, value in case.items())


def _run_chunk(numbered_cases: list[tuple[int, dict]], fmu_path: str, stop_time: float,
               step_size: float) -> tuple[str, np.ndarray, np.ndarray]:
    """Simulate a chunk of cases on a worker.

    Returns the chunk's CSV rows, the common time points and theta and omega of each case
    (shape cases x 2 x points) for the figure.
    """
    text, curves, row_templates = [], [], None
    for number, case in numbered_cases:
        parameters = {k: v for k, v in case.items() if k != "torque" and k not in START_VALUES}
        try:
            run = simulate(case["torque"], parameters=parameters, theta0=case.get("theta0", 0.0),
                           omega0=case.get("omega0", 0.0), stop_time=stop_time,
                           step_size=step_size, fmu_path=fmu_path)
        except FmuError as error:
            raise FmuError(f"case {number} ({_label(case)}): {error}") from None
        if row_templates is None:
            # Every case shares the time points, so they are printed once per chunk.
            row_templates = [f"{t!r},%.17g,%.17g,%.17g\n" for t in run["time"].tolist()]
        # One %-formatting of the whole case, done in C; 17 digits read back as the same double.
        prefix = ",".join([str(number), *(repr(float(v)) for v in case.values())]) + ","
        values = np.column_stack([run["theta"], run["omega"], run["alpha"]]).ravel().tolist()
        text.append((prefix + prefix.join(row_templates)) % tuple(values))
        curves.append((run["theta"], run["omega"]))
    return "".join(text), run["time"], np.array(curves)


def _show_progress(done: int, total: int, seconds: float) -> None:
    # On a terminal the line redraws in place; in a log, a line per finished chunk.
    end = "\r" if sys.stderr.isatty() and done < total else "\n"
    bar = "#" * (30 * done // total)
    print(f"sweep [{bar:<30}] {done}/{total} cases, {seconds:.1f} s", end=end, file=sys.stderr,
          flush=True)


def run_sweep(cases: list[dict], *, output_dir: str | Path, stop_time: float = 3.0,
              step_size: float = 1e-3, scheduler: str | None = None, workers: int | None = None,
              progress: bool = True, fmu_path: str | Path | None = None) -> dict:
    """Run every case on dask; write output_dir/sweep.csv and output_dir/sweep.png.

    sweep.csv is tidy: columns case, the case's keys (torque, gravity, ...), time, theta, omega,
    alpha, one row per case and communication point. scheduler: the address of a running
    dask.distributed scheduler; without one a local cluster of `workers` processes (default 2)
    runs for this call (its workers are spawned, so a script calling this needs the
    `if __name__ == "__main__":` guard). progress: a progress line on stderr.
    Returns {'results': csv path, 'figure': png path, 'cases': count, 'seconds': wall time}.
    """
    from dask.distributed import Client, LocalCluster, as_completed

    started = time.perf_counter()
    names = _check_cases(cases, fmu_path)
    if not (isinstance(stop_time, numbers.Real) and math.isfinite(stop_time)):
        raise ValueError(f"stop time {stop_time} must be a finite number")
    communication_points(0.0, stop_time, step_size)  # refuses a bad stop time or step here, not on a worker
    if scheduler is not None and workers is not None:
        raise ValueError("workers sizes the local cluster; with a scheduler the cluster has its own")
    if workers is not None and (not isinstance(workers, numbers.Integral) or workers < 1):
        raise ValueError(f"workers must be a positive integer, got {workers!r}")
    output_dir = Path(output_dir)
    output_dir.mkdir(parents=True, exist_ok=True)
    # Built here once: workers only read it, each extracting it once per process.
    fmu = str(Path(fmu_path).resolve() if fmu_path else default_fmu())

    if scheduler is None:
        # Port 0 for the scheduler's HTTP server: another cluster may hold dask's usual 8787.
        # Workers log nothing: a case that fails reaches the caller as its own one-line error,
        # which the workers' logs would repeat with a traceback.
        cluster = LocalCluster(n_workers=workers or 2, threads_per_worker=1, processes=True,
                               dashboard_address=":0", silence_logs=logging.CRITICAL)
    else:
        cluster = None
    results = output_dir / "sweep.csv"
    partial = results.with_suffix(".csv.partial")  # so a failed run leaves no half table
    try:
        with Client(cluster if cluster is not None else scheduler) as client, open(partial, "w") as file:
            slots = max(sum(client.nthreads().values()), 1)
            size = math.ceil(len(cases) / (slots * CHUNKS_PER_WORKER))
            numbered = list(enumerate(cases))
            chunks = [numbered[i:i + size] for i in range(0, len(numbered), size)]
            futures = client.map(_run_chunk, chunks, fmu_path=fmu, stop_time=stop_time,
                                 step_size=step_size, pure=False)
            position = {future.key: i for i, future in enumerate(futures)}
            file.write(",".join(["case", *names, *OUTPUTS]) + "\n")
            texts, curves, written, done = {}, [None] * len(chunks), 0, 0
            for future, (text, times, chunk_curves) in as_completed(futures, with_results=True):
                index = position[future.key]
                texts[index], curves[index] = text, chunk_curves
                # Rows go out in case order as soon as the chunks before them are in, so the
                # text, the bulk of the results, never piles up in the client.
                while written in texts:
                    file.write(texts.pop(written))
                    written += 1
                done += len(chunks[index])
                if progress:
                    _show_progress(done, len(cases), time.perf_counter() - started)
        partial.replace(results)
    finally:
        partial.unlink(missing_ok=True)
        if cluster is not None:
            cluster.close()

    runs = {_label(case): {"time": times, "theta": theta, "omega": omega}
            for case, (theta, omega) in zip(cases, np.concatenate(curves))}
    figure = plot_cases(runs, output_dir / "sweep.png",
                        f"Parameter study: {len(cases)} cases of the torque-driven pendulum")
    return {"results": results, "figure": figure, "cases": len(cases),
            "seconds": time.perf_counter() - started}
