"""Parameter studies on dask.distributed: workers simulate chunks of cases and write them (a
small study's chunks the calling process runs itself, here.py).

    from pendulum_fmu.sweep import Study, run_sweep, sweep_grid

    result = run_sweep(Study(sweep_grid([5, 10, 20], [0, 9.81]), stop_time=3.0), output_dir="study")

A study goes to an output directory, a local path or any fsspec URL every worker can write to
(a shared file system, s3://, gs://, ...):

    study.json                        what the study is (cases, times, outputs, chunking)
    trajectories/part-000000.parquet  per chunk: case, time and the chosen outputs at each kept
                                      communication point
    cases/part-000000.parquet         per chunk, one row per case: case, its values, final_theta,
                                      final_omega, final_alpha, max_abs_theta, status ("ok" or
                                      "failed") and message (why the FMU refused the case)
    sweep.png                         the figure (unless run_sweep is asked for none)
    .sweep.lock                       there while a run writes a local folder: a second run is refused
    */_part-000000.<run>.staged       a chunk's part as its worker wrote it, before the run's client
                                      moves it into place: hidden from the readers, removed when
                                      the run ends, and never taken from another run (see store.py)

With format "csv" the same files are CSV. One line of pyarrow reads either table, e.g.
pyarrow.parquet.read_table("out/trajectories"); pandas, dask.dataframe and DuckDB read the same
folders where they are installed (the package does not bring them).

A folder that holds a study is refused unless the run continues it (resume) or replaces it
(overwrite): the replacing study is written into .overwrite.<id>.partial/ inside the folder and
moved into place once whole.

The package, in the order a run goes through it:

    study.py   Study, what goes in (the cases, times, outputs, FMU), and SweepResult, what comes out
    grid.py    the cases: sweep_grid's every combination, or a list of dicts, checked
    run.py     run_sweep: the folder locked, the chunks run (on dask, or here), the figure drawn
    here.py    where a study runs: a small one in the calling process, chunk by chunk
    client.py  the dask client, the chunks submitted and gathered, the progress line
    security.py  who can reach the cluster: the local cluster's certificates, the client's TLS
    worker.py  a chunk on a worker: its cases through the native loop, its two parts written
    store.py   the output folder: study.json, the parts, the lock, the cases table read back
    figure.py  sweep.png from the cases table

May import: figures/, fmu/, signals/ and the basics.
"""

from .client import close_kept_clusters
from .grid import Grid, sweep_grid
from .run import DEFAULT_MAX_CASES, run_sweep
from .security import tls_files
from .study import FORMATS, Study, SweepResult


def __getattr__(name: str):
    # OUTPUTS: the default FMU's outputs (a Study's default outputs on it), read from its model
    # description on first use, not at import; a Study on another FMU takes that FMU's.
    if name == "OUTPUTS":
        from ..fmu._model import fmu_model

        return fmu_model().outputs
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "DEFAULT_MAX_CASES",
    "FORMATS",
    "OUTPUTS",
    "Grid",
    "Study",
    "SweepResult",
    "close_kept_clusters",
    "run_sweep",
    "sweep_grid",
    "tls_files",
]
