"""Parameter studies on dask.distributed: workers simulate chunks of cases and write them.

A study goes to an output directory, a local path or any fsspec URL every worker can write to
(a shared file system, s3://, gs://, ...):

    study.json                        what the study is (cases, times, outputs, chunking)
    trajectories/part-000000.parquet  per chunk: case, time and the chosen outputs at each kept
                                      communication point
    cases/part-000000.parquet         per chunk, one row per case: case, its values, final_theta,
                                      final_omega, final_alpha, max_abs_theta, status ("ok" or
                                      "failed") and message (why the FMU refused the case)
    sweep.png                         the figure
    .sweep.lock                       there while a run writes a local folder: a second run is refused

The worker that ran a chunk writes its two files, trajectories first, so a chunk is done when its
cases part exists; --resume runs the chunks that are not, and an interrupted run removes
what they left. The client submits chunks, shows
progress and draws the figure from the cases table: it never holds a trajectory, so its memory
and its work per case stay small however large the study. A worker steps each case in the native
loop (cs_loop.py) through its thread's FMU instance (simulate.simulator), reset between cases. With format "csv" the
same files are CSV. One line of pandas, pyarrow, dask or DuckDB reads either table, e.g.
pandas.read_parquet("out/trajectories").
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import logging
import math
import numbers
import os
import queue
import sys
import tempfile
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import cs_loop
from . import default_fmu
from .files import TEMPORARY_GLOB, held_lock, replacing_on
from .parameters import START_VALUES, default_parameters, value_reference
from .signal import TorqueSchedule, communication_points
from .simulate import RECORDED, FmuError, initialize, run_schedule_python, simulator

OUTPUTS = RECORDED[1:]  # theta, omega, alpha
FORMATS = ("parquet", "csv")
SUMMARIES = ("final_theta", "final_omega", "final_alpha", "max_abs_theta")
# A study is cut into about this many chunks, so that up to 16 workers each get several (the
# load evens out and progress shows), but no chunk holds more than MAX_CHUNK_CASES cases, so a
# chunk's files stay tens of megabytes and a lost worker loses little.
TARGET_CHUNKS = 64
MAX_CHUNK_CASES = 256
# And a chunk's recordings (every point of every case, before thinning) stay this small.
MAX_CHUNK_BYTES = 64_000_000
# There while a run writes the study (see _only_run); hidden, and never part of a table.
LOCK_FILE = ".sweep.lock"
# Up to this many cases the figure draws every trajectory; above, quantile bands of the summaries.
LINES_UP_TO = 20
# A study larger than this is refused unless asked for (max_cases, --max-cases): at a
# millisecond a case it is a quarter of an hour on 1,000 cores, and a grid multiplied out by a
# stray value list is likelier than a study that large.
DEFAULT_MAX_CASES = 1_000_000


def _sweepable(fmu_path=None) -> list[str]:
    return ["torque", *default_parameters(fmu_path), *START_VALUES]


def _extra_names() -> list[str]:
    return [name for name in _sweepable() if name not in ("torque", "gravity")]


def _values(name: str, values) -> np.ndarray:
    try:
        array = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} values must be numbers, got {values!r}") from None
    if array.ndim != 1:
        raise ValueError(f"{name} values must be a flat list of numbers, got {values!r}")
    if array.size == 0:
        raise ValueError(f"no values given for {name}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} values must be finite, got {array[~np.isfinite(array)][0]}")
    if len(np.unique(array)) < array.size:
        raise ValueError(f"{name} values repeat: {values!r}")
    return array


class Grid(Sequence):
    """Every combination of the axes' values as a sequence of cases ({name: value} dicts), in
    itertools.product order, computed when asked: a grid of a million cases costs its axes."""

    def __init__(self, axes: dict[str, np.ndarray]):
        self.axes = axes
        self._shape = tuple(len(values) for values in axes.values())

    def __len__(self) -> int:
        return math.prod(self._shape)

    def __getitem__(self, index):
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(len(self)))]
        number = index + len(self) if index < 0 else index
        if not 0 <= number < len(self):
            raise IndexError(f"case {index} of a grid of {len(self)}")
        return {name: float(column[0]) for name, column in self.columns(number, number + 1).items()}

    def columns(self, start: int, stop: int) -> dict[str, np.ndarray]:
        """The values of cases start..stop-1, one array per name."""
        positions = np.unravel_index(np.arange(start, stop), self._shape)
        return {name: values[p] for (name, values), p in zip(self.axes.items(), positions)}


def sweep_grid(torques, gravities=(9.81,), extra: dict | None = None) -> Grid:
    """Every combination of the torques, gravities and extra values as a sequence of cases.

    extra: {name: [values, ...]} for the parameters mass, length, inertia, damping and the start
    values theta0, omega0. A case is a dict {'torque': .., 'gravity': .., <extra names>: ..}.
    """
    extra = dict(extra or {})
    extra_names = _extra_names()
    for name in extra:
        if name in ("torque", "gravity"):
            argument = {"torque": "torques", "gravity": "gravities"}[name]
            raise ValueError(f"give {name} values as the {argument} argument, not in extra")
        if name not in extra_names:
            raise ValueError(f"cannot sweep {name!r}: extra takes {', '.join(extra_names)}")
    axes = {"torque": torques, "gravity": gravities, **extra}
    return Grid({name: _values(name, values) for name, values in axes.items()})


def _check_cases(cases, fmu_path=None) -> list[str]:
    """The cases' common keys, which become the cases table's value columns."""
    if isinstance(cases, Grid):
        return list(cases.axes)  # checked when the grid was made
    if not cases:
        raise ValueError("no cases to run")
    names = list(cases[0])
    if "torque" not in names:
        raise ValueError("every case needs a 'torque'")
    sweepable, seen = _sweepable(fmu_path), {}
    for number, case in enumerate(cases):
        if list(case) != names:
            raise ValueError(f"case {number} has keys {list(case)}; every case needs {names}")
        for name, value in case.items():
            if name not in sweepable:
                raise ValueError(f"cannot sweep {name!r}: choose from {', '.join(sweepable)}")
            if not isinstance(value, numbers.Real) or not math.isfinite(value):
                raise ValueError(f"case {number}: {name} = {value!r} must be a finite number")
        # A repeat would only cost time, and share the first one's line in the figure.
        first = seen.setdefault(tuple(case.values()), number)
        if first != number:
            raise ValueError(f"case {number} repeats case {first}")
    return names


def _columns(cases, names: list[str], start: int, stop: int) -> dict[str, np.ndarray]:
    if isinstance(cases, Grid):
        return cases.columns(start, stop)
    return {name: np.array([case[name] for case in cases[start:stop]], float) for name in names}


@dataclass(frozen=True)
class _Study:
    """What every chunk of a study shares; shipped to the workers with each chunk."""

    fmu: str
    filesystem: object  # fsspec
    root: str
    stop_time: float
    step_size: float
    outputs: tuple[str, ...]
    stride: int  # keep every stride-th communication point (and the last)
    format: str

    def part(self, table: str, index: int) -> str:
        return f"{self.root}/{table}/part-{index:06d}.{self.format}"


class _Runner:
    """Cases through this thread's Simulator of the FMU (simulate.simulator), whose instance is
    restarted (reset and initialized again) for each: instantiating costs about a hundred times
    what a restart costs.

    A case is the start values of a restart: the parameters, theta and omega, and the torque,
    which then stays as it was set, so the native loop sets no input per step."""

    def __init__(self, fmu_simulator):
        self.simulator, fmu = fmu_simulator, fmu_simulator.fmu_path
        self.defaults = {**fmu_simulator.defaults, "theta": 0.0, "omega": 0.0, "torque": 0.0}
        start_references = np.array([value_reference(n, fmu) for n in self.defaults], np.uint32)
        outputs = np.array([value_reference(name, fmu) for name in OUTPUTS], np.uint32)
        self.stepper = (cs_loop.Stepper(fmu_simulator.slave, np.empty(0, np.uint32), outputs,
                                        start_references)
                        if fmu_simulator.stepper is not None else None)

    def start_values(self, values: dict[str, np.ndarray], count: int) -> np.ndarray:
        """(count, start values) of the cases given as {name: column}, the defaults elsewhere."""
        given = {START_VALUES.get(name, name): column for name, column in values.items()}
        return np.column_stack([np.broadcast_to(given.get(name, default), count)
                                for name, default in self.defaults.items()]).astype(float)

    def run(self, start_values: np.ndarray, points: np.ndarray, outputs: np.ndarray) -> None:
        """theta, omega and alpha of one case (its row of start_values) at every communication
        point into outputs (points x 3). FmuError when the FMU refuses the case; the next case's
        restart starts from fmi2Reset, whatever state the refusal left."""
        self.simulator.slave.messages.lines.clear()
        if self.stepper is not None:
            self.stepper.run(points, None, None, outputs, start_values=start_values)
        else:
            self._run_python(dict(zip(self.defaults, start_values.tolist())), points, outputs)

    def _run_python(self, start: dict[str, float], points: np.ndarray, outputs: np.ndarray) -> None:
        """The same case through fmpy's calls: FMI 3.0 FMUs, or no native loop."""
        torque, theta0, omega0 = start.pop("torque"), start.pop("theta"), start.pop("omega")
        slave = self.simulator.slave
        slave.reset()
        initialize(slave, parameters=start, theta0=theta0, omega0=omega0, start_time=float(points[0]))
        plan = TorqueSchedule(time=points, torque=np.full(len(points) - 1, torque),
                              torque_rate=np.zeros(len(points) - 1))
        run = run_schedule_python(slave, plan)
        outputs[:] = np.column_stack([run[name] for name in OUTPUTS])


