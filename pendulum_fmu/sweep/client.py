"""The study's side of dask: a client on a local cluster or a scheduler, the chunks submitted and
gathered as they finish, and the progress line.

The client never holds a trajectory: a chunk's worker writes it, and what comes back is counts.
So the client's memory and its work per case stay small however large the study.
"""

from __future__ import annotations

import atexit
import contextlib
import logging
import numbers
import queue
import re
import signal
import ssl
import threading
import time
from collections.abc import Iterable
from concurrent.futures import CancelledError
from dataclasses import dataclass
from typing import Any

from .._errors import InvalidInput, PendulumFmuError
from .._progress_bar import progress_bar as shown_bar
from .security import client_security, run_certificates
from .worker import Task, run_chunk

# dask's periodic work, for a local cluster: at dask's defaults its scheduler, nannies and
# workers wake every 10 to 100 ms (an event-loop watchdog, the dashboard's profile and system
# plots, memory checks), 10 to 12 % of a core for an idle cluster of two workers, 1.5 to 2.4 %
# at these (python -m benchmarks.case_cost). Nothing a sweep uses changes: the dashboard's
# profile page stays empty, its plots are coarser, a worker over its memory limit is stopped
# within 1 s instead of 0.1 s. docs/sweeps.md gives them to workers started by hand
# (dask_environment).
QUIET_DASK = {
    "distributed.admin.tick.interval": "200ms",
    "distributed.admin.system-monitor.interval": "2s",
    "distributed.worker.profile.enabled": False,
    "distributed.worker.memory.monitor-interval": "1s",
}


def dask_environment(config: dict) -> dict[str, str]:
    """The environment variables that give a dask process these settings."""
    return {f"DASK_{key.upper().replace('.', '__').replace('-', '_')}": str(value) for key, value in config.items()}


class SchedulerUnreachable(PendulumFmuError, ConnectionError):
    """The dask scheduler did not answer; the message names the address."""


class SchedulerLost(PendulumFmuError, ConnectionError):
    """The dask scheduler went away while the study ran (killed, its host lost); the message
    says what the output folder keeps and names --resume.
    """


@contextlib.contextmanager
def dask_client(scheduler: str | None, workers: int | None, connect_timeout: float, security=None, keep=False):
    """A dask client: on a local cluster of `workers` processes started (and closed) here, or
    kept for the next study in the process where keep (see kept_client), which only holders of
    its run's certificates can reach (security.py); or on the scheduler at an address,
    connecting with security (a distributed.security.Security; None: dask's configuration's),
    refused within connect_timeout when it does not answer.
    """
    from dask.distributed import Client

    if scheduler is None and keep:
        with kept_client(workers or 2) as client:
            yield client
        return
    if scheduler is None:
        with contextlib.ExitStack() as stack:
            cluster = _local_cluster(stack, workers or 2)
            # A Ctrl-C held while the cluster started is raised here, and the stack closes it.
            yield stack.enter_context(Client(cluster))  # with the cluster's security
        return
    security = client_security(scheduler, security)
    reason = _why_no_scheduler(scheduler, connect_timeout, security)
    if reason is None:
        try:
            client = Client(scheduler, timeout=connect_timeout, security=security)
        except Exception as error:
            reason = _first_line(error)
    if reason is not None and reason.startswith(TLS_REFUSED):
        raise SchedulerUnreachable(
            f"{reason} with the dask scheduler at {scheduler}; give the CA file that signed its "
            "certificate (--tls-ca-file) and a client certificate and key its CA signed (--tls-cert, --tls-key)"
        )
    if reason is not None:
        raise SchedulerUnreachable(
            f"no dask scheduler answered at {scheduler} within {connect_timeout:g} s"
            f"{f' ({reason})' if reason else ''}; check the address (start one with `dask "
            "scheduler`), raise --connect-timeout, or leave out --scheduler for a local cluster"
        )
    with _quiet(logging.getLogger("distributed.client")), client:
        yield client


# The local clusters kept for the next studies of this process, by their workers: each one's
# client, and the stack that closes the two.
_kept: dict[int, tuple[Any, contextlib.ExitStack]] = {}  # a distributed.Client, not imported here


@contextlib.contextmanager
def kept_client(workers: int):
    """A client of the local cluster of `workers` processes kept for this process's studies:
    started by the first study that asks for it, closed by close_kept_clusters (at the latest
    when the process exits). A study that does not end well (Ctrl-C, an error) closes it, so that
    none of its chunks still running is left on the workers of the next study.
    """
    from dask.distributed import Client

    if workers in _kept and _kept[workers][0].status != "running":  # closed under it (a lost worker, a test)
        close_kept_clusters(workers)
    if workers not in _kept:
        atexit.unregister(close_kept_clusters)  # registered once, however many clusters
        atexit.register(close_kept_clusters)
        with contextlib.ExitStack() as stack:
            cluster = _local_cluster(stack, workers)
            _kept[workers] = (stack.enter_context(Client(cluster)), stack.pop_all())
    try:
        yield _kept[workers][0]
    except BaseException:
        _kept.pop(workers)[1].close()
        raise


