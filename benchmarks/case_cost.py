"""A sweep's CPU per case over all its processes, against the C loop's: issue 32's targets.

    .venv/bin/python -m benchmarks.case_cost           # also part of --only scale
    .venv/bin/python -m benchmarks.case_cost --quick

A `dask scheduler` and 1 or 2 `dask worker`s (each under its nanny, one thread; QUIET_DASK's
settings) on localhost run
studies of 3-s cases at 1 ms steps from a client process of their own (scale.py's
measure_client, warmed by a small study), with every output written and with none (--outputs
none), of SMALL and 4 x SMALL cases. A study's CPU is summed over every process: the workers with
their nannies, the client, the scheduler. Reported per case, as a multiple of the C loop's (the
same cases through the native loop in one process, a restart per case, nothing written):
- at 4 x SMALL cases, everything included (starting, the figure);
- marginal: what the larger study cost beyond the smaller, per added case, by process: what a
  case costs in a study so large that its fixed costs no longer count (both studies have 64
  chunks, so a chunk's cost is not in it);
- what a chunk costs each process (two studies of one-step cases, 22 and 64 chunks), and from
  all three the CPU per case of a study of a million 3-s cases, in chunks of the size it gets.
The marginal rows also say how much of the workers' CPU was the kernel's (mostly copying the
parts into the page cache), and a row gives what that copy costs this machine now (kernel CPU
per MB written to new files): on a VM it can move by several times from one minute to the next.
And the speed-up of 2 workers over 1, end to end, at each size; and what dask's periodic work
costs an idle cluster of 2 workers, at dask's defaults and at the sweep's settings (QUIET_DASK,
which these clusters run with). Each figure is the least of the
rounds (other work on a shared machine only adds); the machine's load is printed.
"""

from __future__ import annotations

import argparse
import contextlib
import os
from dataclasses import dataclass

from pendulum_fmu.sweep.client import QUIET_DASK

from .builds import BuiltFmu, build_pendulum_fmu
from .chunk_cost import native_loop_cpu
from .report import Row, as_text, main_table
from .scale import _cpu_seconds, _cpu_times, _study, dask_process_handles, study_grid

PART = "scale"
STOP_TIME = 3.0
ALL_OUTPUTS_TARGET = 1.6  # x the C loop's CPU per case (issue 32)
NO_OUTPUTS_TARGET = 1.15
SPEED_UP_TARGET = 1.7  # 2 workers over 1, end to end, on a quiet machine
PROCESSES = ("workers", "client", "scheduler")
IDLE_SECONDS = 10.0
# Two studies of one-step cases, a case per chunk in the smaller, whose difference is what a
# chunk costs each process (a case of one step costs next to nothing; both over 20 cases, so
# that both figures draw bands): the marginal figures leave it out, as both of their studies
# have 64 chunks.
CHUNK_STUDIES, ONE_STEP, CHUNK_REPEATS = (22, 128), 1e-3, 3
LARGE_STUDY = 1_000_000


