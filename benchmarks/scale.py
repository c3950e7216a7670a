"""Scale: the sweep on a dask cluster of separate processes, as on a real cluster.

`dask scheduler` and N `dask worker` processes (one thread each) run on localhost; a client
process runs the sweep through --scheduler, so its CPU time and peak memory are the client's
alone. Per worker count: 3-second cases at 1 ms steps with all outputs written as Parquet,
end to end (submitting, stepping, writing, the figure) on a cluster that ran a small study
first, as a running cluster has; the median of three rounds that alternate between the worker
counts. Then a study of 100,000 short cases
(10 ms each) for what the client costs per case at scale, and the figure's time from its cases
table. Every figure depends on the machine: the report says which, and its load.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import socket
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path

from pendulum_fmu.sweep.client import QUIET_DASK, dask_environment

from .builds import BuiltFmu
from .report import Row
from .timing import median

PART = "scale"
REPOSITORY = Path(__file__).resolve().parent.parent
CLIENT_CPU_TARGET = 20e-6  # s per case (issue 32)
CLIENT_MEMORY_TARGET = 500e6  # bytes, for 100,000 cases
RATE_TARGET = 1000  # cases/s per worker
EFFICIENCY_TARGET = 0.85
FIGURE_TARGET = 5.0  # s for 100,000 cases
STARTUP_SHARE_TARGET = 0.05  # of a study whose efficiency counts (issue 42)


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


@contextlib.contextmanager
def dask_processes(workers: int):
    """The address of a `dask scheduler` with `workers` single-threaded `dask worker`s, each its
    own process on localhost, started as a user starts them on a cluster (docs/sweeps.md);
    stopped on exit.
    """
    with dask_process_handles(workers) as (address, _):
        yield address


@contextlib.contextmanager
def dask_process_handles(
    workers: int,
    nanny: bool = True,
    host: str = "127.0.0.1",
    places: Sequence[tuple[Sequence[str], str]] = (),
    config: dict = QUIET_DASK,
):
    """(address, [the scheduler's process, each worker's]) of a cluster as dask_processes
    starts it; nanny=False: each worker is the process that runs its tasks (no nanny restarts
    it), for the fault tests to stop or kill. host: the scheduler's (and by default each
    worker's) address; places: each worker's (command prefix, host) instead, e.g. a worker in
    another network namespace, for the fault tests to cut its link. config: the dask settings
    every process gets in its environment (docs/sweeps.md has a user give them; {} for dask's
    defaults).
    """
    from dask.distributed import Client

    port = free_port()
    address = f"tcp://{host}:{port}"
    quiet = dict(stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env={**os.environ, **dask_environment(config)})
    processes = [
        subprocess.Popen(
            [sys.executable, "-m", "dask", "scheduler", "--host", host, "--port", str(port), "--no-dashboard"],
            **quiet,
        )
    ]
    try:
        processes += [
            subprocess.Popen(
                [
                    *prefix,
                    sys.executable,
                    "-m",
                    "dask",
                    "worker",
                    address,
                    "--host",
                    worker_host,
                    "--nthreads",
                    "1",
                    "--no-dashboard",
                    *(() if nanny else ("--no-nanny",)),
                ],
                **quiet,
            )
            for prefix, worker_host in places or [((), host)] * workers
        ]
        with Client(address, timeout=60) as client:
            client.wait_for_workers(workers, timeout=60)
        yield address, processes
    finally:
        for process in reversed(processes):
            if process.poll() is None:
                os.kill(process.pid, signal.SIGCONT)  # a stopped one, to let it end
            process.terminate()
        for process in processes:
            try:
                process.wait(timeout=30)
            except subprocess.TimeoutExpired:  # a nanny slow to stop on a loaded machine
                process.kill()
                process.wait(timeout=30)


def study_grid(cases: int):
    """The cases of a benchmark study: torques evenly from 5 to 40 N.m, gravity 0 and 9.81."""
    import numpy as np

    from pendulum_fmu import sweep

    return sweep.sweep_grid(list(np.linspace(5.0, 40.0, cases // 2)), [0.0, 9.81])


def measure_client(
    address: str,
    cases: int,
    stop_time: float,
    fmu: str,
    output_dir: str,
    outputs: Sequence[str] | None = None,
    others: Sequence[int] = (),
) -> None:
    """Run in the client process: the sweep; prints its figures as JSON. others: the process ids
    whose CPU (with their children's) over the study itself is reported too ("others_cpu"; of
    it in the kernel, "others_kernel_cpu").
    """
    import resource

    from pendulum_fmu import sweep

    grid = study_grid(cases)
    output_dir = f"{output_dir}/study"

    def cpu() -> float:
        usage = resource.getrusage(resource.RUSAGE_SELF)
        return usage.ru_utime + usage.ru_stime

    # A small study first: the workers import the package and unzip the FMU once in their lives,
    # and this process imports what drawing needs; neither is a cost per case. Then the same
    # again, whose seconds are what a study costs besides its cases (connecting, submitting,
    # committing, the figure).
    for name in ("warm-up", "fixed"):
        fixed = sweep.run_sweep(
            sweep.Study(sweep.sweep_grid([1.0, 2.0]), stop_time=0.01, fmu_path=fmu),
            output_dir=f"{output_dir}/{name}",
            scheduler=address,
            progress=False,
        )
    others_before = [_cpu_times(pid) for pid in others]
    before = cpu()
    chosen = {} if outputs is None else {"outputs": outputs}
    result = sweep.run_sweep(
        sweep.Study(grid, stop_time=stop_time, fmu_path=fmu, **chosen),
        output_dir=output_dir,
        scheduler=address,
        progress=False,
    )
    client_cpu = cpu() - before
    others_used = [
        (after[0] - before[0], after[1] - before[1])
        for before, after in zip(others_before, [_cpu_times(pid) for pid in others], strict=True)
    ]
    print(
        json.dumps(
            {
                "seconds": result.seconds,
                "fixed_seconds": fixed.seconds,
                "cpu": client_cpu,
                "figure": result.figure_seconds,
                "bytes": result.bytes,
                "failed": result.failed,
                "chunks": result.chunks,
                "worker_cpu": result.worker_cpu_seconds,
                "worker_stepping": result.worker_stepping_seconds,
                "peak_rss": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024,
                "others_cpu": [sum(used) for used in others_used],
                "others_kernel_cpu": [kernel for _, kernel in others_used],
            }
        )
    )


def simulate_repeatedly(fmu: str, cases: int) -> None:
    """Run in a control process: `cases` 3-second cases through simulate(), no dask, no files."""
    from pendulum_fmu.fmu._simulate import simulate

    for case in range(cases):
        simulate(5.0 + case % 30, stop_time=3.0, fmu_path=fmu)


def _control_speedup(fmu: BuiltFmu, processes: int, cases: int = 200) -> float:
    """How many times one process's rate N plain processes reach together: what the machine
    gives at that moment, the ceiling for N workers.
    """
    import time

    code = f"from benchmarks.scale import simulate_repeatedly; simulate_repeatedly({str(fmu.path)!r}, {cases})"
    seconds = {}
    for count in (1, processes):
        started = time.perf_counter()
        running = [subprocess.Popen([sys.executable, "-c", code], cwd=REPOSITORY) for _ in range(count)]
        if any(process.wait() for process in running):
            raise RuntimeError("a control process failed")
        seconds[count] = time.perf_counter() - started
    return processes * seconds[1] / seconds[processes]


def _study(
    address: str,
    cases: int,
    stop_time: float,
    fmu: BuiltFmu,
    outputs: Sequence[str] | None = None,
    others: Sequence[int] = (),
) -> dict:
    """measure_client's figures of a study run from a client process of its own; outputs: the
    study's (None: the default, every output); others: as measure_client's.
    """
    with tempfile.TemporaryDirectory(prefix="pendulum-scale-") as out:
        code = (
            f"from benchmarks.scale import measure_client; measure_client({address!r}, {cases}, "
            f"{stop_time}, {str(fmu.path)!r}, {out!r}, {None if outputs is None else list(outputs)!r}, "
            f"{list(others)!r})"
        )
        done = subprocess.run([sys.executable, "-c", code], cwd=REPOSITORY, capture_output=True, text=True, check=True)
        result = json.loads(done.stdout.strip().splitlines()[-1])
    if result["failed"]:
        raise RuntimeError(f"{result['failed']} cases failed in the scale benchmark")
    return result


def _load() -> str:
    return (
        f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} before the part "
        f"(other work on the machine slows every figure)"
    )


def _median_study(results: list[dict]) -> dict:
    """Each figure's median over rounds."""
    return {key: median([result[key] for result in results]) for key in results[0]}


