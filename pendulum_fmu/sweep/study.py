"""What goes into a sweep and what comes out: Study and SweepResult."""

from __future__ import annotations

import hashlib
import math
import numbers
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._errors import InvalidInput, WrongType
from ..fmu._model import fmu_model
from ..signals._time_grid import communication_points
from .grid import Grid, check_cases, columns

FORMATS = ("parquet", "csv")


class _AllOutputs(tuple):
    """The default of Study's outputs: all of its FMU's, known only once the FMU is read."""

    def __repr__(self) -> str:
        return "<all of the FMU's outputs>"


ALL_OUTPUTS: tuple[str, ...] = _AllOutputs()
# A study is cut into about this many chunks, so that up to 16 workers each get several (the
# load evens out and progress shows), but no chunk holds more than MAX_CHUNK_CASES cases, so a
# lost worker loses little; more only where its cases are short, up to MAX_CHUNK_STEPS steps in
# all (as many as 1,024 3-s cases at 1 ms steps). A chunk costs its worker, the client and the
# scheduler about 5 ms in all whatever its size (python -m benchmarks.case_cost), 0.02 ms per
# case in chunks of 256 3-s cases: a large study's chunks are as large as MAX_CHUNK_BYTES allows
# (888 3-s cases, the whole study 10 % less CPU per case), and 100,000 10-ms cases go in 64
# chunks instead of 391 (python -m benchmarks --only scale).
TARGET_CHUNKS = 64
MAX_CHUNK_CASES = 1024
MAX_CHUNK_STEPS = MAX_CHUNK_CASES * 3000
# And a chunk's recordings (every point of every case, before thinning) stay this small, so a
# chunk's files stay tens of megabytes.
MAX_CHUNK_BYTES = 64_000_000


