"""sweep.png, drawn from the cases table: every trajectory when there are few, else quantile
bands of the summaries.
"""

from __future__ import annotations

import tempfile
from collections.abc import Sequence
from pathlib import Path

from .._atomic_files import replacing_on
from ..fmu._parameters import unit
from .store import Store

# Up to this many cases the figure draws every trajectory; above, quantile bands of the summaries.
LINES_UP_TO = 20


def draw(store: Store, cases_table, names: list[str], outputs: Sequence[str], fmu: str, target: str) -> None:
    """Write target (on the store's file system) from the cases table and, for few cases with
    theta and omega kept, their trajectories; the axes and labels carry the units fmu declares.
    """
    import pyarrow.dataset as ds

    from ..figures._plot import plot_case_bands, plot_cases  # here: workers never draw, nor import matplotlib

    title = f"Parameter study: {cases_table.num_rows} cases of the torque-driven pendulum"
    units = {name: unit(name, fmu) for name in names}
    with tempfile.TemporaryDirectory(prefix="pendulum_fmu_sweep_") as scratch:
        figure = Path(scratch) / "sweep.png"
        if cases_table.num_rows <= LINES_UP_TO and {"theta", "omega"} <= set(outputs):
            trajectories = ds.dataset(
                f"{store.root}/trajectories", format=store.format, filesystem=store.dataset_filesystem()
            ).to_table()
            case_column = trajectories["case"].to_numpy()
            runs = {}
            for row in cases_table.to_pylist():
                if row["status"] == "ok":
                    rows = case_column == row["case"]
                    label = ", ".join(f"{name} = {row[name]:g} {units[name]}" for name in names)
                    runs[label] = {k: trajectories[k].to_numpy()[rows] for k in ("time", "theta", "omega")}
            plot_cases(runs, figure, title)
        else:
            plot_case_bands(
                {name: cases_table[name].to_numpy() for name in names},
                {
                    "max |theta| in rad": cases_table["max_abs_theta"].to_numpy(),
                    "final theta in rad": cases_table["final_theta"].to_numpy(),
                },
                figure,
                title,
                units,
            )
        with replacing_on(store.filesystem, target) as file:
            file.write(figure.read_bytes())