def close_kept_clusters(workers: int | None = None) -> int:
    """Close the local clusters that run_sweep(..., keep_cluster=True) kept for this process.

    They close when the process exits; this frees their processes sooner.

    Parameters
    ----------
    workers : int, optional
        Close only the cluster kept with this many workers (default: every one).

    Returns
    -------
    int
        How many clusters were closed (none were kept: 0).

    Raises
    ------
    InvalidInput
        workers that is not a positive integer.

    Examples
    --------
    >>> from pendulum_fmu import close_kept_clusters
    >>> close_kept_clusters()
    0
    """
    if workers is not None and (not isinstance(workers, numbers.Integral) or workers < 1):
        raise InvalidInput(f"workers must be a positive integer, got {workers!r}")
    closing = [count for count in _kept if workers in (None, count)]
    for count in closing:
        _kept.pop(count)[1].close()
    return len(closing)


def _local_cluster(stack: contextlib.ExitStack, workers: int):
    """A local cluster of `workers` single-threaded processes on the loopback, speaking TLS with
    certificates made for it, with QUIET_DASK's settings and a Ctrl-C held while it starts;
    closed by the stack, onto which it is put before a Ctrl-C can come.
    """
    import dask
    from dask.distributed import LocalCluster

    certificates = run_certificates()
    # The scheduler and nannies read the settings as they start; each nanny hands them on to its
    # worker.
    with _ctrl_c_held(), dask.config.set(QUIET_DASK):
        # Port 0 for the scheduler's HTTP server: another cluster may hold dask's usual 8787;
        # on the loopback: its pages are no one else's business.
        return stack.enter_context(
            LocalCluster(
                n_workers=workers,
                threads_per_worker=1,
                processes=True,
                security=certificates,
                dashboard_address="127.0.0.1:0",
                silence_logs=logging.CRITICAL,
            )
        )


@contextlib.contextmanager
def _quiet(logger: logging.Logger):
    """The logger silenced: a lost scheduler has the client log each failed reconnection with its
    traceback (tens of lines), where the sweep reports the loss in one line (SchedulerLost);
    a local cluster's logs are silenced alike (silence_logs).
    """
    level = logger.level
    logger.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        logger.setLevel(level)


TLS_REFUSED = "the TLS handshake failed"


def _refused_by_tls(error: BaseException) -> str:
    """Why a TLS handshake failed, where one did (a certificate no CA of the other side's
    signed), as dask's connect gives it up after retrying until its timeout, or as the closed
    connection's text says when the far end refused: OpenSSL's reason; else "".
    """
    seen: BaseException | None = error
    while seen is not None:
        named = re.search(r"\[SSL: (\w+)\]", str(seen))
        if named:
            return f"{TLS_REFUSED} ({named[1]})"
        if isinstance(seen, ssl.SSLError):  # SSLEOFError: the far end closed it, refusing the client's
            return f"{TLS_REFUSED} ({seen.reason or type(seen).__name__})"
        seen = seen.__cause__ or seen.__context__
    return ""


def _first_line(error: BaseException) -> str:
    return str(error).splitlines()[0] if str(error) else type(error).__name__


def _why_no_scheduler(scheduler: str, timeout: float, security) -> str | None:
    """Why the address does not answer dask's handshake and an identity request as a scheduler
    within timeout seconds, all told: "" when nothing answered in time (nothing listens there,
    or it never answers), else what answered; None when a scheduler did.

    dask's Client bounds only the TCP connection by its timeout and then waits for the handshake
    for ever: a port that accepts and never answers (a wrong port, a firewall's tarpit) would hold
    it until the far end closes, and one that answers something else has its bytes read as a
    message length. Asked in a thread of its own, so that it runs where an event loop already
    runs (a notebook) too, and a Ctrl-C still stops the waiting here.
    """
    import asyncio

    from distributed.comm import connect

    async def identity() -> dict:
        comm = await connect(scheduler, timeout=timeout, **security.get_connection_args("client"))
        try:
            await comm.write({"op": "identity", "reply": True})
            return await comm.read()
        finally:
            comm.abort()

    answers: list = []

    def ask() -> None:
        try:
            answers.append(asyncio.run(asyncio.wait_for(identity(), timeout)))
        except (TimeoutError, OSError) as error:
            # Which of the two comes first, dask's connect giving up or the bound here, is chance.
            answers.append(_refused_by_tls(error))
        except Exception as error:  # an address dask cannot parse
            answers.append(_first_line(error))

    asking = threading.Thread(target=ask, name="pendulum_fmu scheduler handshake", daemon=True)
    asking.start()
    asking.join(timeout + 5.0)  # wait_for ends it by then: the margin is for a loaded machine
    if not answers:
        return ""
    answer = answers[0]
    if isinstance(answer, str):
        return answer
    kind = answer.get("type") if isinstance(answer, dict) else None
    if kind != "Scheduler":
        return f"it answers as {kind!r}, not as a dask scheduler"
    return None


