"""run_sweep: a study run on dask into an output folder, top to bottom."""

from __future__ import annotations

import contextlib
import math
import numbers
import os
import time
import uuid
from concurrent.futures import CancelledError
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .._atomic_files import LocalFolders, is_local
from .._errors import InvalidInput, MissingDependency, WrongType
from ..fmu._model import fmu_file
from ..fmu._parameters import pendulum_variables
from ..signals._time_grid import DEFAULT_MAX_CASES
from .client import SchedulerLost, Totals, dask_client, progress_bar, run_chunks
from .figure import draw
from .grid import columns
from .here import check_place, run_chunks_here, runs_here
from .store import Store, StudyExists
from .study import Study, SweepResult
from .worker import Task

if TYPE_CHECKING:
    from distributed.security import Security


def run_sweep(
    study: Study,
    *,
    output_dir: str | os.PathLike,
    resume: bool = False,
    overwrite: bool = False,
    scheduler: str | None = None,
    workers: int | None = None,
    connect_timeout: float = 10.0,
    progress: bool = True,
    max_cases: int = DEFAULT_MAX_CASES,
    security: Security | None = None,
    run_in: str = "auto",
    keep_cluster: bool = False,
    figure: bool = True,
) -> SweepResult:
    """Run every case of a study, on dask or, when it is small, in this process, into output_dir.

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
    overwrite : bool, optional
        Replace the study output_dir holds. The new study is written beside it, inside
        output_dir, and takes its place only once it is whole: until then, and if the run stops,
        the old study stays as it was. Without resume or overwrite, a folder that holds a study,
        finished or not, is refused.
    scheduler : str, optional
        The address of a running dask.distributed scheduler. Without one, a study of fewer than
        here.BREAK_EVEN_STEPS steps in all runs in this process, and a larger one on a local
        cluster of `workers` processes started for this call; its workers are spawned, so a
        script calling this needs the ``if __name__ == "__main__":`` guard.
    workers : int, optional
        Processes of the local cluster (default 2); given, the study runs on one whatever its size.
    connect_timeout : float, optional
        Seconds the scheduler has to answer.
    progress : bool, optional
        Show a progress line on stderr.
    max_cases : int, optional
        The largest study accepted.
    security : distributed.security.Security, optional
        How the client connects to the scheduler: for a tls:// one, its CA certificate and the
        client's certificate and key, e.g. security.tls_files(ca_file, cert, key). Without it,
        dask's configuration's (distributed.comm.tls.*). The local cluster makes its own, which
        only this run holds.
    run_in : {"auto", "process", "cluster"}, optional
        Where the study runs: "auto" in this process when it has fewer than
        here.BREAK_EVEN_STEPS steps still to run and neither scheduler nor workers is given,
        else on dask; "process" in this process whatever its size; "cluster" on dask (a local
        cluster without a scheduler) whatever its size. The files are the same either way, and
        either resumes what the other began.
    keep_cluster : bool, optional
        Keep the local cluster this study starts (or one an earlier study kept, of as many
        workers) for the next studies of this process, instead of closing it: a notebook running
        many studies on a cluster pays its start once. Closed when the process exits, by
        close_kept_clusters(), or when a study on it stops (Ctrl-C, an error).
    figure : bool, optional
        Draw sweep.png. Without it a small study costs about half as much (matplotlib's import
        and the drawing are most of what it costs in a process of its own).

    Returns
    -------
    SweepResult
        Where the tables and the figure are, the counts of cases (failed ones included) and
        chunks, and the time and bytes the run took.

    Raises
    ------
    InvalidInput
        More cases than max_cases, workers with a scheduler, security without one, a bad workers
        count or connect timeout, resume and overwrite together, an unknown run_in or "process"
        with a scheduler or workers, keep_cluster with a scheduler, or TLS files that are no
        certificates; all before anything starts.
    StudyExists
        output_dir holds a study and neither resume (for the same study) nor overwrite was
        given; before anything starts.
    MissingFile, parameters.FmuFileError
        No file at the study's FMU, or none that is a pendulum FMU this machine can run; no file
        at a TLS file's path.
    InUse
        Another run is writing into the same local output_dir.
    CannotWrite
        output_dir cannot be written.
    SchedulerUnreachable
        The scheduler did not answer within connect_timeout, or refused the TLS handshake.

    Warns
    -----
    UnencryptedScheduler
        A plain tcp:// scheduler off the loopback: whoever reaches it runs code on its workers.

    Examples
    --------
    >>> import tempfile
    >>> from pendulum_fmu import Study, run_sweep, sweep_grid
    >>> study = Study(sweep_grid([5, 10], [0, 9.81]), stop_time=0.5)
    >>> result = run_sweep(study, output_dir=tempfile.mkdtemp(), workers=1, progress=False)
    >>> result.cases, result.failed, result.chunks_run == result.chunks
    (4, 0, True)
    """
    started = time.perf_counter()
    if not isinstance(study, Study):
        raise WrongType(f"run_sweep takes a Study(cases, ...), not a {type(study).__name__}")
    if not isinstance(output_dir, str | os.PathLike):
        raise WrongType(f"output_dir is a folder's path or an fsspec URL, not {output_dir!r}")
    _check_options(len(study.cases), max_cases, scheduler, workers, connect_timeout, resume, overwrite, security)
    check_place(run_in, scheduler, workers, keep_cluster)
    url = str(output_dir)
    target = Store(*_file_system(url), format=study.format)
    fmu = str(fmu_file(study.fmu_path).resolve())
    pendulum_variables(fmu)  # a missing file, or none that is a pendulum FMU, refused before anything starts
    definition = study.definition(fmu)
    # The folder taken first, so that a second run is refused before it starts a cluster; then
    # connected, so that a scheduler that does not answer leaves the study untouched.
    with target.only_run(url):
        # What no run owns now (the staged parts of a worker of an earlier run that wrote after
        # its run ended, temporaries of writes cut short) goes before the folder is read.
        target.remove_unfinished()
        chunk_cases = _chunk_cases(target, definition, study, resume, overwrite, url)
        # A study that replaces another is written apart and moved into place once whole.
        store = target.staging() if overwrite else target
        # This run's token: only parts staged under it are committed (see store.py).
        task = Task(
            fmu=fmu,
            store=store,
            stop_time=float(study.stop_time),
            step_size=float(study.step_size),
            outputs=tuple(study.outputs),
            stride=study.stride,
            run=uuid.uuid4().hex,
        )
        pending = _pending_cases(store, len(study.cases), chunk_cases)
        here = runs_here(run_in, scheduler, workers, sum(pending.values()) * (study.points - 1))
        try:
            try:
                with (
                    contextlib.nullcontext()
                    if here
                    else dask_client(scheduler, workers, connect_timeout, security, keep_cluster) as client
                ):
                    store.start(definition, chunk_cases, task.run, task.tables())
                    try:
                        totals = _run_pending(client, task, study, chunk_cases, pending, progress)
                    except CancelledError as error:  # this run cancels none: the cluster did
                        raise _lost(scheduler, error, url, overwrite) from None
            finally:
                # After a local cluster closed, so that none of its workers writes any more (a
                # remote cluster's may still finish the chunk they were running).
                store.remove_unfinished()
            drawing = time.perf_counter()
            table = store.read_cases(study.names)
            if figure:
                draw(store, table, study.names, study.outputs, fmu, f"{store.root}/sweep.png")
            drawn = time.perf_counter()
            if store is not target:
                target.replace_with(store)
        except BaseException:
            if store is not target:
                store.discard()
            raise
    where = _locate(target, url)
    return SweepResult(
        output_dir=where(""),
        trajectories=where("trajectories") if study.outputs else None,
        cases_table=where("cases"),
        figure=where("sweep.png") if figure else None,
        cases=len(study.cases),
        failed=int(np.sum(table["status"].to_numpy(zero_copy_only=False) == "failed")),
        chunks=math.ceil(len(study.cases) / chunk_cases),
        chunks_run=len(pending),
        bytes=totals.bytes,
        seconds=time.perf_counter() - started,
        figure_seconds=drawn - drawing,
        worker_cpu_seconds=totals.worker_cpu_seconds,
        worker_stepping_seconds=totals.worker_stepping_seconds,
        ran_in="process" if here else "cluster",
    )