_runners = threading.local()


def _runner(fmu: str) -> _Runner:
    """This thread's runner for the FMU file, over its Simulator (new when the file changed)."""
    fmu_simulator = simulator(fmu)
    current = getattr(_runners, "runner", None)
    if current is None or current.simulator is not fmu_simulator:
        current = _runners.runner = _Runner(fmu_simulator)
    return current


def _kept_points(points: int, stride: int) -> np.ndarray:
    """Indices of the communication points written: every stride-th, and the last."""
    return np.unique(np.append(np.arange(0, points, stride), points - 1))


def _write_table(study: _Study, name: str, index: int, columns: dict, split: tuple = ()) -> int:
    """Write one part of a table; returns its size in bytes. split: float columns stored
    byte-stream-split, as smooth series compress best."""
    import pyarrow as pa

    arrays = {column: pa.array(values) for column, values in columns.items()}
    # Not nullable (no value is ever missing): the writer then has no definition levels to write.
    table = pa.table(list(arrays.values()), schema=pa.schema(
        [pa.field(column, array.type, nullable=False) for column, array in arrays.items()]))
    with replacing_on(study.filesystem, study.part(name, index)) as file:
        if study.format == "parquet":
            import pyarrow.parquet as pq

            # Measured on trajectories (benchmarks/scale.py): LZ4 after byte-stream-split is as
            # small as zstd level 1 (57 kB for a 3-s case) and writes in a quarter of the time;
            # dictionaries only where values repeat within a column (case numbers, status).
            pq.write_table(table, file, compression="lz4",
                           use_dictionary=[c for c in table.column_names if c not in split],
                           column_encoding={c: "BYTE_STREAM_SPLIT" for c in split})
        else:
            import pyarrow.csv

            pyarrow.csv.write_csv(table, file)  # shortest round-trip digits: reads back exact
        return file.tell()


