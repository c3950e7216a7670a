"""What the sweep's client costs per case at scale, as one paragraph for docs/sweeps.md.

Its wording is TEMPLATE, to which tests/readme_figures.py holds the page:

    .venv/bin/python -m benchmarks.client_cost

A `dask scheduler` and two `dask worker`s on localhost, warmed by a small study, run 100,000
cases of 10 ms (10 steps each) from a client process through --scheduler, as the scale part
does (benchmarks/scale.py): short cases, so that what the client and the scheduler spend per case
shows rather than the simulation. CPU time per case of each process; the paragraph says when and
on what machine, and how loaded it was.
"""

from __future__ import annotations

import datetime
import os
import textwrap

from .builds import build_pendulum_fmu
from .report import cpu_model
from .scale import _cpu_seconds, _study, dask_process_handles

CASES = 100_000
WORKERS = 2

TEMPLATE = (
    "Measured by `.venv/bin/python -m benchmarks.client_cost` on {date} ({machine}, load average "
    "{load} before): {cases} cases of 10 ms on {workers} workers, in {chunks} chunks, ran at "
    "{rate} cases/s end to end. CPU per case: the client {client_us} µs (the figure included, "
    "which took {figure_s} s), the scheduler {scheduler_us} µs, the workers {worker_us} µs; "
    "the client's memory peaked at {peak_mb} MB."
)


def measure(fmu) -> dict:
    """The figures of TEMPLATE."""
    load = os.getloadavg()[0]
    with dask_process_handles(WORKERS) as (address, processes):
        scheduler_cpu = _cpu_seconds(processes[0].pid)
        result = _study(address, CASES, 0.01, fmu)
        scheduler_cpu = _cpu_seconds(processes[0].pid) - scheduler_cpu
    return {
        "date": datetime.date.today().isoformat(),
        "machine": f"{cpu_model()}, {os.cpu_count()} cores",
        "load": f"{load:.1f}",
        "cases": f"{CASES:,}",
        "workers": WORKERS,
        "chunks": result["chunks"],
        "rate": f"{CASES / result['seconds']:,.0f}",
        "client_us": f"{result['cpu'] / CASES * 1e6:.1f}",
        "figure_s": f"{result['figure']:.2f}",
        "scheduler_us": f"{scheduler_cpu / CASES * 1e6:.1f}",
        "worker_us": f"{result['worker_cpu'] / CASES * 1e6:.1f}",
        "peak_mb": f"{result['peak_rss'] / 1e6:.0f}",
    }


def main() -> None:
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory(prefix="pendulum-client-cost-") as scratch:
        fmu = build_pendulum_fmu(Path(scratch))
        print(textwrap.fill(TEMPLATE.format(**measure(fmu)), width=98, break_long_words=False, break_on_hyphens=False))


if __name__ == "__main__":
    main()
