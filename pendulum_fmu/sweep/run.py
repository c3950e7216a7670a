"""run_sweep: a study run on dask into an output folder, top to bottom."""

from __future__ import annotations

import math
import numbers
import os
import time
from pathlib import Path

import numpy as np

from .. import default_fmu
from ..errors import InvalidInput, MissingDependency
from ..parameters import pendulum_variables
from .client import dask_client, progress_bar, run_chunks
from .figure import draw
from .grid import columns
from .store import Store
from .study import Study, SweepResult
from .worker import Task

# A study larger than this is refused unless asked for (max_cases, --max-cases): at a
# millisecond a case it is a quarter of an hour on 1,000 cores, and a grid multiplied out by a
# stray value list is likelier than a study that large.
DEFAULT_MAX_CASES = 1_000_000


def run_sweep(study: Study, *, output_dir: str | os.PathLike, resume: bool = False,
              scheduler: str | None = None, workers: int | None = None,
              connect_timeout: float = 10.0, progress: bool = True,
              max_cases: int = DEFAULT_MAX_CASES) -> SweepResult:
    """Run every case of a study on dask; the workers write it into output_dir.

    output_dir receives study.json, trajectories/ and cases/ (a Parquet or CSV file per chunk of
    cases) and sweep.png; see the package's doc. A case the FMU refuses is recorded with its
    message in the cases table, and the others go on.

    Parameters
    ----------
    study : Study
        The cases, their times and outputs, the FMU.
    output_dir : str or os.PathLike
        A local folder, or an fsspec URL (s3://..., a shared file system), that every worker can
        write to.
    resume : bool, optional
        Run only the chunks a previous run of the same study into output_dir did not finish.
        Without it, a new study replaces whatever study output_dir held.
    scheduler : str, optional
        The address of a running dask.distributed scheduler. Without one a local cluster of
        `workers` processes runs for this call; its workers are spawned, so a script calling
        this needs the ``if __name__ == "__main__":`` guard.
    workers : int, optional
        Processes of the local cluster (default 2).
    connect_timeout : float, optional
        Seconds the scheduler has to answer.
    progress : bool, optional
        Show a progress line on stderr.
    max_cases : int, optional
        The largest study accepted.

    Returns
    -------
    SweepResult
        Where the tables and the figure are, the counts of cases (failed ones included) and
        chunks, and the time and bytes the run took.

    Raises
    ------
    InvalidInput
        More cases than max_cases, workers with a scheduler, a bad workers count or connect
        timeout, or an output_dir that holds a different study on resume; all before anything
        starts.
    MissingFile, parameters.FmuFileError
        No file at the study's FMU, or none that is a pendulum FMU this machine can run.
    InUse
        Another run is writing into the same local output_dir.
    CannotWrite
        output_dir cannot be written.
    SchedulerUnreachable
        The scheduler did not answer within connect_timeout.
    """
    from fsspec.implementations.local import LocalFileSystem

    started = time.perf_counter()
    if not isinstance(study, Study):
        raise TypeError(f"run_sweep takes a Study(cases, ...), not a {type(study).__name__}")
    cases = study.cases
    _check_options(len(cases), max_cases, scheduler, workers, connect_timeout)
    url = str(output_dir)
    store = Store(*_file_system(url), format=study.format)
    fmu = str(Path(study.fmu_path).resolve() if study.fmu_path else default_fmu())
    pendulum_variables(fmu)  # a missing file, or none that is a pendulum FMU, refused before anything starts
    task = Task(fmu=fmu, store=store, stop_time=float(study.stop_time),
                step_size=float(study.step_size), outputs=study.outputs, stride=study.stride)
    # The folder taken first, so that a second run is refused before it starts a cluster; then
    # connected, so that a scheduler that does not answer leaves the study untouched.
    with store.only_run(url):
        try:
            with dask_client(scheduler, workers, connect_timeout) as client:
                chunk_cases = store.prepare(study.definition(fmu), resume, study.chunk_cases(), url)
                chunks = range(math.ceil(len(cases) / chunk_cases))
                done = store.done_chunks()
                pending = [index for index in chunks if index not in done]
                finished = sum(min(chunk_cases, len(cases) - i * chunk_cases) for i in done)
                with progress_bar(len(cases), finished, progress) as bar:
                    totals = run_chunks(client, task, (
                        (index, index * chunk_cases,
                         columns(cases, study.names, index * chunk_cases,
                                 min(len(cases), (index + 1) * chunk_cases)))
                        for index in pending), bar)
        finally:
            # After a local cluster closed, so that none of its workers writes any more (a remote
            # cluster's may still finish the chunk they were running).
            store.remove_unfinished()
    drawing = time.perf_counter()
    table = store.read_cases(study.names)
    draw(store, table, study.names, study.outputs, fmu, f"{store.root}/sweep.png")
    drawn = time.perf_counter()
    # Paths on the local file system, URLs elsewhere.
    where = (Path(store.root).joinpath if isinstance(store.filesystem, LocalFileSystem)
             else f"{url.rstrip('/')}/".__add__)
    return SweepResult(
        output_dir=where(""), trajectories=where("trajectories"), cases_table=where("cases"),
        figure=where("sweep.png"), cases=len(cases),
        failed=int(np.sum(table["status"].to_numpy(zero_copy_only=False) == "failed")),
        chunks=len(chunks), chunks_run=len(pending), bytes=totals.bytes,
        seconds=drawn - started, figure_seconds=drawn - drawing,
        worker_cpu_seconds=totals.worker_cpu_seconds,
        worker_stepping_seconds=totals.worker_stepping_seconds)


def _check_options(count: int, max_cases: int, scheduler: str | None, workers: int | None,
                   connect_timeout: float) -> None:
    if count > max_cases:
        raise InvalidInput(f"{count:,} cases is over the limit of {max_cases:,}: give fewer "
                           "values, or raise the limit (--max-cases) if the study is meant to be "
                           "that large")
    if scheduler is not None and workers is not None:
        raise InvalidInput("workers sizes the local cluster; with a scheduler the cluster has its own")
    if workers is not None and (not isinstance(workers, numbers.Integral) or workers < 1):
        raise InvalidInput(f"workers must be a positive integer, got {workers!r}")
    if not (isinstance(connect_timeout, numbers.Real) and 0 < connect_timeout < math.inf):
        raise InvalidInput(f"connect timeout {connect_timeout} must be a positive number of seconds")


def _file_system(url: str) -> tuple[object, str]:
    """(fsspec file system, the folder's path on it) of an output directory."""
    import fsspec

    try:
        filesystem, root = fsspec.core.url_to_fs(url)
    except ImportError as error:  # "Install s3fs to access S3"
        raise MissingDependency(f"output directory {url}: {error}") from None
    except ValueError as error:  # "Protocol not known: ..."
        raise InvalidInput(f"output directory {url}: {error}") from None
    return filesystem, root.rstrip("/")
