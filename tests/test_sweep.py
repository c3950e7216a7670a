"""Parameter studies on dask: the written study against simulate() and the analytic and Taylor
references, resume, failures, fsspec URLs, a cluster of separate processes, signals and
concurrent runs, and the studies refused before anything starts.
"""

import contextlib
import dataclasses
import glob
import json
import logging
import os
import re
import signal
import socket
import subprocess
import sys
import threading
import time
from importlib import import_module

import numpy as np
import psutil
import pyarrow as pa
import pyarrow.csv
import pyarrow.dataset as ds
import pytest
from bad_inputs import _edited_fmu, alpha_not_an_output
from dask.distributed import Client, LocalCluster
from fsspec.implementations.local import LocalFileSystem

import benchmarks.scale
from pendulum_fmu import default_fmu
from pendulum_fmu._errors import InvalidInput
from pendulum_fmu.cli import main
from pendulum_fmu.oracle._reference import reference
from pendulum_fmu.sweep import OUTPUTS, Study, run_sweep, sweep_grid
from pendulum_fmu.sweep.store import SUMMARIES, Store, StudyExists
from pendulum_fmu.sweep.worker import Task, kept_points, run_chunk

# The module; the package's attribute of that name is its function.
simulate = import_module("pendulum_fmu.fmu._simulate")

I_TOTAL = 20.0 + 40.0 * 0.5**2  # the tutorial's pendulum about its pivot
STOP_TIME, STEP_SIZE = 0.5, 1e-3
POINTS = 501


def _table(path, format="parquet", filesystem=None) -> dict[str, np.ndarray]:
    """A study's table as numpy columns, sorted by case (and time)."""
    if format == "csv":
        format = ds.CsvFileFormat(
            convert_options=pyarrow.csv.ConvertOptions(
                column_types={"message": pyarrow.string()}, strings_can_be_null=False
            )
        )
    table = ds.dataset(str(path), format=format, filesystem=filesystem).to_table()
    keys = [("case", "ascending")] + ([("time", "ascending")] if "time" in table.column_names else [])
    table = table.sort_by(keys)
    return {name: table[name].to_numpy(zero_copy_only=False) for name in table.column_names}


def _exact(case: dict, stride: int = 1) -> np.ndarray:
    """The case through simulate(), the readable path, at the points a study keeps."""
    parameters = {k: v for k, v in case.items() if k not in ("torque", "theta0", "omega0")}
    run = simulate.simulate(
        case["torque"],
        parameters=parameters,
        theta0=case.get("theta0", 0.0),
        omega0=case.get("omega0", 0.0),
        stop_time=STOP_TIME,
        step_size=STEP_SIZE,
    )
    keep = np.unique(np.append(np.arange(0, len(run), stride), len(run) - 1))
    return run[keep]


@pytest.fixture(autouse=True)
def _built_fmu(fmu, monkeypatch):
    """Every study here runs the FMU built for this session."""
    monkeypatch.setattr("pendulum_fmu.default_fmu", lambda: fmu)


# --- studies on a local cluster -------------------------------------------------------------


@pytest.fixture(scope="module")
def threads_scheduler():
    """Workers as threads of this process: quick to start, and they share its memory:// file system."""
    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=False, dashboard_address=":0", silence_logs=logging.WARNING
    ) as cluster:
        yield cluster.scheduler_address


def test_grid_on_a_local_cluster_matches_simulate_bit_for_bit(tmp_path, capsys):
    cases = sweep_grid([5.0, 20.0], [0.0, 9.81])
    result = run_sweep(Study(cases, stop_time=STOP_TIME, step_size=STEP_SIZE), output_dir=tmp_path, workers=2)
    assert "4/4 cases, 0 failed" in capsys.readouterr().err
    assert (result.cases, result.failed, result.chunks_run) == (4, 0, result.chunks)
    trajectories, table = _table(result.trajectories), _table(result.cases_table)
    assert set(trajectories) == {"case", "time", *OUTPUTS} and len(trajectories["case"]) == 4 * POINTS
    assert result.bytes == sum(p.stat().st_size for p in tmp_path.glob("*/part-*.parquet"))
    for number, case in enumerate(cases):
        rows = trajectories["case"] == number
        expected = _exact(case)
        for name in ("time", *OUTPUTS):
            assert np.array_equal(trajectories[name][rows], expected[name]), name
        assert table["torque"][number] == case["torque"] and table["gravity"][number] == case["gravity"]
        assert table["final_theta"][number] == expected["theta"][-1]
        assert table["max_abs_theta"][number] == np.max(np.abs(expected["theta"]))
        assert table["status"][number] == "ok" and table["message"][number] == ""
        if case["gravity"] == 0.0:  # and the physics: theta = tau t^2 / (2 I)
            parabola = 0.5 * case["torque"] / I_TOTAL * expected["time"] ** 2
            assert np.max(np.abs(expected["theta"] - parabola)) < 1e-12
    figure = result.figure.read_bytes()
    assert figure[:8] == b"\x89PNG\r\n\x1a\n" and len(figure) > 10_000


def test_the_local_cluster_and_the_documented_environment_run_dask_s_periodic_work_less_often():
    """QUIET_DASK reaches the local cluster's scheduler and workers, and the environment variables
    docs/sweeps.md gives for workers started by hand are what dask itself reads as those settings.
    """
    import dask

    from pendulum_fmu.sweep.client import QUIET_DASK, dask_client, dask_environment

    environment = dask_environment(QUIET_DASK)
    docs = (benchmarks.scale.REPOSITORY / "docs" / "sweeps.md").read_text()
    assert all(f"export {name}={value}\n" in docs for name, value in environment.items())
    code = f"import dask, distributed, json; print(json.dumps([dask.config.get(k) for k in {list(QUIET_DASK)!r}]))"
    read = subprocess.run(
        [sys.executable, "-c", code], env={**os.environ, **environment}, capture_output=True, text=True, check=True
    )
    assert json.loads(read.stdout) == list(QUIET_DASK.values())
    assert dask.config.get("distributed.admin.tick.interval") == "20ms"  # dask's own, unchanged here
    with dask_client(None, 1, 30.0) as client:
        assert client.run_on_scheduler(lambda dask_scheduler: dask_scheduler._tick_interval) == 0.2
        seen = client.run(lambda dask_worker: (dask_worker._tick_interval, "profile" in dask_worker.periodic_callbacks))
        assert list(seen.values()) == [(0.2, False)]


def test_a_trajectories_part_is_stored_as_measured(tmp_path):
    """LZ4; the series (time and the outputs) byte-stream-split without min/max statistics, the case
    numbers plain with them, as pyarrow's reader sees the part's metadata.
    """
    import pyarrow.parquet as pq

    task = Task(str(default_fmu()), Store(LocalFileSystem(), str(tmp_path), "parquet"), 0.05, 1e-3, OUTPUTS, 1, "run")
    task.store.start({}, 3, task.run, task.tables())
    run_chunk(0, 7, {"torque": np.array([1.0, 2.0, 3.0])}, task)
    metadata = pq.ParquetFile(task.store.staged("trajectories", 0, "run")).metadata
    columns = {metadata.schema.column(j).name: metadata.row_group(0).column(j) for j in range(metadata.num_columns)}
    assert list(columns) == ["case", "time", *OUTPUTS] and metadata.num_rows == 3 * 51
    assert {column.compression for column in columns.values()} == {"LZ4"}
    assert "RLE_DICTIONARY" not in columns["case"].encodings
    assert (columns["case"].statistics.min, columns["case"].statistics.max) == (7, 9)
    for name in ("time", *OUTPUTS):
        assert "BYTE_STREAM_SPLIT" in columns[name].encodings and "RLE_DICTIONARY" not in columns[name].encodings
        assert not columns[name].is_stats_set, name


