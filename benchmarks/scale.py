"""Scale: the sweep command's throughput on a local dask cluster, for 3-second cases (1 ms
steps), on 1 and 2 workers, as the grid grows; and what that predicts for larger studies.

End-to-end rates include starting the cluster; the marginal rate between the two largest grids
leaves the start-up out, which is what a large study sees."""

from __future__ import annotations

import tempfile
from pathlib import Path

from pendulum_fmu.sweep import run_sweep, sweep_grid

from .builds import BuiltFmu
from .report import Row

PART = "scale"


def _cases(n: int) -> list[dict]:
    torques = [5.0 + 35.0 * i / max(n // 2 - 1, 1) for i in range(n // 2)]
    return sweep_grid(torques, [0.0, 9.81])


def scale_rows(fmu: BuiltFmu, quick: bool) -> list[Row]:
    grids = (8, 64) if quick else (8, 64, 512)
    rows, seconds, marginal = [], {}, {}
    for workers in (1, 2):
        for n in grids:
            with tempfile.TemporaryDirectory() as out:
                seconds[workers, n] = run_sweep(_cases(n), output_dir=Path(out), workers=workers,
                                                progress=False, fmu_path=fmu.path)["seconds"]
            rows.append(Row(PART, f"{n} cases on {workers} worker(s), end to end",
                            f"{n / seconds[workers, n]:.1f} cases/s"))
        small, large = grids[-2], grids[-1]
        marginal[workers] = (large - small) / (seconds[workers, large] - seconds[workers, small])
        rows.append(Row(PART, f"{workers} worker(s), marginal rate from {small} to {large} cases",
                        f"{marginal[workers]:.1f} cases/s"))
    rows.append(Row(PART, "2 workers / 1 worker, marginal", f"{marginal[2] / marginal[1]:.2f}"))
    per_worker = marginal[2] / 2
    for machines in (1, 16, 128):
        rows.append(Row(PART, f"100,000 cases on {machines} machine(s) of 2 workers (linear prediction)",
                        f"{100_000 / (per_worker * 2 * machines) / 60:.1f} min"))
    return rows
