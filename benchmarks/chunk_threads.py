"""Whether pyarrow takes cores a sweep worker does not own.

A chunk's CPU on the calling thread against the whole process's, with pyarrow's thread pools at
their default size and at one.

    .venv/bin/python -m benchmarks.chunk_threads

A dask worker runs one chunk per thread; if writing a chunk's Parquet parts ran pyarrow's pool
on other threads, one "worker" would use more than one core and a cluster's workers would
contend. Prints the CPU per case of each, for 20 chunks of 64 3-s cases.
"""

from __future__ import annotations

import tempfile
import time

import numpy as np
import pyarrow as pa
from fsspec.implementations.local import LocalFileSystem

from pendulum_fmu import default_fmu
from pendulum_fmu.sweep import OUTPUTS
from pendulum_fmu.sweep.store import Store
from pendulum_fmu.sweep.worker import Task, run_chunk

CHUNKS, CASES = 20, 64


def main() -> None:
    values = {"torque": np.linspace(1.0, 40.0, CASES), "gravity": np.full(CASES, 9.81)}
    with tempfile.TemporaryDirectory(prefix="pendulum-chunk-threads-") as folder:
        task = Task(str(default_fmu()), Store(LocalFileSystem(), folder, "parquet"), 3.0, 1e-3, OUTPUTS, 1, "benchmark")
        task.store.start({}, CASES, task.run, task.tables())  # the run's folders and mark, as run_sweep makes them
        run_chunk(0, 0, values, task)  # the FMU unzipped and instantiated once, as on a worker
        for pool in ("default", "one thread"):
            if pool == "one thread":
                pa.set_cpu_count(1)
                pa.set_io_thread_count(1)
            process, thread = time.process_time(), time.thread_time()
            for index in range(CHUNKS):
                run_chunk(index, 0, values, task)
            cases = CHUNKS * CASES
            process = (time.process_time() - process) / cases
            thread = (time.thread_time() - thread) / cases
            print(
                f"pyarrow pool {pool} ({pa.cpu_count()} threads): {process * 1e3:.3f} ms CPU per case "
                f"in the process, {thread * 1e3:.3f} ms on the calling thread, "
                f"{max(process - thread, 0.0) * 1e3:.3f} ms on others"
            )


if __name__ == "__main__":
    main()
