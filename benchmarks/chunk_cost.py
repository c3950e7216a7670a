"""What a sweep worker's CPU per case goes to, in one process, and the Parquet encoding by measurement.

    .venv/bin/python -m benchmarks.chunk_cost

Runs chunks of 64 3-s cases at 1 ms steps through sweep.worker.run_chunk (what a dask worker
runs per chunk: stepping, building and writing the parts) with every output and with none, and
the same cases through the native loop alone, a restart per call (the C loop plus a few
microseconds of ctypes: the floor a case can cost). Then the chunk's trajectories table written
with the store's Parquet options (sweep/store.py parquet_options) and with each alternative
(VARIANTS, one option changed at a time): size and CPU per case, the figures the store's choice
rests on. CPU is this thread's (time.thread_time), the least of 5 rounds; the machine's load is printed, as it slows
every figure.
"""

from __future__ import annotations

import io
import os
import tempfile
import time

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
from fsspec.implementations.local import LocalFileSystem

from pendulum_fmu import default_fmu
from pendulum_fmu.signals._time_grid import communication_points
from pendulum_fmu.sweep import OUTPUTS
from pendulum_fmu.sweep.store import Store, parquet_options
from pendulum_fmu.sweep.worker import Task, _runner, run_chunk

CHUNKS, CASES, STOP_TIME, STEP_SIZE = 10, 64, 3.0, 1e-3
ROUNDS = 5  # each figure the least of this many: other work on a shared machine only adds


def _values() -> dict[str, np.ndarray]:
    return {"torque": np.linspace(1.0, 40.0, CASES), "gravity": np.full(CASES, 9.81)}


def chunk_cpu(outputs: tuple[str, ...]) -> tuple[float, float, float]:
    """(CPU, of which stepping, bytes written) per case of run_chunk, over CHUNKS chunks: the
    round of least CPU.
    """
    rounds = []
    with tempfile.TemporaryDirectory(prefix="pendulum-chunk-cost-") as folder:
        task = Task(
            str(default_fmu()),
            Store(LocalFileSystem(), folder, "parquet"),
            STOP_TIME,
            STEP_SIZE,
            outputs,
            1,
            "benchmark",
        )
        task.store.start({}, CASES, task.run, task.tables())  # the run's folders and mark, as run_sweep makes them
        run_chunk(0, 0, _values(), task)  # the FMU unzipped and instantiated once, as on a worker
        for _ in range(ROUNDS):
            chunks = [run_chunk(index, 0, _values(), task)[3:] for index in range(CHUNKS)]
            written, cpu, stepping = (sum(column) / (CHUNKS * CASES) for column in zip(*chunks, strict=False))
            rounds.append((cpu, stepping, written))
    return min(rounds)


def native_loop_cpu(
    fmu: str | None = None, values: dict[str, np.ndarray] | None = None, repeats: int = CHUNKS
) -> float:
    """CPU per case of the same cases (or those of values, {name: column}) through Stepper.run,
    a restart per call, nothing written, over repeats times the cases.
    """
    runner = _runner(fmu or str(default_fmu()))
    points = communication_points(0.0, STOP_TIME, STEP_SIZE)
    values = _values() if values is None else values
    start_values = runner.start_values(values, len(next(iter(values.values()))))
    outputs = np.empty((len(points), len(OUTPUTS)))
    rounds = []
    for _ in range(ROUNDS):
        started = time.thread_time()
        for _ in range(repeats):
            for case in start_values:
                runner.stepper.run(points, None, None, outputs, start_values=case)
        rounds.append((time.thread_time() - started) / (repeats * len(start_values)))
    return min(rounds)


# The store's Parquet options (sweep/store.py parquet_options), and each alternative measured
# against them: one option changed at a time.
VARIANTS = {
    "the store's: LZ4, byte-stream-split series": {},
    "zstd instead of LZ4": {"compression": "zstd"},
    "no compression": {"compression": "none"},
    "series plain, not byte-stream-split": {"column_encoding": None},
    "no compression, series plain": {"compression": "none", "column_encoding": None},
    "case numbers a dictionary, not plain": {"use_dictionary": ["case"]},
    "statistics on every column": {"write_statistics": True},
    "batches of 1,024 values (pyarrow's)": {"write_batch_size": 1024},
}


def encodings() -> list[tuple[str, float, float]]:
    """(variant, bytes per case, write CPU per case) of a chunk's trajectories table (case, time,
    theta, omega, alpha) written with the store's options and with each of VARIANTS'.
    """
    runner = _runner(str(default_fmu()))
    points = communication_points(0.0, STOP_TIME, STEP_SIZE)
    recorded = np.empty((len(OUTPUTS), CASES, len(points)))
    runner.run_cases(runner.start_values(_values(), CASES), points, recorded)
    table = pa.table(
        {
            "case": np.repeat(np.arange(CASES), len(points)),
            "time": np.tile(points, CASES),
            **{name: recorded[j].reshape(-1) for j, name in enumerate(OUTPUTS)},
        }
    )
    stored = parquet_options(table.column_names, ("time", *OUTPUTS))
    rows = []
    for variant, change in VARIANTS.items():
        cpu = float("inf")
        for _ in range(ROUNDS):
            sink, started = io.BytesIO(), time.thread_time()
            pq.write_table(table, sink, **{**stored, **change})
            cpu = min(cpu, (time.thread_time() - started) / CASES)
        rows.append((variant, sink.tell() / CASES, cpu))
    return rows


def main() -> None:
    print(
        f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}; {CHUNKS} chunks of "
        f"{CASES} 3-s cases at 1 ms, CPU of this thread per case, least of {ROUNDS} rounds"
    )
    floor = native_loop_cpu()
    print(f"native loop alone, a restart per call: {floor * 1e3:.3f} ms")
    for label, outputs in (("all outputs", OUTPUTS), ("--outputs none", ())):
        cpu, stepping, written = chunk_cpu(outputs)
        print(
            f"run_chunk, {label}: {cpu * 1e3:.3f} ms ({stepping * 1e3:.3f} ms stepping), "
            f"{cpu / floor:.2f} x the native loop, {written / 1e3:.1f} kB written"
        )
    print("trajectories part: kB per case, write CPU per case")
    for variant, size, cpu in encodings():
        print(f"  {variant:42} {size / 1e3:6.1f} kB {cpu * 1e3:7.3f} ms")


if __name__ == "__main__":
    main()