def _run_chunk(index: int, first: int, values: dict[str, np.ndarray], study: _Study) -> tuple:
    """Simulate a chunk of cases on a worker and write its parts.

    values: the chunk's cases, one array per name; first: the number of its first case.
    Returns (index, cases, failed, bytes written, CPU seconds of this thread, of which stepping).
    """
    cpu = time.thread_time()
    points = communication_points(0.0, study.stop_time, study.step_size)
    count = len(next(iter(values.values())))
    recorded = np.empty((count, len(points), len(OUTPUTS)))
    messages = [""] * count
    runner = _runner(study.fmu)
    start_values = runner.start_values(values, count)
    stepping = time.thread_time()
    for i in range(count):
        try:
            runner.run(start_values[i], points, recorded[i])
        except FmuError as error:
            messages[i] = str(error)
            recorded[i] = np.nan
    stepping = time.thread_time() - stepping
    ok = np.array([not message for message in messages], bool)
    numbers = first + np.arange(count)
    written = 0
    if study.outputs:
        keep = _kept_points(len(points), study.stride)
        kept = recorded if ok.all() else recorded[ok]  # a copy only when a case failed
        if len(keep) < len(points):
            kept = kept[:, keep]
        written += _write_table(study, "trajectories", index, {
            "case": np.repeat(numbers[ok], len(keep)), "time": np.tile(points[keep], int(ok.sum())),
            **{name: kept[:, :, OUTPUTS.index(name)].ravel() for name in study.outputs}},
            split=("time", *study.outputs))
    final = recorded[:, -1]
    summaries = [*final.T, np.max(np.abs(recorded[:, :, 0]), axis=1)]
    written += _write_table(study, "cases", index, {
        "case": numbers, **values, **dict(zip(SUMMARIES, summaries)),
        "status": np.where(ok, "ok", "failed").tolist(), "message": messages})
    return index, count, count - int(ok.sum()), written, time.thread_time() - cpu, stepping