def test_csv_with_chosen_outputs_and_interval(tmp_path, threads_scheduler):
    cases = [{"torque": 10.0, "damping": 0.0, "theta0": 0.3}, {"torque": 10.0, "damping": 4.0, "theta0": 0.3}]
    study = Study(
        cases, stop_time=STOP_TIME, step_size=STEP_SIZE, outputs=["theta"], output_interval=0.007, format="csv"
    )
    result = run_sweep(study, output_dir=tmp_path, scheduler=threads_scheduler, progress=False)
    trajectories = _table(result.trajectories, "csv")
    assert set(trajectories) == {"case", "time", "theta"}
    for number, case in enumerate(cases):
        rows = trajectories["case"] == number
        expected = _exact(case, stride=7)
        assert expected["time"][-1] == STOP_TIME and np.diff(expected["time"])[-1] < 0.007
        # The CSV's shortest round-trip digits read back as the same doubles.
        assert np.array_equal(trajectories["time"][rows], expected["time"])
        assert np.array_equal(trajectories["theta"][rows], expected["theta"])
        oracle = reference(
            10.0, stop_time=STOP_TIME, step_size=STEP_SIZE, theta0=0.3, parameters={"damping": case["damping"]}
        )
        assert abs(expected["theta"][-1] - oracle["theta"][-1]) < 1e-10
    assert _table(result.cases_table, "csv")["damping"].tolist() == [0.0, 4.0]


def test_a_study_on_an_fmu_with_other_outputs_chooses_and_records_by_its_own(tmp_path, threads_scheduler):
    """The pendulum with alpha no output: a study of it keeps theta and omega, and refuses alpha."""
    fmu = tmp_path / "NoAlphaOutput.fmu"
    fmu.write_bytes(_edited_fmu(alpha_not_an_output))
    with pytest.raises(InvalidInput, match=r"outputs alpha: choose each at most once among theta, omega$"):
        Study([{"torque": 1.0}], outputs=["alpha"], fmu_path=fmu)
    cases = sweep_grid([5.0, 20.0], [0.0, 9.81])
    study = Study(cases, stop_time=STOP_TIME, step_size=STEP_SIZE, fmu_path=fmu)
    assert study.outputs == ("theta", "omega")
    result = run_sweep(study, output_dir=tmp_path / "study", scheduler=threads_scheduler, progress=False)
    trajectories, table = _table(result.trajectories), _table(result.cases_table)
    assert set(trajectories) == {"case", "time", "theta", "omega"} and len(trajectories["case"]) == 4 * POINTS
    for number, case in enumerate(cases):
        rows = trajectories["case"] == number
        oracle = reference(
            case["torque"], stop_time=STOP_TIME, step_size=STEP_SIZE, parameters={"gravity": case["gravity"]}
        )
        for name in ("time", "theta", "omega"):
            assert np.max(np.abs(trajectories[name][rows] - oracle[name])) < 1e-9, (number, name)
        if case["gravity"] == 0.0:  # theta = tau t^2 / (2 I), omega = tau t / I
            seconds = trajectories["time"][rows]
            assert np.max(np.abs(trajectories["theta"][rows] - 0.5 * case["torque"] / I_TOTAL * seconds**2)) < 1e-12
            assert np.max(np.abs(trajectories["omega"][rows] - case["torque"] / I_TOTAL * seconds)) < 1e-12
        assert table["final_theta"][number] == trajectories["theta"][rows][-1]
        assert table["final_omega"][number] == trajectories["omega"][rows][-1]
        assert table["max_abs_theta"][number] == np.max(np.abs(trajectories["theta"][rows]))
        # Not an output of this FMU: not computed, so NaN, never zeros.
        assert np.isnan(table["final_alpha"][number]) and table["status"][number] == "ok"
    # The command without --outputs keeps them all, as Study does: the same table.
    command = ["sweep", "--torque", "5", "20", "--gravity", "0", "9.81", "--stop-time", str(STOP_TIME)]
    command += ["--output-dir", str(tmp_path / "command"), "--scheduler", threads_scheduler, "--fmu", str(fmu)]
    assert main(command) == 0
    assert {name: column.tolist() for name, column in _table(tmp_path / "command" / "trajectories").items()} == {
        name: column.tolist() for name, column in trajectories.items()
    }


def test_a_case_the_fmu_refuses_is_recorded_and_the_rest_go_on(tmp_path, threads_scheduler):
    cases = sweep_grid([1.0, 2.0], [9.81], {"mass": [0.0, 1.0], "length": [0.0, 0.5], "inertia": [0.0]})
    result = run_sweep(
        Study(cases, stop_time=0.05, step_size=STEP_SIZE),
        output_dir=tmp_path,
        scheduler=threads_scheduler,
        progress=False,
    )
    table, trajectories = _table(result.cases_table), _table(result.trajectories)
    refused = {"mass must be > 0", "inertia about the pivot) must be > 0"}
    for number, case in enumerate(cases):
        if case["mass"] == 0.0 or case["length"] == 0.0:  # and inertia 0: nothing to turn
            assert table["status"][number] == "failed"
            assert any(reason in table["message"][number] for reason in refused), table["message"][number]
            assert np.isnan(table["final_theta"][number]) and number not in trajectories["case"]
        else:
            assert table["status"][number] == "ok"
            # After refused cases the instance starts afresh: still simulate()'s numbers.
            parameters = {k: case[k] for k in ("mass", "length", "inertia", "gravity")}
            run = simulate.simulate(case["torque"], parameters=parameters, stop_time=0.05)
            assert np.array_equal(trajectories["theta"][trajectories["case"] == number], run["theta"])
    assert result.failed == 6 and len(table["case"]) == 8


def test_resume_runs_only_the_chunks_not_written(tmp_path, threads_scheduler):
    cases = sweep_grid(list(np.linspace(1.0, 40.0, 70)), [9.81])  # 2 cases per chunk, 35 chunks
    first = run_sweep(Study(cases, stop_time=0.05), output_dir=tmp_path, scheduler=threads_scheduler, progress=False)
    parts = sorted(tmp_path.glob("cases/part-*.parquet"))
    assert first.chunks == len(parts) == 35
    # As if interrupted: three chunks never finished (one wrote its trajectories only).
    for index in (0, 17, 34):
        parts[index].unlink()
    (tmp_path / "trajectories" / "part-000005.parquet").unlink()  # its cases part still says done
    kept = {p.name: p.stat().st_mtime_ns for p in tmp_path.glob("cases/part-*.parquet")}
    again = run_sweep(
        Study(cases, stop_time=0.05), output_dir=tmp_path, resume=True, scheduler=threads_scheduler, progress=False
    )
    assert again.chunks_run == 3 and again.cases == 70
    assert {p.name: p.stat().st_mtime_ns for p in tmp_path.glob("cases/part-*.parquet") if p.name in kept} == kept
    table = _table(again.cases_table)
    assert table["case"].tolist() == list(range(70))
    for number in (0, 1, 34, 35, 68, 69):
        run = simulate.simulate(cases[number]["torque"], stop_time=0.05)
        assert table["final_theta"][number] == run["theta"][-1]
    with pytest.raises(StudyExists, match="holds another study \\(stop_time differ; 35 of 35 chunks"):
        run_sweep(Study(cases, stop_time=0.06), output_dir=tmp_path, resume=True, progress=False)
    # Asked to, a new study replaces the old one.
    fresh = run_sweep(
        Study(cases[:3], stop_time=0.05),
        output_dir=tmp_path,
        overwrite=True,
        scheduler=threads_scheduler,
        progress=False,
    )
    assert fresh.chunks_run == fresh.chunks and len(_table(fresh.cases_table)["case"]) == 3
    assert not list(tmp_path.glob("**/.*"))


def _stale_task(output_dir) -> Task:
    """The task a worker of the run that last wrote output_dir holds: its store and run token."""
    manifest = json.loads((output_dir / "study.json").read_text())
    study = manifest["study"]
    return Task(
        fmu=str(default_fmu()),
        store=Store(LocalFileSystem(), str(output_dir), "parquet"),
        stop_time=study["stop_time"],
        step_size=study["step_size"],
        outputs=tuple(study["outputs"]),
        stride=study["stride"],
        run=manifest["run"],
    )


