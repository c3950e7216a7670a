"""Where a study runs: in the calling process when it is small, else on a dask cluster.

A local cluster costs a study its start and close (its processes, their imports, TLS: about
1.5 s on two cores) before it saves anything; the calling process needs none of that and steps
the cases itself, through the same run_chunk a worker runs, into the same files, committing each
chunk as the cluster's client does. So a study of fewer steps than BREAK_EVEN_STEPS runs here,
unless it is given a scheduler, a worker count or run_in="cluster".
"""

from __future__ import annotations

from collections.abc import Iterable

from .._errors import InvalidInput
from ..signals._time_grid import BREAK_EVEN_STEPS, RUN_IN
from .client import Totals
from .worker import Task, run_chunk


def runs_here(run_in: str, scheduler: str | None, workers: int | None, steps: int) -> bool:
    """Whether the study's pending work, `steps` in all, runs in the calling process.

    run_in "process" or "cluster" decides; "auto" runs it here when no scheduler and no worker
    count is given (either asks for a cluster) and it has fewer than BREAK_EVEN_STEPS steps.
    """
    if run_in == "process":
        return True
    if run_in == "cluster" or scheduler is not None or workers is not None:
        return False
    return steps < BREAK_EVEN_STEPS


def check_place(run_in: str, scheduler: str | None, workers: int | None, keep_cluster: bool = False) -> None:
    """run_in is one of RUN_IN, "process" comes with no scheduler nor worker count, and
    keep_cluster with no scheduler; else one line.
    """
    if keep_cluster and scheduler is not None:
        raise InvalidInput("keep_cluster keeps a local cluster; a scheduler's cluster is kept by whoever started it")
    if run_in not in RUN_IN:
        raise InvalidInput(f"run_in {run_in!r}: choose {', '.join(RUN_IN)}")
    if run_in == "process" and (scheduler is not None or workers is not None):
        raise InvalidInput(
            "run_in 'process' (--run-in process) runs the study in this process: give it no "
            "scheduler nor workers (--scheduler, --workers)"
        )


def run_chunks_here(task: Task, chunks: Iterable[tuple[int, int, dict]], bar) -> Totals:
    """Run each chunk (its index, the number of its first case, its values) in this thread, as a
    worker would, and commit its parts as the cluster's client does, advancing the bar.

    A Ctrl-C lands between two calls into the native loop; the chunk it cuts leaves only staged
    parts (or a trajectories part without its cases part), which run_sweep removes on the way
    out, so the chunks committed before it stay for --resume.
    """
    totals = Totals()
    for index, first, values in chunks:
        result = run_chunk(index, first, values, task)
        task.store.commit(index, task.run, task.tables())
        totals.add(result, bar)
    if totals.chunks:
        bar.refresh()  # the last count, which a log would otherwise miss
    return totals