def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _definition(cases, names, study: _Study) -> dict:
    """What makes two runs the same study, for --resume."""
    if isinstance(cases, Grid):
        values = {name: axis.tolist() for name, axis in cases.axes.items()}
    else:
        values = _sha256(np.stack(list(_columns(cases, names, 0, len(cases)).values())).tobytes())
    with open(study.fmu, "rb") as file:
        fmu = _sha256(file.read())
    return {"names": names, "cases": len(cases), "values": values, "stop_time": study.stop_time,
            "step_size": study.step_size, "outputs": list(study.outputs), "stride": study.stride,
            "format": study.format, "fmu_sha256": fmu}


def _parts(study: _Study, table: str) -> dict[int, str]:
    """{chunk index: path} of a table's parts."""
    pattern = f"{study.root}/{table}/part-*.{study.format}"
    return {int(Path(path).stem.split("-")[1]): path for path in study.filesystem.glob(pattern)}


def _done_chunks(study: _Study) -> set[int]:
    return set(_parts(study, "cases"))


def _remove(study: _Study, patterns) -> None:
    fs = study.filesystem
    for pattern in patterns:
        for path in fs.glob(f"{study.root}/{pattern}"):
            with contextlib.suppress(FileNotFoundError):
                fs.rm(path)


def _remove_unfinished(study: _Study) -> None:
    """What interrupted chunks leave: the temporaries of writes cut short (a killed worker, see
    files.py), and trajectory parts whose chunk did not get to write its cases part."""
    _remove(study, (TEMPORARY_GLOB, f"trajectories/{TEMPORARY_GLOB}", f"cases/{TEMPORARY_GLOB}"))
    done = _done_chunks(study)
    for index, path in _parts(study, "trajectories").items():
        if index not in done:
            with contextlib.suppress(FileNotFoundError):
                study.filesystem.rm(path)


def _prepare(study: _Study, definition: dict, resume: bool, count: int, points: int,
             output_dir) -> int:
    """Write study.json (or check it, on resume); returns the cases per chunk."""
    fs, manifest = study.filesystem, f"{study.root}/study.json"
    if resume and fs.exists(manifest):
        with fs.open(manifest, "r") as file:
            previous = json.load(file)
        differences = [key for key in definition if previous["study"].get(key) != definition[key]]
        if differences:
            raise ValueError(
                f"{output_dir} holds a different study ({', '.join(differences)} differ); leave "
                "out --resume to replace it, or choose another output directory")
        return previous["chunk_cases"]
    # A new study replaces whatever study was there.
    _remove(study, ("study.json", "sweep.png", "trajectories/part-*", "cases/part-*"))
    fitting = MAX_CHUNK_BYTES // (points * len(OUTPUTS) * 8)
    chunk_cases = max(1, min(MAX_CHUNK_CASES, fitting, math.ceil(count / TARGET_CHUNKS)))
    with replacing_on(fs, manifest) as file:
        file.write(json.dumps({"study": definition, "chunk_cases": chunk_cases}, indent=1).encode())
    return chunk_cases