def test_a_stale_workers_part_never_enters_the_study_that_replaced_its_own(tmp_path, threads_scheduler, caplog):
    # Issue 32: a worker stopped mid-study writes its chunk after the study was replaced by
    # another (--overwrite, another grid) in the same folder.
    old_cases = sweep_grid([10.0, 20.0], [9.81], {"damping": [0.0, 0.5]})
    new_cases = sweep_grid([10.0, 20.0], [9.81], {"damping": [0.0, 0.25]})
    run_sweep(Study(old_cases, stop_time=STOP_TIME), output_dir=tmp_path, scheduler=threads_scheduler, progress=False)
    stale = _stale_task(tmp_path)
    new = run_sweep(
        Study(new_cases, stop_time=STOP_TIME),
        output_dir=tmp_path,
        overwrite=True,
        scheduler=threads_scheduler,
        progress=False,
    )
    assert new.chunks == 4 and _stale_task(tmp_path).run != stale.run
    parts = {p: p.read_bytes() for p in tmp_path.glob("*/part-*")}
    cases, trajectories = _table(tmp_path / "cases"), _table(tmp_path / "trajectories")
    # The stopped worker continues: chunk 1 of the old study, case 1, damping 0.5. It stages its
    # parts and, its run ended, removes them: the folder holds nothing of it.
    caplog.clear()
    assert run_chunk(1, 1, old_cases.columns(1, 2), stale)[:4] == (1, 1, 0, 0)
    assert caplog.messages == [f"chunk 1 of run {stale.run} not kept: the run ended while it ran"]
    assert not list(tmp_path.glob("**/_part-*")) and not list(tmp_path.glob("**/.*"))
    # A worker of the new run, which was written apart and moved into place, woken now: its
    # folder is gone, and it makes none.
    stale_new = _stale_task(tmp_path)
    apart = dataclasses.replace(
        stale_new, store=Store(LocalFileSystem(), str(tmp_path / ".overwrite.0.partial"), "parquet")
    )
    assert run_chunk(2, 2, new_cases.columns(2, 3), apart)[:4] == (2, 1, 0, 0)
    assert not list(tmp_path.glob("**/.*"))
    # No reader takes it: the folder's tables, the package's reading of the cases, a resume.
    assert {p: p.read_bytes() for p in tmp_path.glob("*/part-*")} == parts
    for name, table in (("cases", cases), ("trajectories", trajectories)):
        again = _table(tmp_path / name)
        assert all(np.array_equal(again[k], table[k]) for k in table), name
    expected = _exact({"torque": 10.0, "damping": 0.25})
    assert cases["damping"][1] == 0.25 and cases["final_theta"][1] == expected["theta"][-1]
    assert np.array_equal(trajectories["theta"][trajectories["case"] == 1], expected["theta"])
    assert (
        Store(LocalFileSystem(), str(tmp_path), "parquet")
        .read_cases(["torque", "gravity", "damping"])["final_theta"]
        .to_pylist()
        == cases["final_theta"].tolist()
    )
    resumed = run_sweep(
        Study(new_cases, stop_time=STOP_TIME),
        output_dir=tmp_path,
        resume=True,
        scheduler=threads_scheduler,
        progress=False,
    )
    assert resumed.chunks_run == 0 and {p: p.read_bytes() for p in tmp_path.glob("*/part-*")} == parts
    assert not list(tmp_path.glob("*/_part-*"))  # and the stale parts are gone


def test_finished_chunks_are_gathered_together_and_none_awaited_once_all_are_in(monkeypatch):
    """The client asks for the results of the chunks that finished together in one request,
    waiting a moment for more, but not once every chunk it waits for is in.
    """
    import queue

    from pendulum_fmu.sweep import client

    finished = queue.SimpleQueue()
    for future in ("a", "b", "c"):
        finished.put(future)
    # All three it waits for are in: it returns them without waiting out the window.
    monkeypatch.setattr(client, "GATHER_SECONDS", 30.0)
    started = time.monotonic()
    assert client._finished_together(finished, 3) == ["a", "b", "c"]
    assert time.monotonic() - started < 30.0
    # More to come than are in: it waits out the window, then returns those that came.
    for future in ("d", "e"):
        finished.put(future)
    monkeypatch.setattr(client, "GATHER_SECONDS", 0.05)
    assert client._finished_together(finished, 4) == ["d", "e"]
    assert finished.empty()


def test_the_chunks_that_ran_are_committed_before_one_that_failed_with_them_raises():
    """A chunk that fails (a full disk) in a batch of chunks that finished together: the others
    of the batch are committed first, so --resume keeps them.
    """
    from pendulum_fmu.sweep import client

    store = _Commits()
    with pytest.raises(OSError, match="No space"):
        client.run_chunks(_Cluster(failing=1), Task("fmu", store, 1.0, 0.1, (), 1, "run"), _chunks(3), _Bar())
    assert store.committed == [0, 2]


def test_chunks_whose_results_the_lost_scheduler_cannot_give_are_kept_and_the_loss_reported():
    """The scheduler lost between chunks finishing and the request for their results: the chunks
    are committed (their parts are staged whole) and run_sweep hears of a lost scheduler.
    """
    from concurrent.futures import CancelledError

    from pendulum_fmu.sweep import client

    store = _Commits()
    with pytest.raises(CancelledError) as lost:
        client.run_chunks(_Cluster(unreachable=True), Task("fmu", store, 1.0, 0.1, (), 1, "run"), _chunks(3), _Bar())
    assert str(lost.value) == "scheduler-connection-lost"
    assert store.committed == [0, 1, 2]


def _chunks(count):
    return [(index, index, {}) for index in range(count)]


class _Finished:
    """A dask future already done: finished, or failed with error."""

    def __init__(self, index, error=None):
        self.index, self.error, self.key = index, error, f"run_chunk-{index}"
        self.status = "error" if error else "finished"

    def add_done_callback(self, callback):
        callback(self)

    def result(self):
        raise self.error

    def release(self):
        pass


class _Cluster:
    """A dask client whose chunks are done at once: `failing` fails with a full disk; unreachable:
    the scheduler cannot be reached for the results.
    """

    def __init__(self, failing=None, unreachable=False):
        self.failing, self.unreachable = failing, unreachable

    def map(self, function, indices, firsts, values, tasks, pure):
        return [_Finished(i, OSError("No space left on device") if i == self.failing else None) for i in indices]

    def gather(self, futures):
        if self.unreachable:
            raise OSError("Timed out trying to connect to tcp://127.0.0.1:1 after 10 s")
        assert all(future.status == "finished" for future in futures)
        return [(future.index, 1, 0, 10, 0.0, 0.0) for future in futures]


class _Commits:
    def __init__(self):
        self.committed = []

    def commit(self, index, run, tables):
        self.committed.append(index)


class _Bar:
    def set_postfix_str(self, text, refresh):
        pass

    def update(self, count):
        pass

    def refresh(self):
        pass


def test_a_run_commits_only_the_parts_staged_under_its_own_token(tmp_path):
    store = Store(LocalFileSystem(), str(tmp_path), "parquet")
    store.start({}, 3, "other-run", ("cases",))  # its folder, as the run makes it
    store.write_table("cases", 0, {"case": np.arange(3)}, "other-run")
    with pytest.raises(FileNotFoundError):
        store.commit(0, "this-run", ("cases",))
    assert store.done_chunks() == set()
    store.commit(0, "other-run", ("cases",))
    assert store.done_chunks() == {0} and _table(tmp_path / "cases")["case"].tolist() == [0, 1, 2]


def test_the_cases_table_reads_back_as_pyarrows_dataset_reads_it_whatever_int_the_parts_hold(tmp_path):
    """Parts whose case numbers numpy made int32 (numpy 1 on Windows) or int64 read back alike,
    in the order of their paths: the table pyarrow's dataset gives, case numbers as int64.
    """
    store = Store(LocalFileSystem(), str(tmp_path), "parquet")
    store.start({}, 2, "run", ("cases",))  # its folder, as the run makes it
    summaries = {name: np.array([0.5, np.nan]) for name in SUMMARIES}
    for index, integers in ((1, np.int64), (0, np.int32)):  # written in another order than read
        columns = {"case": np.arange(2, dtype=integers) + 2 * index, "torque": np.array([1.0, 2.0]) + 2 * index}
        columns |= {**summaries, "status": ["ok", "failed"], "message": ["", "refused"]}
        store.write_table("cases", index, columns, "run")
        store.commit(index, "run", ("cases",))
    table = store.read_cases(["torque"])
    types = {"case": pa.int64(), "torque": pa.float64(), **dict.fromkeys(SUMMARIES, pa.float64())}
    dataset = ds.dataset(str(tmp_path / "cases"), format="parquet", schema=pa.schema(types | {"status": pa.string()}))
    expected = dataset.to_table(columns=table.column_names)
    assert table.schema == expected.schema
    assert json.dumps(table.to_pydict()) == json.dumps(expected.to_pydict())  # NaN as NaN
    assert table["case"].to_pylist() == [0, 1, 2, 3] and table["torque"].to_pylist() == [1.0, 2.0, 3.0, 4.0]


