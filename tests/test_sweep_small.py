"""Small studies in the calling process (issue 42): the files a local cluster writes, bit for bit
and each case simulate()'s; resumed by either way of running, whichever began; stopped by a
signal, resumable; and the rule that chooses where a study runs.
"""

import json
import os
import signal
import subprocess
import time

import numpy as np
import psutil
import pytest
from test_sweep import OUTPUTS, STEP_SIZE, STOP_TIME, _assert_every_case_once, _exact, _sweep_command, _table

from pendulum_fmu import simulate
from pendulum_fmu._errors import InvalidInput
from pendulum_fmu.signals._time_grid import BREAK_EVEN_STEPS
from pendulum_fmu.sweep import Study, close_kept_clusters, run_sweep, sweep_grid
from pendulum_fmu.sweep.here import runs_here


@pytest.fixture(autouse=True)
def _built_fmu(fmu, monkeypatch):
    """Every study here runs the FMU built for this session."""
    monkeypatch.setattr("pendulum_fmu.default_fmu", lambda: fmu)


def _running(pid: int) -> bool:
    try:
        return psutil.Process(pid).status() != psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return False


def _files(folder) -> list[str]:
    return sorted(str(path.relative_to(folder)) for path in folder.rglob("*"))


def test_a_study_in_the_process_writes_what_a_local_cluster_writes_bit_for_bit(tmp_path):
    cases = sweep_grid([5.0, 20.0], [0.0, 9.81])
    study = Study(cases, stop_time=STOP_TIME, step_size=STEP_SIZE)
    here = run_sweep(study, output_dir=tmp_path / "here", progress=False)  # small: run here unasked
    cluster = run_sweep(study, output_dir=tmp_path / "cluster", progress=False, run_in="cluster")
    assert (here.ran_in, cluster.ran_in) == ("process", "cluster")
    assert (here.cases, here.failed, here.chunks, here.chunks_run) == (4, 0, 4, 4)
    assert _files(tmp_path / "here") == _files(tmp_path / "cluster")
    mine, its = (json.loads((tmp_path / where / "study.json").read_text()) for where in ("here", "cluster"))
    assert mine.pop("run") != its.pop("run") and mine == its  # each run its own token; the same study
    for table in ("trajectories", "cases"):
        mine, its = _table(tmp_path / "here" / table), _table(tmp_path / "cluster" / table)
        assert mine.keys() == its.keys()
        for column in mine:
            assert np.array_equal(mine[column], its[column]), (table, column)
    # And each case is simulate()'s, the readable path, bit for bit.
    trajectories, table = _table(here.trajectories), _table(here.cases_table)
    for number, case in enumerate(cases):
        expected, rows = _exact(case), trajectories["case"] == number
        for name in ("time", *OUTPUTS):
            assert np.array_equal(trajectories[name][rows], expected[name]), name
        assert table["final_theta"][number] == expected["theta"][-1]
    assert here.figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("first, then", [("process", "cluster"), ("cluster", "process")])
def test_either_way_of_running_resumes_what_the_other_began(tmp_path, first, then):
    torques = [float(t) for t in np.linspace(1.0, 40.0, 12)]  # a case per chunk
    study = Study(sweep_grid(torques, [9.81]), stop_time=0.05)
    assert run_sweep(study, output_dir=tmp_path, run_in=first, progress=False).ran_in == first
    parts = sorted(tmp_path.glob("cases/part-*.parquet"))
    for index in (0, 5, 11):  # as if interrupted: three chunks never finished
        parts[index].unlink()
    kept = {p.name: p.stat().st_mtime_ns for p in tmp_path.glob("cases/part-*.parquet")}
    again = run_sweep(study, output_dir=tmp_path, resume=True, run_in=then, progress=False)
    assert (again.ran_in, again.chunks_run, again.chunks) == (then, 3, 12)
    assert {p.name: p.stat().st_mtime_ns for p in tmp_path.glob("cases/part-*.parquet") if p.name in kept} == kept
    _assert_every_case_once(tmp_path, torques, 0.05, sample=12)


def test_where_a_study_runs_is_chosen_by_the_steps_it_has_still_to_run(tmp_path, monkeypatch):
    assert runs_here("auto", None, None, BREAK_EVEN_STEPS - 1)
    assert not runs_here("auto", None, None, BREAK_EVEN_STEPS)
    # A scheduler or a worker count asks for a cluster, and "cluster" or "process" decide.
    assert not runs_here("auto", "tls://127.0.0.1:8786", None, 1)
    assert not runs_here("auto", None, 2, 1)
    assert not runs_here("cluster", None, None, 1)
    assert runs_here("process", None, None, 10 * BREAK_EVEN_STEPS)
    # In a run: a study of 4 cases of 50 steps, over a break-even of 150 steps, goes to a cluster;
    # resumed with 2 of them still to run, here.
    monkeypatch.setattr("pendulum_fmu.sweep.here.BREAK_EVEN_STEPS", 150)

    def no_cluster(*arguments):
        raise RuntimeError("a cluster was asked for")

    monkeypatch.setattr("pendulum_fmu.sweep.run.dask_client", no_cluster)
    study = Study(sweep_grid([1.0, 2.0, 3.0, 4.0]), stop_time=0.05)
    with pytest.raises(RuntimeError, match="a cluster was asked for"):
        run_sweep(study, output_dir=tmp_path / "fresh", progress=False)
    run_sweep(study, output_dir=tmp_path, run_in="process", progress=False)
    for part in sorted(tmp_path.glob("cases/part-*.parquet"))[1:3]:
        part.unlink()
    again = run_sweep(study, output_dir=tmp_path, resume=True, progress=False)
    assert (again.ran_in, again.chunks_run) == ("process", 2)