def _pending_cases(store: Store, cases: int, chunk_cases: int) -> dict[int, int]:
    """{index: cases} of the study's chunks that the store does not hold done."""
    done = store.done_chunks()
    return {
        index: min(chunk_cases, cases - index * chunk_cases)
        for index in range(math.ceil(cases / chunk_cases))
        if index not in done
    }


def _run_pending(client, task: Task, study: Study, chunk_cases: int, pending: dict[int, int], progress: bool) -> Totals:
    """Run, with the progress line, the pending chunks of the study: on the dask client's
    cluster, or in this process where client is None.
    """
    cases = study.cases
    values = (
        (index, index * chunk_cases, columns(cases, study.names, index * chunk_cases, index * chunk_cases + count))
        for index, count in pending.items()
    )
    with progress_bar(len(cases), len(cases) - sum(pending.values()), progress) as bar:
        if client is None:
            return run_chunks_here(task, values, bar)
        return run_chunks(client, task, values, bar)


def _locate(target: Store, url: str):
    """Where a path inside the output folder is: a Path on the local file system, a URL elsewhere."""
    if is_local(target.filesystem):
        return Path(target.root).joinpath
    return f"{url.rstrip('/')}/".__add__


def _lost(scheduler: str | None, error: CancelledError, url: str, overwrite: bool) -> SchedulerLost:
    """The one line for a scheduler lost mid-study: what the folder keeps, and how to go on."""
    which = f"the dask scheduler at {scheduler}" if scheduler else "the local dask cluster's scheduler"
    # dask's cancellation gives its reason apart; run_chunks' (the results unreachable) as its text.
    reason = getattr(error, "reason", None) or str(error) or "its work was cancelled"
    if overwrite:
        kept = (
            f"{url} holds what it held before (the new study was not finished and is not "
            "kept): start a scheduler and run the same command again"
        )
    else:
        kept = (
            f"the chunks that finished are kept in {url}: start a scheduler and run the same "
            "command with --resume to run the rest"
        )
    return SchedulerLost(f"{which} was lost mid-study ({reason}); {kept}")