def _cpu_times(pid: int) -> tuple[float, float]:
    """(user, kernel) CPU seconds of a process and of its children (a worker's nanny and the
    worker it runs).
    """
    import psutil

    parent = psutil.Process(pid)
    times = [member.cpu_times() for member in (parent, *parent.children(recursive=True))]
    return sum(t.user for t in times), sum(t.system for t in times)


def _cpu_seconds(pid: int) -> float:
    """CPU of a process and of its children, user and kernel."""
    return sum(_cpu_times(pid))


def scale_rows(fmu: BuiltFmu, quick: bool, cases: int | None = None, per_worker: bool = False) -> list[Row]:
    """The part's rows; cases: of each 3-s study (default 1024 quick, else 4096), more where the
    cores are many, so that 16 workers each run more than a few chunks' worth. per_worker: cases
    is per worker instead, each worker count's study as many times larger (every study then lasts
    about as long, and so can be long enough at 16 workers for its start-up not to count
    without taking 16 times as long at 1), and each control process runs as many cases.
    """
    per_count = cases or (1024 if quick else 4096)
    rounds = 1 if quick else 3
    worker_counts = [n for n in (1, 2, 4, 8, 16) if n <= (os.cpu_count() or 1)]
    studies = {workers: per_count * workers if per_worker else per_count for workers in worker_counts}
    rows = [Row(PART, "machine", _load())]
    control_cases = per_count if per_worker else 200
    # Every cluster runs at once and the rounds alternate between them, so that a change in the
    # machine's speed (other jobs on a shared VM) falls on every worker count alike.
    with contextlib.ExitStack() as clusters:
        handles = {workers: clusters.enter_context(dask_process_handles(workers)) for workers in worker_counts}
        runs = {workers: [] for workers in worker_counts}
        for _ in range(rounds):
            for workers, (address, processes) in handles.items():
                scheduler_cpu = _cpu_seconds(processes[0].pid)
                runs[workers].append(_study(address, studies[workers], 3.0, fmu))
                runs[workers][-1]["scheduler_cpu"] = _cpu_seconds(processes[0].pid) - scheduler_cpu
    results = {workers: _median_study(runs[workers]) for workers in worker_counts}
    rates = {workers: studies[workers] / result["seconds"] for workers, result in results.items()}
    # The figure is a fixed cost of a study (about a second), whatever its size or workers.
    running_rates = {
        workers: studies[workers] / (result["seconds"] - result["figure"]) for workers, result in results.items()
    }
    worker_cpu = {workers: result["worker_cpu"] / studies[workers] for workers, result in results.items()}
    for workers, result in results.items():
        cases = studies[workers]
        stepping = result["worker_stepping"] / cases
        label = f"{workers} worker(s), {cases} 3-s cases, median of {rounds}"
        per_worker = rates[workers] / workers
        efficiency = rates[workers] / (workers * rates[1])
        running_efficiency = running_rates[workers] / (workers * running_rates[1])
        per_case_cpu = result["cpu"] / cases
        rows += [
            Row(
                PART,
                f"{label}: cases/s end to end",
                f"{rates[workers]:.0f} ({per_worker:.0f} per worker)",
                f">= {RATE_TARGET} per worker",
                per_worker >= RATE_TARGET,
            ),
            Row(
                PART,
                f"{label}: parallel efficiency",
                f"{efficiency:.0%}",
                f">= {EFFICIENCY_TARGET:.0%}" if workers > 1 else "",
                efficiency >= EFFICIENCY_TARGET if workers > 1 else None,
            ),
            Row(
                PART,
                f"{label}: the same without the figure ({result['figure']:.2f} s): cases/s, efficiency",
                f"{running_rates[workers]:.0f}, {running_efficiency:.0%}",
            ),
            Row(
                PART,
                f"{label}: a 2-case study's seconds on the warm cluster (what a study costs besides "
                "its cases) / this one's",
                f"{result['fixed_seconds'] / result['seconds']:.1%}",
                f"< {STARTUP_SHARE_TARGET:.0%}",
                result["fixed_seconds"] / result["seconds"] < STARTUP_SHARE_TARGET,
            ),
            *(
                [
                    Row(
                        PART,
                        f"control: {workers} plain processes running simulate() (no dask, no files), "
                        f"{control_cases} cases each, speed-up over one",
                        f"{_control_speedup(fmu, workers, control_cases):.2f} of {workers}",
                    )
                ]
                if workers > 1
                else []
            ),
            Row(
                PART,
                f"{label}: worker CPU per case (stepping and writing)",
                f"{worker_cpu[workers] * 1e3:.2f} ms ({stepping * 1e3:.2f} ms of it running the case "
                f"through FMI), so at most {1 / worker_cpu[workers]:.0f} cases/s per core",
                f">= {RATE_TARGET} cases/s",
                1 / worker_cpu[workers] >= RATE_TARGET,
            ),
            *(
                [
                    Row(
                        PART,
                        f"{label}: worker CPU per case at 1 worker / at {workers} (work added by "
                        "workers: none at 100 %)",
                        f"{worker_cpu[1] / worker_cpu[workers]:.0%}",
                    )
                ]
                if workers > 1
                else []
            ),
            Row(PART, f"{label}: client CPU per case (whole run, figure included)", f"{per_case_cpu * 1e6:.0f} µs"),
            Row(PART, f"{label}: scheduler CPU per case", f"{result['scheduler_cpu'] / cases * 1e6:.0f} µs"),
            Row(PART, f"{label}: client peak memory", f"{result['peak_rss'] / 1e6:.0f} MB"),
            Row(PART, f"{label}: bytes written per case", f"{result['bytes'] / cases / 1e3:.1f} kB"),
        ]
    many = 20_000 if quick else 100_000
    workers = worker_counts[-1]
    with dask_processes(workers) as address:
        result = _study(address, many, 0.01, fmu)
    label = f"{many:,} 10-ms cases on {workers} worker(s)"
    rows += [
        Row(PART, f"{label}: cases/s end to end", f"{many / result['seconds']:.0f}"),
        Row(
            PART,
            f"{label}: client CPU per case",
            f"{result['cpu'] / many * 1e6:.0f} µs",
            f"<= {CLIENT_CPU_TARGET * 1e6:.0f} µs",
            result["cpu"] / many <= CLIENT_CPU_TARGET,
        ),
        Row(
            PART,
            f"{label}: client peak memory",
            f"{result['peak_rss'] / 1e6:.0f} MB",
            f"<= {CLIENT_MEMORY_TARGET / 1e6:.0f} MB at 100,000" if many == 100_000 else "",
            result["peak_rss"] <= CLIENT_MEMORY_TARGET if many == 100_000 else None,
        ),
        Row(
            PART,
            f"{label}: figure from the cases table",
            f"{result['figure']:.2f} s",
            f"<= {FIGURE_TARGET:g} s at 100,000" if many == 100_000 else "",
            result["figure"] <= FIGURE_TARGET if many == 100_000 else None,
        ),
    ]
    return rows