@contextlib.contextmanager
def _ctrl_c_held():
    """SIGINT blocked in this thread while the local cluster starts, so that the threads the
    cluster starts, and the worker processes they spawn, inherit it blocked for good.

    A terminal's Ctrl-C goes to every process of its process group, the workers too, where each
    would print a KeyboardInterrupt traceback. So the workers never receive it: the client alone
    stops the study, and closing the cluster stops them. A Ctrl-C meanwhile is held pending and
    raised here as soon as the cluster has started.
    """
    if not hasattr(signal, "pthread_sigmask"):  # Windows: Ctrl-C reaches the console's processes alike
        yield
        return
    from multiprocessing import resource_tracker

    # Started first, as its start unblocks SIGINT in the thread that starts it (CPython 3.11).
    resource_tracker.ensure_running()
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def progress_bar(total: int, done: int, enabled: bool):
    """A bar of the cases on stderr, `done` of them already (_progress_bar.py)."""
    # No time: the run's one duration, cluster and figure included, is the summary's (run_sweep's
    # seconds), which a second, shorter one here would contradict.
    return shown_bar("sweep", "{n_fmt}/{total_fmt} cases{postfix}", total, done, enabled, postfix="0 failed")


@dataclass
class Totals:
    """What the chunks of one run reported."""

    failed: int = 0
    bytes: int = 0
    worker_cpu_seconds: float = 0.0
    worker_stepping_seconds: float = 0.0
    chunks: int = 0

    def add(self, result: tuple, bar) -> None:
        """Count a chunk's result (run_chunk's tuple) and advance the bar by its cases."""
        _, count, failed, written, cpu, stepping = result
        self.failed += failed
        self.bytes += written
        self.worker_cpu_seconds += cpu
        self.worker_stepping_seconds += stepping
        self.chunks += 1
        bar.set_postfix_str(f"{self.failed} failed", refresh=False)
        bar.update(count)


def run_chunks(client, task: Task, chunks: Iterable[tuple[int, int, dict]], bar) -> Totals:
    """Run each chunk (its index, the number of its first case, its values) on a worker,
    committing its parts (only those of this run: task.run) and advancing the bar as each
    finishes.
    """
    totals = Totals()
    chunks = list(chunks)
    indices = [index for index, _, _ in chunks]
    # One request for all the chunks, and one for the results of those that finished together:
    # each request costs the scheduler and this client about half a millisecond each (a result()
    # per future cost them 0.55 and 0.65 ms more per task than one gather, 256 tasks measured).
    futures = client.map(
        run_chunk,
        indices,
        [first for _, first, _ in chunks],
        [values for _, _, values in chunks],
        [task] * len(chunks),
        pure=False,
    )
    chunk_of = {future.key: index for future, index in zip(futures, indices, strict=True)}
    # Done callbacks rather than as_completed: on Ctrl-C no waiting coroutine is left to fail,
    # with a traceback, when the cluster closes.
    finished: queue.SimpleQueue = queue.SimpleQueue()
    for future in futures:
        future.add_done_callback(finished.put)
    waiting = len(futures)
    while waiting:
        batch = _finished_together(finished, waiting)
        waiting -= len(batch)
        # A chunk whose run finished has its parts staged whole: committed at once, before a
        # failed one raises (a full disk) and whether or not its result can still be asked of the
        # scheduler, so that every whole chunk is kept for --resume.
        ran = [future for future in batch if future.status == "finished"]
        for future in ran:
            task.store.commit(chunk_of[future.key], task.run, task.tables())
        try:
            results = client.gather(ran)
        except OSError:  # the scheduler went away since: reported as when that comes first
            raise CancelledError("scheduler-connection-lost") from None  # as dask's cancellation says it
        for result in results:
            totals.add(result, bar)
        for future in batch:
            if future.status != "finished":
                future.result()  # raises what the chunk's run raised
            future.release()
    if futures:
        bar.refresh()  # the last count, which a log would otherwise miss
    return totals


# How long the client lets finished chunks gather before it asks for their results: as long as
# the progress line waits between redraws on a terminal.
GATHER_SECONDS = 0.2


def _finished_together(finished: queue.SimpleQueue, waiting: int) -> list:
    """The next finished futures: the first to come, and those that finish within GATHER_SECONDS
    of it (none more once all `waiting` are in).
    """
    batch = [finished.get()]
    deadline = time.monotonic() + GATHER_SECONDS
    while len(batch) < waiting:
        try:
            batch.append(finished.get(timeout=max(0.0, deadline - time.monotonic())))
        except queue.Empty:
            break
    return batch