def _only_run(study: _Study, output_dir):
    """Two runs into one folder would replace each other's parts: the second is refused while the
    first runs. A lock held on a local folder; on other file systems (object stores have no
    locks) keeping runs apart is the user's part."""
    from fsspec.implementations.local import LocalFileSystem

    if not isinstance(study.filesystem, LocalFileSystem):
        return contextlib.nullcontext()
    return held_lock(Path(study.root) / LOCK_FILE, f"output directory {output_dir}")


class SchedulerUnreachable(ConnectionError):
    """The dask scheduler did not answer; the message names the address."""


@contextlib.contextmanager
def _client(scheduler: str | None, workers: int | None, connect_timeout: float):
    """A dask client: on a local cluster of `workers` processes started (and closed) here, or on
    the scheduler at an address, refused within connect_timeout when it does not answer."""
    from dask.distributed import Client, LocalCluster

    if scheduler is None:
        # Port 0 for the scheduler's HTTP server: another cluster may hold dask's usual 8787.
        with LocalCluster(n_workers=workers or 2, threads_per_worker=1, processes=True,
                          dashboard_address=":0", silence_logs=logging.CRITICAL) as cluster, \
                Client(cluster) as client:
            yield client
        return
    try:
        # A port that answers but is no dask scheduler would otherwise be waited on for ever, or
        # have its bytes read as a message length.
        client = Client(scheduler, timeout=connect_timeout)
    except Exception as error:
        reason = str(error).splitlines()[0] if str(error) else type(error).__name__
        raise SchedulerUnreachable(
            f"no dask scheduler answered at {scheduler} within {connect_timeout:g} s ({reason}); "
            "check the address (start one with `dask scheduler`), raise --connect-timeout, or "
            "leave out --scheduler for a local cluster") from None
    with client:
        yield client