def test_output_to_a_file_url(tmp_path):
    result = run_sweep(
        Study(sweep_grid([3.0, 6.0]), stop_time=0.1), output_dir=tmp_path.as_uri(), workers=1, progress=False
    )
    assert result.figure == tmp_path / "sweep.png" and result.figure.exists()
    table = _table(tmp_path / "cases")
    run = simulate.simulate(6.0, stop_time=0.1)
    assert table["final_theta"][1] == run["theta"][-1]


def test_output_to_fsspec_memory(threads_scheduler):
    import fsspec

    result = run_sweep(
        Study(sweep_grid([3.0, 6.0], [0.0]), stop_time=0.1),
        output_dir="memory://study",
        scheduler=threads_scheduler,
        progress=False,
    )
    assert result.figure == "memory://study/sweep.png"
    filesystem = fsspec.filesystem("memory")
    assert filesystem.cat("/study/sweep.png")[:4] == b"\x89PNG"
    trajectories = _table("/study/trajectories", filesystem=filesystem)
    rows = trajectories["case"] == 1
    assert np.max(np.abs(trajectories["theta"][rows] - 3.0 / I_TOTAL * trajectories["time"][rows] ** 2)) < 1e-12
    assert not [path for path in filesystem.find("/study") if "/." in path]


def test_many_cases_draw_quantile_bands(tmp_path, threads_scheduler):
    cases = sweep_grid(list(np.linspace(0.0, 40.0, 8)), [0.0, 9.81], {"damping": [0.0, 1.0]})
    result = run_sweep(
        Study(cases, stop_time=0.05, outputs=[]), output_dir=tmp_path, scheduler=threads_scheduler, progress=False
    )
    assert not (tmp_path / "trajectories").exists()  # no outputs: the cases table alone
    assert result.figure.read_bytes()[:4] == b"\x89PNG"


