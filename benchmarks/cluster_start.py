"""What a study pays for its local cluster, and of that for its TLS.

One-case studies through run_sweep, each on a local cluster of its own (started, used for one
chunk of 10 steps, closed); then the cluster alone as run_sweep starts it (TLS with certificates
made for the run) against the same cluster on plain TCP (as before issue 38), taking turns; and
the certificates alone:

    .venv/bin/python -m benchmarks.cluster_start

A one-case study's seconds are nearly all the cluster's start and close: the case is 10 steps,
and the figure's seconds are printed apart. The studies' part runs on any checkout (one from
before the local cluster spoke TLS too), so that two can be compared.
"""

from __future__ import annotations

import contextlib
import importlib.util
import os
import tempfile
import time
from pathlib import Path

from pendulum_fmu.sweep import Study, run_sweep, sweep_grid

from .builds import build_pendulum_fmu
from .timing import interleaved, median

STUDIES = 10
WORKERS = 2
CERTIFICATES = 20


def study_seconds(fmu: Path, scratch: Path) -> list[tuple[float, float]]:
    """(seconds in all, of which the figure) of each of STUDIES one-case studies."""
    study = Study(sweep_grid([5.0]), stop_time=0.01, fmu_path=fmu)
    run_sweep(study, output_dir=scratch / "warm", workers=WORKERS, progress=False)  # imports, the FMU unzipped
    seconds = []
    for number in range(STUDIES):
        result = run_sweep(study, output_dir=scratch / f"study-{number}", workers=WORKERS, progress=False)
        seconds.append((result.seconds, result.figure_seconds))
    return seconds


def cluster_seconds() -> dict[str, list[float]]:
    """Seconds of the local cluster's start, one call on each worker, and close: as run_sweep
    starts it, and the same on plain TCP (its certificates replaced by dask's default security),
    taking turns, STUDIES times each.
    """
    from unittest import mock

    from distributed.security import Security

    from pendulum_fmu.sweep.client import dask_client

    def started(plain: bool):
        def run() -> float:
            plain_tcp = mock.patch("pendulum_fmu.sweep.client.run_certificates", Security)
            with plain_tcp if plain else contextlib.nullcontext():
                started = time.perf_counter()
                with dask_client(None, WORKERS, 30.0) as client:
                    assert client.scheduler.address.startswith("tcp://" if plain else "tls://")
                    client.run(os.getpid)
                return time.perf_counter() - started

        return run

    return interleaved({"TLS": started(False), "plain TCP": started(True)}, STUDIES)


def certificate_seconds() -> list[float]:
    """Seconds of each of CERTIFICATES keys and certificates as the local cluster makes them."""
    from distributed.security import Security

    seconds = []
    for _ in range(CERTIFICATES):
        started = time.perf_counter()
        Security.temporary()
        seconds.append(time.perf_counter() - started)
    return seconds


def main() -> None:
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="pendulum-cluster-start-") as scratch:
        fmu = build_pendulum_fmu(Path(scratch)).path
        studies = study_seconds(fmu, Path(scratch))
    whole, without_figure = [s for s, _ in studies], [s - figure for s, figure in studies]
    print(f"{STUDIES} one-case studies, each on a local cluster of {WORKERS} workers (load average {load:.1f} before):")
    print(
        f"  per study: median {median(whole):.2f} s (min {min(whole):.2f}, max {max(whole):.2f}); "
        f"without the figure: median {median(without_figure):.2f} s (min {min(without_figure):.2f})"
    )
    if importlib.util.find_spec("pendulum_fmu.sweep.security") is None:
        return  # a checkout whose local cluster is plain TCP
    clusters = cluster_seconds()
    print(
        f"  the local cluster alone (start, a call on each worker, close), taking turns: TLS median "
        f"{median(clusters['TLS']):.2f} s (min {min(clusters['TLS']):.2f}), plain TCP median "
        f"{median(clusters['plain TCP']):.2f} s (min {min(clusters['plain TCP']):.2f})"
    )
    certificates = certificate_seconds()
    print(
        f"  the run's TLS key and certificate (Security.temporary, {CERTIFICATES} times): median "
        f"{median(certificates) * 1e3:.0f} ms (max {max(certificates) * 1e3:.0f} ms)"
    )


if __name__ == "__main__":
    main()