class _Progress:
    """A bar redrawn in place on a terminal; elsewhere (a log) a plain line every few seconds."""

    def __init__(self, total: int, enabled: bool):
        self.total, self.enabled, self.tty = total, enabled, sys.stderr.isatty()
        self.started = self.shown = time.perf_counter()

    def show(self, done: int, failed: int) -> None:
        now = time.perf_counter()
        if not self.enabled or (done < self.total and now - self.shown < (0.2 if self.tty else 5.0)):
            return
        self.shown = now
        counts = f"{done}/{self.total} cases, {failed} failed, {now - self.started:.1f} s"
        if self.tty:
            bar = "#" * (30 * done // self.total)
            end = "\n" if done == self.total else ""
            print(f"\rsweep [{bar:<30}] {counts}", end=end, file=sys.stderr, flush=True)
        else:
            print(f"sweep: {counts}", file=sys.stderr, flush=True)


def _read_cases(study: _Study, names: list[str]):
    """The cases table's values and summaries, as a pyarrow table."""
    import pyarrow as pa
    import pyarrow.dataset as ds

    types = {"case": pa.int64(), **{n: pa.float64() for n in (*names, *SUMMARIES)},
             "status": pa.string(), "message": pa.string()}
    if study.format == "csv":
        import pyarrow.csv

        file_format = ds.CsvFileFormat(convert_options=pyarrow.csv.ConvertOptions(column_types=types))
    else:
        file_format = "parquet"
    dataset = ds.dataset(f"{study.root}/cases", format=file_format, schema=pa.schema(types),
                         filesystem=study.filesystem)
    return dataset.to_table(columns=["case", *names, "max_abs_theta", "final_theta", "status"])


def _draw(study: _Study, cases_table, names: list[str], target: str) -> None:
    """sweep.png: every trajectory when there are few, else quantile bands of the summaries."""
    import pyarrow.dataset as ds

    from .plot import plot_case_bands, plot_cases  # here: workers never draw, nor import matplotlib

    title = f"Parameter study: {cases_table.num_rows} cases of the torque-driven pendulum"
    with tempfile.TemporaryDirectory(prefix="pendulum_fmu_sweep_") as scratch:
        figure = Path(scratch) / "sweep.png"
        if cases_table.num_rows <= LINES_UP_TO and {"theta", "omega"} <= set(study.outputs):
            trajectories = ds.dataset(f"{study.root}/trajectories", format=study.format,
                                      filesystem=study.filesystem).to_table()
            case_column = trajectories["case"].to_numpy()
            runs = {}
            for row in cases_table.to_pylist():
                if row["status"] == "ok":
                    rows = case_column == row["case"]
                    label = ", ".join(f"{name} = {row[name]:g}" for name in names)
                    runs[label] = {k: trajectories[k].to_numpy()[rows] for k in ("time", "theta", "omega")}
            plot_cases(runs, figure, title)
        else:
            plot_case_bands({name: cases_table[name].to_numpy() for name in names},
                            {"max |theta| in rad": cases_table["max_abs_theta"].to_numpy(),
                             "final theta in rad": cases_table["final_theta"].to_numpy()},
                            figure, title)
        with replacing_on(study.filesystem, target) as file:
            file.write(figure.read_bytes())


def run_sweep(cases, *, output_dir: str | os.PathLike, stop_time: float = 3.0,
              step_size: float = 1e-3, outputs=OUTPUTS, output_interval: float | None = None,
              format: str = "parquet", resume: bool = False, scheduler: str | None = None,
              workers: int | None = None, connect_timeout: float = 10.0, progress: bool = True,
              fmu_path: str | Path | None = None, max_cases: int = DEFAULT_MAX_CASES) -> dict:
    """Run every case on dask; the workers write the study into output_dir (see the module doc).

    cases: sweep_grid(...) or a list of {'torque': .., <parameter or start value>: ..} dicts.
    output_dir: a local path or an fsspec URL that every worker can write to. outputs: which of
    theta, omega, alpha the trajectories keep (none: only the cases table); output_interval: keep
    a point every so many seconds (a whole number of steps; default every step). resume: run
    only the chunks a previous run of the same study into output_dir did not finish.
    scheduler: the address of a running dask.distributed scheduler, which must answer within
    connect_timeout seconds; without one a local cluster of `workers` processes (default 2) runs
    for this call (its workers are spawned, so a script calling this needs the
    `if __name__ == "__main__":` guard). progress: a progress line on stderr. max_cases: the
    largest study accepted (default DEFAULT_MAX_CASES); a larger one is refused before anything
    starts.
    Returns {'output_dir', 'trajectories', 'cases_table', 'figure': paths or URLs; 'cases',
    'failed': counts; 'chunks', 'chunks_run'; 'bytes': written by this run; 'seconds' in all,
    'figure_seconds' of them reading the cases table and drawing; 'worker_cpu_seconds' the
    workers spent on this run's chunks, 'worker_stepping_seconds' of them running the cases}.
    """
    import fsspec

    started = time.perf_counter()
    if len(cases) > max_cases:
        raise ValueError(f"{len(cases):,} cases is over the limit of {max_cases:,}: give fewer "
                         "values, or raise the limit (--max-cases) if the study is meant to be "
                         "that large")
    names = _check_cases(cases, fmu_path)
    if not (isinstance(stop_time, numbers.Real) and math.isfinite(stop_time)):
        raise ValueError(f"stop time {stop_time} must be a finite number")
    points = len(communication_points(0.0, stop_time, step_size))  # refuses a bad stop or step here
    outputs = tuple(outputs)
    for name in outputs:
        if name not in OUTPUTS or outputs.count(name) > 1:
            raise ValueError(f"outputs {', '.join(outputs)}: choose each at most once among "
                             f"{', '.join(OUTPUTS)}")
    stride = 1
    if output_interval is not None:
        stride = round(output_interval / step_size) if math.isfinite(output_interval) else 0
        if stride < 1 or abs(stride * step_size - output_interval) > 1e-9 * output_interval:
            raise ValueError(f"output interval {output_interval} s must be a whole number of steps "
                             f"of {step_size} s")
    if format not in FORMATS:
        raise ValueError(f"format {format!r}: choose {' or '.join(FORMATS)}")
    if scheduler is not None and workers is not None:
        raise ValueError("workers sizes the local cluster; with a scheduler the cluster has its own")
    if workers is not None and (not isinstance(workers, numbers.Integral) or workers < 1):
        raise ValueError(f"workers must be a positive integer, got {workers!r}")
    if not (isinstance(connect_timeout, numbers.Real) and 0 < connect_timeout < math.inf):
        raise ValueError(f"connect timeout {connect_timeout} must be a positive number of seconds")
    filesystem, root = fsspec.core.url_to_fs(str(output_dir))
    url = str(output_dir)
    study = _Study(fmu=str(Path(fmu_path).resolve() if fmu_path else default_fmu()),
                   filesystem=filesystem, root=root.rstrip("/"), stop_time=float(stop_time),
                   step_size=float(step_size), outputs=outputs, stride=stride, format=format)
    bar = _Progress(len(cases), progress)
    written, worker_cpu, worker_stepping = 0, 0.0, 0.0
    # The folder taken first, so that a second run is refused before it starts a cluster; then
    # connected, so that a scheduler that does not answer leaves the study untouched.
    with _only_run(study, url):
        try:
            with _client(scheduler, workers, connect_timeout) as client:
                chunk_cases = _prepare(study, _definition(cases, names, study), resume, len(cases),
                                       points, url)
                chunks = range(math.ceil(len(cases) / chunk_cases))
                done = _done_chunks(study)
                pending = [index for index in chunks if index not in done]
                finished = sum(min(chunk_cases, len(cases) - i * chunk_cases) for i in done)
                futures = [client.submit(_run_chunk, index, index * chunk_cases,
                                         _columns(cases, names, index * chunk_cases,
                                                  min(len(cases), (index + 1) * chunk_cases)),
                                         study, pure=False) for index in pending]
                # Done callbacks rather than as_completed: on Ctrl-C no waiting coroutine is left
                # to fail, with a traceback, when the cluster closes.
                finished_futures = queue.SimpleQueue()
                for future in futures:
                    future.add_done_callback(finished_futures.put)
                failed = 0
                for _ in futures:
                    future = finished_futures.get()
                    _, count, chunk_failed, chunk_bytes, chunk_cpu, chunk_stepping = future.result()
                    finished, failed = finished + count, failed + chunk_failed
                    written, worker_cpu = written + chunk_bytes, worker_cpu + chunk_cpu
                    worker_stepping += chunk_stepping
                    future.release()
                    bar.show(finished, failed)
        finally:
            # After a local cluster closed, so that none of its workers writes any more (a remote
            # cluster's may still finish the chunk they were running).
            _remove_unfinished(study)
    drawing = time.perf_counter()
    table = _read_cases(study, names)
    _draw(study, table, names, f"{study.root}/sweep.png")
    drawn = time.perf_counter()
    failed = int(np.sum(table["status"].to_numpy(zero_copy_only=False) == "failed"))
    from fsspec.implementations.local import LocalFileSystem

    # Paths on the local file system, URLs elsewhere.
    where = (Path(study.root).joinpath if isinstance(filesystem, LocalFileSystem)
             else f"{url.rstrip('/')}/".__add__)
    return {"output_dir": where(""), "trajectories": where("trajectories"),
            "cases_table": where("cases"), "figure": where("sweep.png"),
            "cases": len(cases), "failed": failed,
            "chunks": len(chunks), "chunks_run": len(pending), "bytes": written,
            "seconds": drawn - started, "figure_seconds": drawn - drawing,
            "worker_cpu_seconds": worker_cpu, "worker_stepping_seconds": worker_stepping}