def test_the_command_names_only_what_it_wrote_and_one_duration(tmp_path, capsys, monkeypatch):
    # Issue 28 item 5: --outputs none printed `wrote .../trajectories`; the progress line and the
    # summary gave two durations for one run.
    drawn = []

    class Terminal:  # stderr as a terminal: the bar redrawn in place, and left on screen
        def write(self, text):
            drawn.append(text)

        def flush(self):
            pass

        def isatty(self):
            return True

    monkeypatch.setattr(sys, "stderr", Terminal())
    assert (
        main(
            [
                "sweep",
                "--torque",
                "2",
                "4",
                "--stop-time",
                "0.1",
                "--outputs",
                "none",
                "--workers",
                "1",
                "--output-dir",
                str(tmp_path),
            ]
        )
        == 0
    )
    out = capsys.readouterr().out.splitlines()
    assert re.fullmatch(r"2 cases in \d+\.\d s", out[0]), out
    assert out[1:] == [f"wrote {tmp_path / 'cases'}", f"wrote {tmp_path / 'sweep.png'}"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cases", "study.json", "sweep.png"]
    bar = "".join(drawn)
    assert "2/2 cases, 0 failed" in bar and not re.search(r"\d s\b", bar), bar


# --- a folder that holds a study: refused, resumed, or replaced once the new one is whole ----


def _snapshot(folder) -> dict:
    """Every file under folder (hidden ones too) and its bytes."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_a_finished_study_is_never_replaced_unasked(tmp_path, monkeypatch, capsys):
    # The commands, as a careless user types them.
    monkeypatch.chdir(tmp_path)
    assert main(["sweep", "--torque", "5", "10", "20", "40", "--output-dir", "study"]) == 0
    capsys.readouterr()
    before = _snapshot(tmp_path / "study")
    assert main(["sweep", "--torque", "1", "--output-dir", "study"]) == 2
    refusal = capsys.readouterr().err.splitlines()
    assert len(refusal) == 1 and "study holds another study (cases, values differ; 4 of 4 chunks written)" in refusal[0]
    assert "--overwrite" in refusal[0] and "--resume" in refusal[0]
    # The same study again: refused too, pointing at --resume, which runs nothing.
    assert main(["sweep", "--torque", "5", "10", "20", "40", "--output-dir", "study"]) == 2
    refusal = capsys.readouterr().err.splitlines()
    assert len(refusal) == 1 and "already holds this study, finished (4 of 4 chunks written)" in refusal[0]
    assert "--resume" in refusal[0] and "--overwrite" in refusal[0]
    assert main(["sweep", "--torque", "1", "--output-dir", "study", "--resume"]) == 2
    assert "--resume continues only the same study" in capsys.readouterr().err
    with pytest.raises(SystemExit) as refused:  # argparse's own refusal
        main(["sweep", "--torque", "1", "--output-dir", "study", "--resume", "--overwrite"])
    assert refused.value.code == 2 and "not allowed with argument --resume" in capsys.readouterr().err
    assert _snapshot(tmp_path / "study") == before
    assert main(["sweep", "--torque", "5", "10", "20", "40", "--output-dir", "study", "--resume"]) == 0
    assert "0 of 4 chunks run" in capsys.readouterr().out
    # Asked to, the 1-case study replaces the 4-case one, and what else the folder holds stays.
    (tmp_path / "study" / "notes.txt").write_text("mine")
    assert main(["sweep", "--torque", "1", "--output-dir", "study", "--overwrite"]) == 0
    table = _table(tmp_path / "study" / "cases")
    assert table["torque"].tolist() == [1.0]
    assert table["final_theta"][0] == simulate.simulate(1.0)["theta"][-1]
    assert len(_table(tmp_path / "study" / "trajectories")["case"]) == 3001
    assert (tmp_path / "study" / "notes.txt").read_text() == "mine"
    assert sorted(p.name for p in (tmp_path / "study").iterdir()) == [
        "cases",
        "notes.txt",
        "study.json",
        "sweep.png",
        "trajectories",
    ]


def test_an_unfinished_study_is_refused_too(tmp_path, threads_scheduler):
    cases = sweep_grid([1.0, 2.0, 3.0, 4.0])
    run_sweep(Study(cases, stop_time=0.05), output_dir=tmp_path, scheduler=threads_scheduler, progress=False)
    for part in list(tmp_path.glob("cases/part-00000[12].parquet")):  # as if interrupted
        part.unlink()
    with pytest.raises(
        StudyExists, match="already holds this study, unfinished \\(2 of 4 chunks written\\): add --resume"
    ):
        run_sweep(Study(cases, stop_time=0.05), output_dir=tmp_path, progress=False)
    with pytest.raises(StudyExists, match="holds another study \\(stop_time differ; 2 of 4 chunks written\\)"):
        run_sweep(Study(cases, stop_time=0.06), output_dir=tmp_path, progress=False)
    # A folder with a study's entries that no sweep's study.json describes is someone else's.
    (tmp_path / "study.json").write_text("my notes")
    with pytest.raises(
        StudyExists, match=r"holds study\.json, trajectories, cases, sweep\.png but no study\.json of a sweep"
    ):
        run_sweep(Study(cases, stop_time=0.05), output_dir=tmp_path, resume=True, progress=False)


def test_a_study_that_fails_to_replace_another_leaves_it_whole(tmp_path, threads_scheduler, monkeypatch):
    run_sweep(
        Study(sweep_grid([1.0, 2.0]), stop_time=0.05), output_dir=tmp_path, scheduler=threads_scheduler, progress=False
    )
    before = _snapshot(tmp_path)

    def fail(*arguments):
        raise OSError("the disk is full")

    monkeypatch.setattr("pendulum_fmu.sweep.run.draw", fail)  # the very last step before the move
    with pytest.raises(OSError, match="the disk is full"):
        run_sweep(
            Study(sweep_grid([3.0]), stop_time=0.05),
            output_dir=tmp_path,
            overwrite=True,
            scheduler=threads_scheduler,
            progress=False,
        )
    assert _snapshot(tmp_path) == before and not list(tmp_path.glob(".*"))


def test_overwrite_on_an_fsspec_url(threads_scheduler):
    import fsspec

    for torques in ([3.0, 6.0], [9.0]):
        result = run_sweep(
            Study(sweep_grid(torques, [0.0]), stop_time=0.1),
            output_dir="memory://replaced",
            overwrite=True,
            scheduler=threads_scheduler,
            progress=False,
        )
    filesystem = fsspec.filesystem("memory")
    table = _table("/replaced/cases", filesystem=filesystem)
    assert result.cases == 1 and table["torque"].tolist() == [9.0]
    assert table["final_theta"][0] == pytest.approx(0.5 * 9.0 / I_TOTAL * 0.1**2, abs=1e-14)
    assert sorted(filesystem.ls("/replaced", detail=False)) == [
        f"/replaced/{name}" for name in ("cases", "study.json", "sweep.png", "trajectories")
    ]


@pytest.mark.cluster
def test_ctrl_c_during_overwrite_leaves_the_old_study_whole(tmp_path):
    old = tmp_path / "study"
    assert (
        subprocess.run(
            _sweep_command(old, "--torque", "1", "2", "--stop-time", "0.1", "--workers", "1"), capture_output=True
        ).returncode
        == 0
    )
    before = _snapshot(old)
    # 594 cases of 600 s on one worker: still running after 4 s on any machine (with 60-s cases
    # one CI run had finished them all in 2.9 s and printed its progress line before the signal).
    for delay in (2.0, 4.0):  # while the cluster starts, while the chunks run
        process = subprocess.Popen(
            _sweep_command(
                old,
                "--overwrite",
                "--torque",
                *map(str, range(3, 300)),
                "--gravity",
                "0",
                "9.81",
                "--stop-time",
                "600",
                "--outputs",
                "none",
                "--workers",
                "1",
            ),
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            start_new_session=True,
        )
        time.sleep(delay)
        assert process.poll() is None, process.communicate()
        os.killpg(process.pid, signal.SIGINT)
        _, err = process.communicate(timeout=120)
        assert process.returncode == 130 and err.count("\n") == 1, err
        assert f"{old} holds what it held before" in err
        assert _snapshot(old) == before


# --- a cluster of separate processes, as on a real cluster ---------------------------------


@pytest.fixture
def dask_processes():
    """`dask scheduler` and two `dask worker`s on localhost, each its own process."""
    with benchmarks.scale.dask_processes(2) as address:
        yield address


@pytest.mark.cluster
def test_a_study_on_a_scheduler_and_workers_started_as_processes(tmp_path, dask_processes, fmu, capsys):
    assert (
        main(
            [
                "sweep",
                "--torque",
                "2",
                "4",
                "8",
                "16",
                "--gravity",
                "0",
                "9.81",
                "--stop-time",
                "0.2",
                "--scheduler",
                dask_processes,
                "--output-dir",
                str(tmp_path),
            ]
        )
        == 0
    )
    assert "8 cases" in capsys.readouterr().out
    table = _table(tmp_path / "cases")
    for number, (torque, gravity) in enumerate([(t, g) for t in (2, 4, 8, 16) for g in (0.0, 9.81)]):
        expected = (
            0.5 * torque / I_TOTAL * 0.2**2
            if gravity == 0.0
            else reference(float(torque), stop_time=0.2, step_size=STEP_SIZE)["theta"][-1]
        )
        assert abs(table["final_theta"][number] - expected) < 1e-10
    with Client(dask_processes) as client:
        # Both workers ran chunks, each unzipping the FMU once (into its one model object).
        assert list(
            client.run(
                lambda: sum(
                    1
                    for held in __import__("gc").get_objects()
                    if type(held).__name__ == "FmuModel" and "_unzipped" in vars(held)
                )
            ).values()
        ) == [1, 1]


@pytest.mark.cluster
def test_a_chunk_whose_worker_dies_is_run_again(tmp_path, dask_processes):
    # 64 chunks of 4 cases of 60 s: a chunk takes several times what finding and killing the
    # worker does, so chunks are still queued when it dies.
    cases = sweep_grid(list(np.linspace(1.0, 40.0, 256)), [9.81])
    results = []
    study = threading.Thread(
        target=lambda: results.append(
            run_sweep(
                Study(cases, stop_time=60.0, outputs=[]), output_dir=tmp_path, scheduler=dask_processes, progress=False
            )
        )
    )
    study.start()
    deadline = time.monotonic() + 120
    while not list(tmp_path.glob("cases/part-*")):
        assert study.is_alive() and time.monotonic() < deadline
        time.sleep(0.01)
    # The process a `dask worker` (its nanny) started to run tasks, killed as a lost node would be,
    # while chunks are still queued, so it holds one.
    nannies = [p for p in psutil.Process().children() if "worker" in p.cmdline()]
    victim = next(c for c in nannies[0].children() if "spawn_main" in " ".join(c.cmdline()))
    victim.kill()
    assert len(list(tmp_path.glob("cases/part-*"))) < 60
    study.join(timeout=300)
    assert not victim.is_running()
    assert results[0].cases == 256 and results[0].failed == 0
    table = _table(tmp_path / "cases")
    assert table["case"].tolist() == list(range(256)) and set(table["status"]) == {"ok"}
    assert table["final_theta"][255] == simulate.simulate(40.0, stop_time=60.0)["theta"][-1]
    assert not list(tmp_path.glob("**/.*"))


@pytest.mark.cluster
def test_a_scheduler_killed_mid_study_is_one_line_and_resume_on_a_new_one_finishes(tmp_path):
    # Issue 32, fault 2: the cluster's failure, not ours: exit 2 (as for an unreachable
    # scheduler), one line naming --resume, none of dask's log.
    torques = list(map(str, np.linspace(1.0, 40.0, 128)))  # 64 chunks of 2 cases
    arguments = ("--torque", *torques, "--stop-time", "300", "--outputs", "theta", "--output-interval", "1")
    with benchmarks.scale.dask_process_handles(1) as (address, processes):
        sweep = subprocess.Popen(
            _sweep_command(tmp_path, *arguments, "--scheduler", address),
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        deadline = time.monotonic() + 120
        while not list(tmp_path.glob("cases/part-*")):
            assert sweep.poll() is None and time.monotonic() < deadline, sweep.communicate()
            time.sleep(0.01)
        processes[0].kill()
        out, err = sweep.communicate(timeout=120)
    assert sweep.returncode == 2 and out == "", (out, err)
    lines = [line for line in err.splitlines() if not line.startswith("sweep: ")]  # progress
    assert lines == [
        f"pendulum-fmu sweep: error: the dask scheduler at {address} was lost "
        "mid-study (scheduler-connection-lost); the chunks that finished are kept in "
        f"{tmp_path}: start a scheduler and run the same command with --resume to "
        "run the rest"
    ], err
    written = len(list(tmp_path.glob("cases/part-*")))
    assert 0 < written < 64
    with benchmarks.scale.dask_processes(1) as address:
        resumed = subprocess.run(
            _sweep_command(tmp_path, *arguments, "--scheduler", address, "--resume"),
            capture_output=True,
            text=True,
            timeout=300,
        )
    assert resumed.returncode == 0, resumed.stderr
    assert f"({64 - written} of 64 chunks run;" in resumed.stdout
    table, trajectories = _table(tmp_path / "cases"), _table(tmp_path / "trajectories")
    assert table["case"].tolist() == list(range(128)) and set(table["status"]) == {"ok"}
    assert np.array_equal(np.unique(trajectories["case"]), np.arange(128))
    for number in (0, 127):  # a chunk of the first run, and one of the resumed run
        expected = simulate.simulate(float(torques[number]), stop_time=300.0)
        assert table["final_theta"][number] == expected["theta"][-1]


@pytest.mark.cluster
@pytest.mark.skipif(not hasattr(signal, "SIGSTOP"), reason="no SIGSTOP on this platform")
def test_a_worker_stopped_mid_study_and_continued_after_an_overwrite_changes_nothing(tmp_path, monkeypatch):
    # Issue 32, fault 1 with the real fault: a worker (no nanny) stopped with SIGSTOP mid-study;
    # the study finishes without it; another grid replaces it (--overwrite); the worker is
    # continued, stages its old chunk in the folder and, its run ended, removes it.
    monkeypatch.setenv("DASK_DISTRIBUTED__SCHEDULER__WORKER_TTL", "2s")  # a stopped worker is dropped
    torques = list(np.linspace(1.0, 40.0, 128))  # 64 chunks of 4 cases, a few s in all
    options = dict(stop_time=600.0, outputs=["theta"], output_interval=1.0)
    old = Study(sweep_grid(torques, [9.81], {"damping": [0.0, 0.5]}), **options)
    new = Study(sweep_grid(torques, [9.81], {"damping": [0.0, 0.25]}), **options)
    # The worker is stopped wherever it is when seen computing: stopped outside a chunk (between
    # two, or after its chunk's write), it has no stale chunk to write when continued (seen once,
    # in a CI run on the loaded 2-core VM), and the scenario runs once more, in a folder of its own.
    for attempt in range(2):
        folder = tmp_path / f"try-{attempt}"
        parts, stale = _stop_replace_and_continue(folder, old, new)
        assert {p: p.read_bytes() for p in folder.glob("*/part-*")} == parts
        # Nothing of the stale chunk: no staged part, no temporary, no folder (issue 48).
        assert not list(folder.glob("**/_part-*")) and not list(folder.glob("**/.*"))
        if stale:
            break
    assert stale, "in two tries the worker continued finished no chunk of the study it was stopped in"
    table, trajectories = _table(folder / "cases"), _table(folder / "trajectories")
    assert table["case"].tolist() == list(range(256)) and set(table["damping"]) == {0.0, 0.25}
    assert len(trajectories["case"]) == 256 * 601
    # The new study's cases are its own: their damping's trajectory, to the bit (every part is
    # unchanged above; a sample of the damping-0.25 cases against simulate() here).
    for number in range(1, 256, 16):
        expected = simulate.simulate(torques[number // 2], parameters={"damping": 0.25}, stop_time=600.0)
        assert np.array_equal(trajectories["theta"][trajectories["case"] == number], expected["theta"][::1000]), number
    again = run_sweep(new, output_dir=folder, resume=True, workers=1, progress=False)
    assert again.chunks_run == 0 and {p: p.read_bytes() for p in folder.glob("*/part-*")} == parts
    assert not list(folder.glob("*/_part-*"))


def _stop_replace_and_continue(folder, old: Study, new: Study) -> tuple[dict, bool]:
    """On a cluster of 2 workers without nannies: old run into folder, one worker stopped while it
    computes, old finished without it, new run into folder with overwrite, the worker continued.
    Returns the new study's parts (path: bytes) as new left them, and whether the continued
    worker finished its stale chunk (old's run) within 60 s, as its log says.
    """
    log = folder.parent / f"{folder.name}-worker.log"
    logged = ("sh", "-c", f'exec "$@" 2>>"{log}"', "sh")  # the stopped worker's stderr, its log
    places = [(logged, "127.0.0.1"), ((), "127.0.0.1")]
    with benchmarks.scale.dask_process_handles(2, nanny=False, places=places) as (address, processes):
        stopped = psutil.Process(processes[1].pid)
        results = []
        first = threading.Thread(
            target=lambda: results.append(run_sweep(old, output_dir=folder, scheduler=address, progress=False))
        )
        first.start()
        deadline = time.monotonic() + 120
        while not (list(folder.glob("cases/part-*")) and stopped.cpu_percent(0.1) > 30):
            assert first.is_alive() and time.monotonic() < deadline
        stopped.suspend()  # mid-chunk, as a rule: it was computing
        first.join(timeout=300)
        assert results[0].cases == 256 and results[0].failed == 0
        stale_run = _stale_task(folder).run
        run_sweep(new, output_dir=folder, overwrite=True, scheduler=address, progress=False)
        parts = {p: p.read_bytes() for p in folder.glob("*/part-*")}
        stopped.resume()
        deadline = time.monotonic() + 60
        while f"of run {stale_run} not kept: the run ended while it ran" not in log.read_text():
            if time.monotonic() > deadline:
                return parts, False
            time.sleep(0.05)
    return parts, True


def _assert_every_case_once(folder, torques, stop_time: float, stride: int = 1, sample: int = 4) -> None:
    """The study of these torques (gravity 9.81, every output, every stride-th step) whole in
    folder: every case once in both tables, every case's rows, and a sample of the cases'
    trajectories bit-identical to simulate()'s.
    """
    table, trajectories = _table(folder / "cases"), _table(folder / "trajectories")
    assert table["case"].tolist() == list(range(len(torques))) and set(table["status"]) == {"ok"}
    assert table["torque"].tolist() == [float(t) for t in torques]
    points = len(kept_points(round(stop_time / STEP_SIZE) + 1, stride))
    assert np.bincount(trajectories["case"]).tolist() == [points] * len(torques)
    for number in np.linspace(0, len(torques) - 1, sample).round().astype(int):
        run = simulate.simulate(float(torques[number]), stop_time=stop_time)
        expected = run[kept_points(len(run), stride)]
        rows = trajectories["case"] == number
        for name in ("time", *OUTPUTS):
            assert np.array_equal(trajectories[name][rows], expected[name]), (number, name)
        assert table["final_theta"][number] == run["theta"][-1]


def _computing(nanny: subprocess.Popen) -> psutil.Process:
    """The process a `dask worker`'s nanny started to run its tasks."""
    return next(c for c in psutil.Process(nanny.pid).children() if "spawn_main" in " ".join(c.cmdline()))


def _wait_till_busy(process: psutil.Process, folder, study: threading.Thread) -> None:
    """Until the study has written a chunk and the worker process is computing one."""
    deadline = time.monotonic() + 120
    while not (list(folder.glob("cases/part-*")) and process.cpu_percent(0.1) > 30):
        assert study.is_alive() and time.monotonic() < deadline


def _worker_address(scheduler: str, process: psutil.Process) -> str:
    """The address the scheduler knows the worker running in process by."""
    with Client(scheduler) as client:
        pids = client.run(os.getpid)
    return next(address for address, pid in pids.items() if pid == process.pid)


def _wait_till_dropped(scheduler: str, worker: str) -> None:
    """Until the scheduler has removed the worker as lost (not closed by its own wish), as its
    event log says for a worker silent past the scheduler's time for one.
    """
    deadline = time.monotonic() + 60
    with Client(scheduler) as client:
        while not any(
            event["action"] == "remove-worker" and not event["expected"] for _, event in client.get_events(worker)
        ):
            assert time.monotonic() < deadline, client.get_events(worker)
            time.sleep(0.1)


def _study_thread(study: Study, folder, address: str) -> tuple[threading.Thread, list]:
    """run_sweep of the study on the scheduler at address, started in a thread; its result
    lands in the list.
    """
    results = []
    thread = threading.Thread(
        target=lambda: results.append(run_sweep(study, output_dir=folder, scheduler=address, progress=False))
    )
    thread.start()
    return thread, results


# Dask's own timeout, short, so that a fault test outlasts it within seconds: the scheduler drops
# a worker silent for 2 s.
SHORT_DASK_TIMEOUTS = {"DASK_DISTRIBUTED__SCHEDULER__WORKER_TTL": "2s"}
FAULT_TORQUES = list(np.linspace(1.0, 40.0, 128))  # 64 chunks of 2 cases


@pytest.fixture
def network_namespace():
    """(the host's address, a command prefix that runs a command in a network namespace of its
    own, its address there, the host's end of the link between them): a veth pair, as two hosts
    on one network.
    """
    if os.geteuid() != 0:
        pytest.skip("cutting a worker's link needs root (network namespaces)")
    name, tag = f"sweep{os.getpid()}", os.getpid() % 250
    host_end, far_end = f"sw{os.getpid()}h", f"sw{os.getpid()}n"
    host, far = f"10.213.{tag}.1", f"10.213.{tag}.2"
    commands = [
        ["ip", "netns", "add", name],
        ["ip", "link", "add", host_end, "type", "veth", "peer", "name", far_end],
        ["ip", "link", "set", far_end, "netns", name],
        ["ip", "addr", "add", f"{host}/24", "dev", host_end],
        ["ip", "link", "set", host_end, "up"],
        ["ip", "netns", "exec", name, "ip", "addr", "add", f"{far}/24", "dev", far_end],
        ["ip", "netns", "exec", name, "ip", "link", "set", far_end, "up"],
        ["ip", "netns", "exec", name, "ip", "link", "set", "lo", "up"],
    ]
    try:
        for command in commands:
            done = subprocess.run(command, capture_output=True, text=True)
            if done.returncode:
                pytest.skip(f"no network namespaces here: {' '.join(command)}: {done.stderr.strip()}")
        yield host, ("ip", "netns", "exec", name), far, host_end
    finally:
        subprocess.run(["ip", "link", "del", host_end], capture_output=True)
        subprocess.run(["ip", "netns", "del", name], capture_output=True)


# The scheduler listens on the namespaces' link, off the loopback, on plain TCP: the sweep warns so.
@pytest.mark.filterwarnings("ignore::pendulum_fmu.UnencryptedScheduler")
@pytest.mark.cluster
def test_a_workers_link_cut_mid_study_changes_nothing(tmp_path, monkeypatch, network_namespace):
    # Issue 32, a fault survived: the link of a worker on another host cut while it computes a
    # chunk, for longer than the scheduler waits for a silent worker, then restored.
    for name, value in SHORT_DASK_TIMEOUTS.items():
        monkeypatch.setenv(name, value)
    host, elsewhere, far, link = network_namespace
    study = Study(sweep_grid(FAULT_TORQUES, [9.81]), stop_time=300.0, output_interval=1.0)
    places = [((), host), (elsewhere, far)]
    with benchmarks.scale.dask_process_handles(2, host=host, places=places) as (address, processes):
        far_worker = _computing(processes[2])
        far_address = _worker_address(address, far_worker)
        first, results = _study_thread(study, tmp_path, address)
        _wait_till_busy(far_worker, tmp_path, first)
        subprocess.run(["ip", "link", "set", link, "down"], check=True)
        _wait_till_dropped(address, far_address)  # the scheduler's 2 s for a silent worker, and its check
        subprocess.run(["ip", "link", "set", link, "up"], check=True)
        first.join(timeout=300)
    assert results[0].cases == 128 and results[0].failed == 0 and results[0].chunks_run == 64
    _assert_every_case_once(tmp_path, FAULT_TORQUES, 300.0, stride=1000)


@pytest.mark.cluster
@pytest.mark.skipif(not hasattr(signal, "SIGSTOP"), reason="no SIGSTOP on this platform")
def test_a_worker_stopped_mid_study_under_a_nanny_changes_nothing(tmp_path, monkeypatch):
    # Issue 32, a fault survived: a worker (the process its nanny started) stopped while it
    # computes a chunk; the study finishes without it, and it is continued afterwards.
    for name, value in SHORT_DASK_TIMEOUTS.items():
        monkeypatch.setenv(name, value)
    study = Study(sweep_grid(FAULT_TORQUES, [9.81]), stop_time=300.0, output_interval=1.0)
    with benchmarks.scale.dask_process_handles(2) as (address, processes):
        stopped = _computing(processes[2])
        stopped_address = _worker_address(address, stopped)
        first, results = _study_thread(study, tmp_path, address)
        _wait_till_busy(stopped, tmp_path, first)
        stopped.suspend()
        _wait_till_dropped(address, stopped_address)
        first.join(timeout=300)
        assert results[0].cases == 128 and results[0].failed == 0
        parts = {p: p.read_bytes() for p in tmp_path.glob("*/part-*")}
        with contextlib.suppress(psutil.NoSuchProcess):  # its nanny may have ended it
            stopped.resume()
        # Till it ends (its nanny, told it is gone, stops it) or writes the chunk it held.
        deadline = time.monotonic() + 10
        while stopped.is_running() and stopped.status() != psutil.STATUS_ZOMBIE and time.monotonic() < deadline:
            if list(tmp_path.glob("cases/_part-*.staged")):
                break
            time.sleep(0.05)
    assert {p: p.read_bytes() for p in tmp_path.glob("*/part-*")} == parts
    _assert_every_case_once(tmp_path, FAULT_TORQUES, 300.0, stride=1000)


@pytest.fixture
def small_disk(tmp_path):
    """A 4 MB file system of its own (tmpfs), mounted on a folder and unmounted after."""
    if os.geteuid() != 0:
        pytest.skip("filling a disk needs root (mounting a small tmpfs)")
    disk = tmp_path / "disk"
    disk.mkdir()
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=4m", "tmpfs", str(disk)], capture_output=True, text=True)
    if done.returncode:
        pytest.skip(f"cannot mount a tmpfs here: {done.stderr.strip()}")
    try:
        yield disk
    finally:
        subprocess.run(["umount", "-l", str(disk)], check=True)


@pytest.mark.cluster
def test_a_disk_filling_mid_study_is_one_line_and_resume_finishes_it(small_disk):
    # Issue 32, a fault survived: the output's disk fills while the workers write. One line,
    # only whole chunks kept; once space is freed, --resume runs the rest.
    filler = small_disk / "filler"
    filler.write_bytes(b"\0" * 3_000_000)  # about 1 MB left: some chunks fit, not all
    folder = small_disk / "study"
    torques = [f"{t:g}" for t in np.linspace(1.0, 40.0, 64)]
    arguments = ("--torque", *torques, "--stop-time", "1", "--workers", "1")
    full = subprocess.run(_sweep_command(folder, *arguments), capture_output=True, text=True, timeout=300)
    assert full.returncode == 2 and full.stdout == "", (full.stdout, full.stderr)
    lines = [line for line in full.stderr.splitlines() if not line.startswith("sweep: ")]  # progress
    assert len(lines) == 1 and "No space left on device" in lines[0], full.stderr
    cases, trajectories = (sorted(p.name for p in folder.glob(f"{t}/*")) for t in ("cases", "trajectories"))
    # No staged or temporary file, no trajectories without their cases part, and what is kept reads.
    assert 0 < len(cases) < 64 and cases == trajectories and all(n.startswith("part-") for n in cases), cases
    assert len(_table(folder / "cases")["case"]) == len(cases)
    filler.unlink()
    resumed = subprocess.run(
        _sweep_command(folder, *arguments, "--resume"), capture_output=True, text=True, timeout=300
    )
    assert resumed.returncode == 0, resumed.stderr
    assert f"({64 - len(cases)} of 64 chunks run;" in resumed.stdout
    _assert_every_case_once(folder, torques, 1.0)
    assert not list(folder.glob("**/.*"))


@pytest.mark.cluster
def test_an_unreachable_silent_or_wrong_scheduler_is_one_line_within_the_timeout(tmp_path, capsys):
    closed = f"tcp://127.0.0.1:{benchmarks.scale.free_port()}"
    held = []  # the silent server's connections, open till the test ends
    with socket.socket() as silent, socket.socket() as impostor:
        for server in (silent, impostor):
            server.bind(("127.0.0.1", 0))
            server.listen()

        def accept_and_never_answer():
            while True:
                held.append(silent.accept()[0])

        def babble():  # answers, but not as a dask scheduler
            connection, _ = impostor.accept()
            connection.sendall(b"HTTP/1.1 400 Bad Request\r\n\r\n" * 100)
            time.sleep(5)
            connection.close()

        threading.Thread(target=accept_and_never_answer, daemon=True).start()
        threading.Thread(target=babble, daemon=True).start()
        for server in (None, silent, impostor):
            address = f"tcp://127.0.0.1:{server.getsockname()[1]}" if server else closed
            started = time.perf_counter()
            assert (
                main(
                    [
                        "sweep",
                        "--torque",
                        "1",
                        "--stop-time",
                        "0.01",
                        "--scheduler",
                        address,
                        "--connect-timeout",
                        "2",
                        "--output-dir",
                        str(tmp_path),
                    ]
                )
                == 2
            )
            assert time.perf_counter() - started < 2 + 3  # the timeout, and a margin for a loaded machine
            err = capsys.readouterr().err
            assert err.count("\n") == 1 and f"no dask scheduler answered at {address} within 2 s" in err
        assert held  # the silent server was reached, and kept the connection open
    for connection in held:
        connection.close()


# --- signals and concurrent runs, with real processes --------------------------------------


def _sweep_command(output_dir, *arguments):
    default_fmu()  # built (when stale) here once, not by every process at once
    return [sys.executable, "-m", "pendulum_fmu", "sweep", "--output-dir", str(output_dir), *arguments]


@pytest.mark.cluster
@pytest.mark.parametrize(
    "signal_number, code, word", [(signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")]
)
def test_a_signal_stops_a_sweep_cleanly(tmp_path, signal_number, code, word):
    # Cases of 600 s kept every second: a chunk (4 of them, as its recordings hold every step)
    # steps for a tenth of a second or more, so the study is still running when its first part
    # appears (cases of 3 s had all finished once, on a loaded machine, before the signal came).
    settings = "--gravity 0 9.81 --stop-time 600 --output-interval 1 --workers 2"
    command = _sweep_command(tmp_path, "--torque", *map(str, range(1, 300)), *settings.split())
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not glob.glob(str(tmp_path / "cases" / "part-*")):
        assert process.poll() is None and time.monotonic() < deadline, process.communicate()
        time.sleep(0.05)
    children = psutil.Process(process.pid).children(recursive=True)
    os.kill(process.pid, signal_number)
    _out, err = process.communicate(timeout=60)
    assert process.returncode == code
    assert err.startswith(f"pendulum-fmu sweep: {word}; ") and err.count("\n") == 1, err
    _, alive = psutil.wait_procs(children, timeout=10)
    assert [p for p in alive if p.status() != psutil.STATUS_ZOMBIE] == []  # the cluster is down
    assert not list(tmp_path.glob("**/.*"))  # no temporaries
    written = sorted(p.name for p in tmp_path.glob("cases/part-*"))
    assert written and written == sorted(p.name for p in tmp_path.glob("trajectories/part-*"))
    # And what was written is whole: every part reads, a chunk's cases are consecutive, no case
    # twice, and each case's trajectory has its 601 points (0 to 600 s, one a second).
    parts = [_table(tmp_path / "cases" / name)["case"] for name in written]
    assert all(np.array_equal(case, np.arange(case[0], case[0] + len(case))) for case in parts)
    cases = np.concatenate(parts)
    assert 0 < len(cases) < 598 and len(np.unique(cases)) == len(cases)
    trajectories = _table(tmp_path / "trajectories")
    assert np.array_equal(trajectories["case"], np.repeat(np.sort(cases), 601))
    assert np.array_equal(trajectories["time"], np.tile(np.arange(601.0), len(cases)))


@pytest.mark.cluster
@pytest.mark.parametrize("delay", [0.3, 0.6, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0])
def test_ctrl_c_to_the_process_group_is_one_line_whenever_it_comes(tmp_path, delay):
    # As a terminal sends it: to every process of the group, the local cluster's workers too.
    # 400 cases of 600 s (only the cases table kept): still running after 4 s on any machine
    # (2 workers ran 400 cases of 60 s in 1.8 s here, after the Taylor integrator).
    study = tmp_path / "study"
    process = subprocess.Popen(
        _sweep_command(
            study,
            "--torque",
            *map(str, range(1, 201)),
            "--gravity",
            "0",
            "9.81",
            "--stop-time",
            "600",
            "--outputs",
            "none",
            "--run-in",
            "cluster",
        ),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    time.sleep(delay)
    assert process.poll() is None, process.communicate()
    os.killpg(process.pid, signal.SIGINT)
    _, err = process.communicate(timeout=120)
    assert process.returncode == 130 and err.count("\n") == 1, err
    assert err.startswith(
        (
            "pendulum-fmu: interrupted while starting",
            "pendulum-fmu sweep: interrupted;",
            "pendulum-fmu sweep: interrupted before anything was written",
        )
    )
    if "before anything was written" in err:
        assert not any(study.glob("*")), "nothing of the study is there"
    deadline = time.monotonic() + 30
    while any(_in_group(pid, process.pid) for pid in psutil.pids()):  # the cluster is down
        assert time.monotonic() < deadline
        time.sleep(0.1)


def _in_group(pid: int, group: int) -> bool:
    try:
        return os.getpgid(pid) == group and psutil.Process(pid).status() != psutil.STATUS_ZOMBIE
    except (ProcessLookupError, psutil.NoSuchProcess):
        return False


@pytest.mark.cluster
def test_eight_sweeps_into_eight_directories_at_once(tmp_path):
    processes = [
        subprocess.Popen(
            _sweep_command(
                tmp_path / f"study{i}", "--torque", str(i + 1.0), str(i + 2.0), "--stop-time", "0.05", "--workers", "1"
            ),
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for i in range(8)
    ]
    for i, process in enumerate(processes):
        _out, err = process.communicate(timeout=300)
        assert process.returncode == 0, err
        table = _table(tmp_path / f"study{i}" / "cases")
        for number, torque in enumerate((i + 1.0, i + 2.0)):
            run = simulate.simulate(torque, stop_time=0.05)
            assert table["final_theta"][number] == run["theta"][-1]


@pytest.mark.cluster
def test_a_second_run_into_a_folder_in_use_is_refused_and_the_first_is_whole(tmp_path, capsys):
    first = subprocess.Popen(
        _sweep_command(tmp_path, "--torque", *map(str, range(1, 201)), "--stop-time", "0.5", "--workers", "1"),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + 120
    while not (tmp_path / "study.json").exists() and first.poll() is None and time.monotonic() < deadline:
        time.sleep(0.1)
    # A different study into the same folder would replace the first one's parts as it runs.
    assert (
        main(
            ["sweep", "--torque", "1001", "1002", "--stop-time", "0.5", "--workers", "1", "--output-dir", str(tmp_path)]
        )
        == 2
    )
    refusal = capsys.readouterr().err.strip().splitlines()
    assert len(refusal) == 1 and "is in use by another run" in refusal[0], refusal
    _out, err = first.communicate(timeout=300)
    assert first.returncode == 0, err
    table = _table(tmp_path / "cases")
    assert table["torque"].tolist() == [float(t) for t in range(1, 201)]
    assert table["final_theta"][9] == simulate.simulate(10.0, stop_time=0.5)["theta"][-1]
    _assert_every_case_once(tmp_path, range(1, 201), 0.5)


# --- refused before any cluster starts ------------------------------------------------------

STUDY_FIELDS = ("stop_time", "step_size", "outputs", "output_interval", "format")


@pytest.mark.parametrize(
    "cases, options, message",
    [
        ([], {}, "no cases to run"),
        ([{"gravity": 1.0}], {}, "every case needs a 'torque'"),
        ([{"torque": 1.0}, {"torque": 1.0, "mass": 2.0}], {}, "case 1 has keys"),
        ([{"torque": 1.0, "colour": 2.0}], {}, "cannot sweep 'colour'"),
        ([{"torque": float("nan")}], {}, "case 0: torque = nan must be a finite number"),
        ([{"torque": "5"}], {}, "case 0: torque = '5' must be a finite number"),
        ([{"torque": 1.0}, {"torque": 2.0}, {"torque": 1.0}], {}, "case 2 repeats case 0"),
        ([{"torque": 1.0}], {"step_size": 0.0}, "step size 0.0 must be positive"),
        ([{"torque": 1.0}], {"stop_time": float("inf")}, "stop time inf must be a finite number"),
        ([{"torque": 1.0}], {"workers": 0}, "workers must be a positive integer"),
        ([{"torque": 1.0}], {"workers": 2, "scheduler": "tcp://127.0.0.1:1"}, "workers sizes the local cluster"),
        ([{"torque": 1.0}], {"outputs": ["theta", "torque"]}, "choose each at most once among theta, omega, alpha"),
        ([{"torque": 1.0}], {"outputs": ["theta", "theta"]}, "choose each at most once"),
        ([{"torque": 1.0}], {"output_interval": 0.0015}, "output interval 0.0015 s must be a whole number of steps"),
        ([{"torque": 1.0}], {"output_interval": 0.0}, "output interval 0.0 s must be"),
        ([{"torque": 1.0}], {"format": "xlsx"}, "format 'xlsx': choose parquet or csv"),
        ([{"torque": 1.0}], {"connect_timeout": 0}, "connect timeout 0 must be a positive number"),
        ([{"torque": 1.0}], {"connect_timeout": float("inf")}, "connect timeout inf must be a positive"),
        ([{"torque": 1.0}, {"torque": 2.0}, {"torque": 3.0}], {"max_cases": 2}, "3 cases is over the limit of 2"),
        (
            [{"torque": 1.0}],
            {"resume": True, "overwrite": True},
            "resume continues .* and overwrite replaces it: choose one",
        ),
    ],
)
def test_bad_runs_are_refused_before_any_cluster_starts(tmp_path, cases, options, message):
    study_options = {k: v for k, v in options.items() if k in STUDY_FIELDS}
    with pytest.raises(InvalidInput, match=message):
        run_sweep(
            Study(cases, **study_options),
            output_dir=tmp_path,
            **{k: v for k, v in options.items() if k not in study_options},
        )
    assert list(tmp_path.iterdir()) == []