def chunks(cases: int, stop_time: float) -> tuple[int, int]:
    """(chunks, cases per chunk) of a benchmark study of this many cases."""
    from pendulum_fmu.sweep import Study

    per_chunk = Study(study_grid(cases), stop_time=stop_time).chunk_cases()
    return -(-cases // per_chunk), per_chunk


def idle_cpu(config: dict) -> tuple[float, float]:
    """(the scheduler's, the 2 workers' with their nannies) CPU per second, in % of a core, of a
    cluster that runs nothing, started with these dask settings in its environment: dask's
    periodic work, which a study pays for as long as it runs.
    """
    import time

    with dask_process_handles(2, config=config) as (_, processes):
        time.sleep(2.0)  # past the start
        before = [_cpu_seconds(process.pid) for process in processes]
        time.sleep(IDLE_SECONDS)
        used = [
            (_cpu_seconds(process.pid) - cpu) / IDLE_SECONDS * 100
            for process, cpu in zip(processes, before, strict=True)
        ]
    return used[0], sum(used[1:])


def kernel_write_cpu(megabytes: int = 256) -> float:
    """Kernel CPU seconds per MB written to new files in the temporary folder (the copy into the
    page cache; the disk is written later, by the kernel's own threads). A sweep's workers pay it
    for every byte of their parts. On this project's VM it moved by ten times within an hour
    (likely the host's work for fresh guest pages; not verified).
    """
    import tempfile

    block = os.urandom(1 << 20)
    with tempfile.TemporaryDirectory(prefix="pendulum-kernel-write-") as folder:
        _, before = _cpu_times(os.getpid())
        for index in range(megabytes // 4):
            with open(os.path.join(folder, str(index)), "wb") as out:
                for _ in range(4):
                    out.write(block)
        return (_cpu_times(os.getpid())[1] - before) / megabytes


@dataclass(frozen=True)
class StudyCost:
    """A study's wall time, each process's CPU seconds, and of the workers' those in the kernel."""

    seconds: float
    cpu: dict[str, float]
    workers_kernel: float = 0.0

    def total(self) -> float:
        return sum(self.cpu.values())


def _measured(address: str, processes, cases: int, fmu: BuiltFmu, outputs, stop_time: float = STOP_TIME) -> StudyCost:
    """A study's cost, each process's CPU over the study alone (the client process's start and
    its warm-up study left out).
    """
    result = _study(address, cases, stop_time, fmu, outputs, [process.pid for process in processes])
    scheduler, *workers = result["others_cpu"]
    return StudyCost(
        result["seconds"],
        {"workers": sum(workers), "client": result["cpu"], "scheduler": scheduler},
        sum(result["others_kernel_cpu"][1:]),
    )


def measure(fmu: BuiltFmu, small: int, rounds: int) -> dict:
    """{(workers, outputs label, cases): the round of least CPU (and, apart, of least wall time)}."""
    kinds = {"all outputs": None, "--outputs none": ()}
    sizes = (small, 4 * small)
    costs: dict[tuple, list[StudyCost]] = {}
    with contextlib.ExitStack() as clusters:
        handles = {workers: clusters.enter_context(dask_process_handles(workers)) for workers in (1, 2)}
        # Rounds alternate between every setting, so that a change in the machine's speed falls
        # on all alike.
        for _ in range(rounds):
            for workers, (address, processes) in handles.items():
                for label, outputs in kinds.items():
                    for cases in sizes:
                        cost = _measured(address, processes, cases, fmu, outputs)
                        costs.setdefault((workers, label, cases), []).append(cost)
                for _ in range(CHUNK_REPEATS if workers == 1 else 0):
                    for cases in CHUNK_STUDIES:
                        cost = _measured(address, processes, cases, fmu, None, ONE_STEP)
                        costs.setdefault((workers, "one-step cases", cases), []).append(cost)
    return {
        key: (
            _least_by_process(runs) if "one-step cases" in key else min(runs, key=StudyCost.total),
            min(run.seconds for run in runs),
        )
        for key, runs in costs.items()
    }


def _least_by_process(runs: list[StudyCost]) -> StudyCost:
    """Each process's least CPU over the runs: a chunk's cost is the difference of two studies of
    about a second, which one slow draw of the figure would swamp.
    """
    return StudyCost(min(run.seconds for run in runs), {name: min(run.cpu[name] for run in runs) for name in PROCESSES})


def case_cost_rows(fmu: BuiltFmu, quick: bool) -> list[Row]:
    """The part's rows: CPU per case against the C loop's, at a size and marginal; the speed-up."""
    small, rounds = (1024, 1) if quick else (4096, 2)
    load = os.getloadavg()[0]
    # The smaller study's own cases (the larger's are spread alike): a case's cost depends on its
    # torque, up to a fifth more at the strongest than at the weakest.
    c_loop = native_loop_cpu(str(fmu.path), study_grid(small).columns(0, small), repeats=1)
    kernel_write = kernel_write_cpu()
    measured = measure(fmu, small, rounds)
    large = 4 * small
    rows = [
        Row(PART, "case cost: load average before", f"{load:.1f} (2-core figures need a quiet machine)"),
        Row(PART, "case cost: C loop CPU per 3-s case (native loop, a restart per case)", f"{c_loop * 1e3:.3f} ms"),
        Row(
            PART,
            "case cost: kernel CPU per MB written to new files, before the studies (this machine, now)",
            f"{kernel_write * 1e3:.2f} ms",
        ),
    ]
    for label, target in (("all outputs", ALL_OUTPUTS_TARGET), ("--outputs none", NO_OUTPUTS_TARGET)):
        for workers in (1, 2):
            (big, _), (little, _) = measured[(workers, label, large)], measured[(workers, label, small)]
            at_size = big.total() / large / c_loop
            marginal = {name: (big.cpu[name] - little.cpu[name]) / (large - small) for name in PROCESSES}
            ratio = sum(marginal.values()) / c_loop
            kernel = (big.workers_kernel - little.workers_kernel) / (large - small)
            breakdown = ", ".join(f"{name} {marginal[name] * 1e3:.3f}" for name in PROCESSES)
            breakdown += f"; of the workers', in the kernel {kernel * 1e3:.3f}"
            fixed = ", ".join(f"{name} {little.cpu[name] - marginal[name] * small:.2f}" for name in PROCESSES)
            rows += [
                Row(
                    PART,
                    f"case cost, {label}, {workers} worker(s): CPU per case, all processes, {large} cases",
                    f"{at_size:.2f} x the C loop ({big.total() / large * 1e3:.3f} ms)",
                    f"<= {target:g} x",
                    at_size <= target,
                ),
                Row(
                    PART,
                    f"case cost, {label}, {workers} worker(s): marginal CPU per case ({small} -> {large} cases)",
                    f"{ratio:.2f} x the C loop ({breakdown} ms)",
                    f"<= {target:g} x",
                    ratio <= target,
                ),
                Row(PART, f"case cost, {label}, {workers} worker(s): fixed CPU per study", f"{fixed} s"),
            ]
    (few, _), (many, _) = (measured[(1, "one-step cases", cases)] for cases in CHUNK_STUDIES)
    added_chunks = chunks(CHUNK_STUDIES[1], ONE_STEP)[0] - chunks(CHUNK_STUDIES[0], ONE_STEP)[0]
    per_chunk = {name: (many.cpu[name] - few.cpu[name]) / added_chunks for name in PROCESSES}
    rows.append(
        Row(
            PART,
            f"case cost: CPU per chunk, 1 worker (studies of {CHUNK_STUDIES[0]} and {CHUNK_STUDIES[1]} one-step cases)",
            ", ".join(f"{name} {per_chunk[name] * 1e3:.2f}" for name in PROCESSES) + " ms",
        )
    )
    # A study of LARGE_STUDY 3-s cases: the marginal CPU per case, each chunk's, and the study's
    # fixed cost (the smaller study's, less its chunks').
    (big, _), (little, _) = measured[(1, "all outputs", large)], measured[(1, "all outputs", small)]
    large_chunks, chunk_cases = chunks(LARGE_STUDY, STOP_TIME)
    small_chunks = chunks(small, STOP_TIME)[0]
    marginal = (big.total() - little.total()) / (large - small)
    chunk_cpu = sum(per_chunk.values())
    fixed = little.total() - marginal * small - small_chunks * chunk_cpu
    at_scale = (marginal * LARGE_STUDY + chunk_cpu * large_chunks + fixed) / LARGE_STUDY
    rows.append(
        Row(
            PART,
            f"case cost, all outputs, 1 worker: CPU per case in a study of {LARGE_STUDY:,} 3-s cases "
            f"({large_chunks:,} chunks of {chunk_cases}), estimated",
            f"{at_scale / c_loop:.2f} x the C loop ({at_scale * 1e3:.3f} ms: marginal {marginal * 1e3:.3f}, "
            f"chunks {chunk_cpu / chunk_cases * 1e3:.3f})",
            f"<= {ALL_OUTPUTS_TARGET:g} x",
            at_scale / c_loop <= ALL_OUTPUTS_TARGET,
        )
    )
    for label, config in (("dask's defaults", {}), ("the sweep's settings (QUIET_DASK)", QUIET_DASK)):
        scheduler, workers = idle_cpu(config)
        rows.append(
            Row(
                PART,
                f"case cost: an idle cluster of 2 workers, {label}: CPU, % of a core",
                f"scheduler {scheduler:.1f}, workers with their nannies {workers:.1f}",
            )
        )
    for cases in (small, large):
        (_, one), (_, two) = measured[(1, "all outputs", cases)], measured[(2, "all outputs", cases)]
        rows.append(
            Row(
                PART,
                f"case cost: 2 workers over 1, end to end, {cases} cases, all outputs",
                f"{one / two:.2f} ({one:.2f} s / {two:.2f} s)",
                f">= {SPEED_UP_TARGET:g}",
                one / two >= SPEED_UP_TARGET,
            )
        )
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="1,024 and 4,096 cases, one round")
    args = parser.parse_args()
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory(prefix="pendulum-case-cost-") as scratch:
        print(as_text(main_table(case_cost_rows(build_pendulum_fmu(Path(scratch)), args.quick))))


if __name__ == "__main__":
    main()