def _chunk_cases(target: Store, definition: dict, study: Study, resume: bool, overwrite: bool, output_dir: str) -> int:
    """The cases per chunk of this run: the study's own, or on resume those of the run it
    continues. StudyExists where the run would replace a study without being asked to.
    """
    if overwrite:  # what the folder holds is not read: it goes
        return study.chunk_cases()
    held = target.held()
    if not held.entries:
        return study.chunk_cases()
    if held.manifest is None:
        raise StudyExists(
            f"{output_dir} holds {', '.join(held.entries)} but no study.json of a sweep: choose "
            "another output directory, or add --overwrite to replace them (--resume continues "
            "only a study a sweep wrote)"
        )
    previous = held.manifest["study"]
    differences = [key for key in definition if previous.get(key) != definition[key]]
    progress = f"{held.done_chunks} of {held.chunks()} chunks written"
    if differences:
        raise StudyExists(
            f"{output_dir} holds another study ({', '.join(differences)} differ; {progress}): "
            "choose another output directory, or add --overwrite to replace it once the new one "
            "is whole (--resume continues only the same study)"
        )
    if not resume and held.done_chunks == held.chunks():
        raise StudyExists(
            f"{output_dir} already holds this study, finished ({progress}): nothing to run; add "
            "--overwrite to run it again and replace it once the new one is whole (--resume only "
            "draws its figure again)"
        )
    if not resume:
        raise StudyExists(
            f"{output_dir} already holds this study, unfinished ({progress}): add --resume to run "
            "only the chunks not written, or --overwrite to run it all again and replace it once "
            "the new one is whole"
        )
    return held.manifest["chunk_cases"]


def _check_options(
    count: int,
    max_cases: int,
    scheduler: str | None,
    workers: int | None,
    connect_timeout: float,
    resume: bool,
    overwrite: bool,
    security: Security | None,
) -> None:
    if count > max_cases:
        raise InvalidInput(
            f"{count:,} cases is over the limit of {max_cases:,}: give fewer "
            "values, or raise the limit (--max-cases) if the study is meant to be "
            "that large"
        )
    if scheduler is not None and workers is not None:
        raise InvalidInput("workers sizes the local cluster; with a scheduler the cluster has its own")
    if scheduler is None and security is not None:
        raise InvalidInput("security is for a scheduler's address; the local cluster makes certificates of its own")
    if workers is not None and (not isinstance(workers, numbers.Integral) or workers < 1):
        raise InvalidInput(f"workers must be a positive integer, got {workers!r}")
    if not (isinstance(connect_timeout, numbers.Real) and 0 < connect_timeout < math.inf):
        raise InvalidInput(f"connect timeout {connect_timeout} must be a positive number of seconds")
    if resume and overwrite:
        raise InvalidInput(
            "resume continues the study the output directory holds and overwrite replaces it: choose one"
        )


def _file_system(url: str) -> tuple[object, str]:
    """(fsspec file system, the folder's path on it) of an output directory; LocalFolders for a
    POSIX path, whose path is the one fsspec's LocalFileSystem makes of it.
    """
    if os.sep == "/" and ":" not in url and not url.startswith("~"):
        # fsspec's make_path_posix: an absolute path as it is; a relative one after the working
        # folder, one leading "./" (or "." alone) left out.
        path = url if url.startswith("/") else f"{os.getcwd()}/{'' if url == '.' else url.removeprefix('./')}"
        return LocalFolders(), path.rstrip("/")
    import fsspec

    try:
        filesystem, root = fsspec.core.url_to_fs(url)
    except ImportError as error:  # "Install s3fs to access S3"
        raise MissingDependency(f"output directory {url}: {error}") from None
    except ValueError as error:  # "Protocol not known: ..."
        raise InvalidInput(f"output directory {url}: {error}") from None
    return filesystem, root.rstrip("/")