@pytest.mark.parametrize(
    "options, message",
    [
        ({"run_in": "elsewhere"}, "run_in 'elsewhere': choose auto, process, cluster"),
        ({"run_in": "process", "workers": 2}, r"run_in 'process' \(--run-in process\) runs the study in this process"),
        ({"run_in": "process", "scheduler": "tcp://127.0.0.1:1"}, "give it no scheduler nor workers"),
    ],
)
def test_a_place_that_contradicts_the_options_is_refused_before_anything_runs(tmp_path, options, message):
    with pytest.raises(InvalidInput, match=message):
        run_sweep(Study(sweep_grid([1.0]), stop_time=0.05), output_dir=tmp_path, **options)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "signal_number, code, word", [(signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")]
)
def test_a_signal_stops_a_study_in_the_process_and_resume_finishes_it(tmp_path, signal_number, code, word):
    # 300 cases of 120 s, in chunks of 5 (60 chunks of 0.6 million steps): a few seconds in all,
    # so the study is still running when its first part appears.
    torques = range(1, 301)
    settings = ["--stop-time", "120", "--output-interval", "1", "--run-in", "process"]
    command = _sweep_command(tmp_path, "--torque", *map(str, torques), *settings)
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not list(tmp_path.glob("cases/part-*")):
        assert process.poll() is None and time.monotonic() < deadline, process.communicate()
        time.sleep(0.02)
    process.send_signal(signal_number)
    _out, err = process.communicate(timeout=60)
    assert process.returncode == code, err
    assert err == (
        f"pendulum-fmu sweep: {word}; the chunks that finished are kept in {tmp_path}: run the same "
        "command with --resume to run the rest\n"
    )
    assert not list(tmp_path.glob("**/.*"))  # no temporaries, no staged part, no lock
    written = sorted(p.name for p in tmp_path.glob("cases/part-*"))
    assert 0 < len(written) < 60 and written == sorted(p.name for p in tmp_path.glob("trajectories/part-*"))
    resumed = subprocess.run([*command, "--resume"], capture_output=True, text=True, timeout=300)
    assert resumed.returncode == 0, resumed.stderr
    assert f"({60 - len(written)} of 60 chunks run;" in resumed.stdout
    _assert_every_case_once(tmp_path, torques, 120.0, stride=1000)


def test_a_kept_cluster_serves_the_next_studies_and_goes_with_one_that_stops(tmp_path, monkeypatch):
    from pendulum_fmu.sweep import client

    torques = [1.0, 2.0, 3.0]
    study = Study(sweep_grid(torques), stop_time=0.05)
    options = {"run_in": "cluster", "workers": 1, "keep_cluster": True, "progress": False}
    try:
        run_sweep(study, output_dir=tmp_path / "first", **options)
        kept = client._kept[1][0]
        workers = kept.run(os.getpid)
        run_sweep(study, output_dir=tmp_path / "second", **options)
        assert client._kept[1][0] is kept and kept.run(os.getpid) == workers  # the same processes
        for folder in ("first", "second"):
            _assert_every_case_once(tmp_path / folder, torques, 0.05, sample=3)

        def stopped(*arguments):
            raise KeyboardInterrupt

        monkeypatch.setattr("pendulum_fmu.sweep.run.run_chunks", stopped)
        with pytest.raises(KeyboardInterrupt):
            run_sweep(study, output_dir=tmp_path / "third", **options)
        assert client._kept == {}
        deadline = time.monotonic() + 30
        while any(_running(pid) for pid in workers.values()):  # the cluster is down
            assert time.monotonic() < deadline
            time.sleep(0.1)
        monkeypatch.undo()
        run_sweep(study, output_dir=tmp_path / "fourth", **options)  # a new one, kept in turn
        assert close_kept_clusters(2) == 0 and close_kept_clusters() == 1 and client._kept == {}
    finally:
        close_kept_clusters()
    with pytest.raises(InvalidInput, match="keep_cluster keeps a local cluster"):
        run_sweep(study, output_dir=tmp_path / "fifth", scheduler="tcp://127.0.0.1:1", keep_cluster=True)


def test_no_figure_writes_the_tables_alone_and_names_only_them(tmp_path, capsys):
    from pendulum_fmu.cli import main

    command = ["sweep", "--torque", "2", "4", "--stop-time", "0.1", "--no-figure", "--output-dir", str(tmp_path)]
    assert main(command) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[1:] == [f"wrote {tmp_path / 'trajectories'}", f"wrote {tmp_path / 'cases'}"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cases", "study.json", "trajectories"]
    final_theta = [simulate(torque, stop_time=0.1)["theta"][-1] for torque in (2.0, 4.0)]
    assert _table(tmp_path / "cases")["final_theta"].tolist() == final_theta