@dataclass(frozen=True)
class Study:
    """A parameter study: its cases, how each runs, and what is kept of it.

    Checked when made, so a bad study is refused before any cluster starts. Two runs of equal
    studies (and the same FMU) into one folder are one study, which --resume continues.

    Parameters
    ----------
    cases : Grid or sequence of dict
        sweep_grid(...), or a list of {'torque': .., <parameter or start value>: ..} dicts,
        all with the same keys.
    stop_time : float, optional
        End of every case in s (each starts at 0).
    step_size : float, optional
        Communication step in s.
    outputs : sequence of str, optional
        Which of the FMU's outputs (the default FMU's: theta, omega, alpha) the trajectories
        keep (default: all of them); none: only the cases table.
    output_interval : float, optional
        Keep a point every so many s, a whole number of steps (default: every step).
    format : {"parquet", "csv"}, optional
        File format of the tables.
    fmu_path : str or Path, optional
        The FMU every case runs (default: pendulum_fmu.default_fmu()); the workers read it from
        the same path.

    Raises
    ------
    InvalidInput
        Cases that are not all alike, finite and distinct; a stop time or step size that makes
        no run; an unknown or repeated output; an interval that is no whole number of steps; an
        unknown format.
    MissingFile, parameters.FmuFileError
        No file at fmu_path, or none that is a pendulum FMU this machine can run.

    Examples
    --------
    >>> from pendulum_fmu import Study, sweep_grid
    >>> study = Study(sweep_grid([5, 10]), stop_time=0.5, outputs=("theta",))
    >>> study.names, study.points, study.outputs
    (['torque', 'gravity'], 501, ('theta',))
    """

    cases: Grid | Sequence[dict]
    stop_time: float = 3.0
    step_size: float = 1e-3
    outputs: Sequence[str] = ALL_OUTPUTS
    output_interval: float | None = None
    format: str = "parquet"
    fmu_path: str | Path | None = None

    # Worked out from the fields when the study is made.
    names: list[str] = field(init=False, compare=False)  # the cases' keys: the cases table's value columns
    points: int = field(init=False, compare=False)  # communication points of a case, its start included
    stride: int = field(init=False, compare=False)  # keep every stride-th point (and the last)
    # The FMU's outputs, in modelDescription.xml's order: what a worker records of every case,
    # and what outputs chooses among.
    fmu_outputs: tuple[str, ...] = field(init=False, compare=False)

    def __post_init__(self):
        # The study's own FMU, read once here (check_cases reads it too: the same object).
        model = fmu_model(self.fmu_path)
        derived: dict[str, object] = {"names": check_cases(self.cases, model), "fmu_outputs": model.outputs}
        # Refuses a bad stop time or step size with simulate()'s words.
        derived["points"] = len(communication_points(0.0, self.stop_time, self.step_size))
        if isinstance(self.outputs, str):
            raise WrongType(f"outputs is a list of names, e.g. ['theta'], not the string {self.outputs!r}")
        derived["outputs"] = outputs = model.outputs if self.outputs is ALL_OUTPUTS else tuple(self.outputs)
        for name in outputs:
            if name not in model.outputs or outputs.count(name) > 1:
                raise InvalidInput(
                    f"outputs {', '.join(outputs)}: choose each at most once among {', '.join(model.outputs)}"
                )
        derived["stride"] = _stride(self.output_interval, self.step_size)
        if self.format not in FORMATS:
            raise InvalidInput(f"format {self.format!r}: choose {' or '.join(FORMATS)}")
        for name, value in derived.items():
            object.__setattr__(self, name, value)  # frozen: the only way in, once

    def chunk_cases(self) -> int:
        """The cases of a chunk, each chunk written as one part of each table."""
        fitting = MAX_CHUNK_BYTES // (self.points * max(1, len(self.fmu_outputs)) * 8)
        most = max(MAX_CHUNK_CASES, MAX_CHUNK_STEPS // max(1, self.points - 1))
        return max(1, min(most, fitting, math.ceil(len(self.cases) / TARGET_CHUNKS)))

    def definition(self, fmu: str) -> dict:
        """What makes two runs the same study, for --resume (study.json keeps it)."""
        values: dict[str, list] | str
        if isinstance(self.cases, Grid):
            values = {name: axis.tolist() for name, axis in self.cases.axes.items()}
        else:
            table = columns(self.cases, self.names, 0, len(self.cases))
            values = hashlib.sha256(np.stack(list(table.values())).tobytes()).hexdigest()
        with open(fmu, "rb") as file:
            fmu_sha256 = hashlib.file_digest(file, "sha256").hexdigest()
        return {
            "names": self.names,
            "cases": len(self.cases),
            "values": values,
            "stop_time": float(self.stop_time),
            "step_size": float(self.step_size),
            "outputs": list(self.outputs),
            "stride": self.stride,
            "format": self.format,
            "fmu_sha256": fmu_sha256,
        }


def _stride(output_interval: float | None, step_size: float) -> int:
    if output_interval is None:
        return 1
    if not isinstance(output_interval, numbers.Real):
        raise InvalidInput(f"output interval {output_interval!r} must be a number of seconds")
    stride = round(output_interval / step_size) if math.isfinite(output_interval) else 0
    if stride < 1 or abs(stride * step_size - output_interval) > 1e-9 * output_interval:
        raise InvalidInput(f"output interval {output_interval} s must be a whole number of steps of {step_size} s")
    return stride


@dataclass(frozen=True)
class SweepResult:
    """What a sweep wrote, and what it cost.

    Paths are Path objects on the local file system and URLs elsewhere.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from pendulum_fmu import Study, run_sweep, sweep_grid
    >>> folder = Path(tempfile.mkdtemp())
    >>> result = run_sweep(Study(sweep_grid([5, 10]), stop_time=0.1), output_dir=folder, workers=1, progress=False)
    >>> result.cases, result.failed, result.trajectories == folder / "trajectories", result.ran_in
    (2, 0, True, 'cluster')
    """

    output_dir: Path | str
    # A folder of a file per chunk: case, time and the outputs kept; None with no outputs.
    trajectories: Path | str | None
    cases_table: Path | str  # a folder of a file per chunk: a row per case (its values, summaries, status)
    figure: Path | str | None  # sweep.png; None where run_sweep was asked for none
    cases: int
    failed: int  # cases the FMU refused; their status and message are in the cases table
    chunks: int
    chunks_run: int  # by this run; the others were written by an earlier one (resume)
    bytes: int  # written by this run
    seconds: float  # in all
    figure_seconds: float  # of them, reading the cases table and drawing
    worker_cpu_seconds: float  # the workers spent on this run's chunks
    worker_stepping_seconds: float  # of them, running the cases through the FMU
    ran_in: str  # "process" (this one) or "cluster" (dask's: local or at the scheduler's address)
