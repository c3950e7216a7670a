"""Parameter studies on dask: the native loop against the Python loop, the written study against
simulate() and the analytic and scipy references, resume, failures, fsspec URLs, a cluster of
separate processes, signals and concurrent runs."""

import glob
import logging
import os
import signal
import socket
import subprocess
import sys
import threading
import time

import numpy as np
import psutil
import pyarrow.csv
import pyarrow.dataset as ds
import pytest
from dask.distributed import Client, LocalCluster

import benchmarks.scale

from pendulum_fmu import cs_loop, simulate
from pendulum_fmu import default_fmu
from pendulum_fmu.cli import main
from pendulum_fmu.parameters import value_reference
from pendulum_fmu.reference import reference, reference_schedule
from pendulum_fmu.signal import TorqueTable, schedule
from pendulum_fmu.sweep import OUTPUTS, run_sweep, sweep_grid

I_TOTAL = 20.0 + 40.0 * 0.5**2  # the tutorial's pendulum about its pivot
STOP_TIME, STEP_SIZE = 0.5, 1e-3
POINTS = 501


def _table(path, format="parquet", filesystem=None) -> dict[str, np.ndarray]:
    """A study's table as numpy columns, sorted by case (and time)."""
    if format == "csv":
        format = ds.CsvFileFormat(convert_options=pyarrow.csv.ConvertOptions(
            column_types={"message": pyarrow.string()}, strings_can_be_null=False))
    table = ds.dataset(str(path), format=format, filesystem=filesystem).to_table()
    keys = [("case", "ascending")] + ([("time", "ascending")] if "time" in table.column_names else [])
    table = table.sort_by(keys)
    return {name: table[name].to_numpy(zero_copy_only=False) for name in table.column_names}


def _exact(case: dict, stride: int = 1) -> np.ndarray:
    """The case through simulate(), the readable path, at the points a study keeps."""
    parameters = {k: v for k, v in case.items() if k not in ("torque", "theta0", "omega0")}
    run = simulate.simulate(case["torque"], parameters=parameters, theta0=case.get("theta0", 0.0),
                            omega0=case.get("omega0", 0.0), stop_time=STOP_TIME, step_size=STEP_SIZE)
    keep = np.unique(np.append(np.arange(0, len(run), stride), len(run) - 1))
    return run[keep]


@pytest.fixture(autouse=True)
def _built_fmu(fmu, monkeypatch):
    """Every study here runs the FMU built for this session."""
    monkeypatch.setattr("pendulum_fmu.sweep.default_fmu", lambda: fmu)


# --- the native loop ------------------------------------------------------------------------

def test_the_native_loop_is_built():
    assert cs_loop.available(), "build it: pip install -e ."


@pytest.mark.parametrize("ramp", [False, True])
def test_native_loop_matches_the_python_loop_bit_for_bit(fmu, ramp):
    # Uneven steps: a jump at 0.2505 s becomes a communication point between two 1 ms steps.
    table = TorqueTable(time=np.array([0.0, 0.2505, 0.2505, 0.6]), torque=np.array([5.0, 30.0, -8.0, 12.0]))
    plan = schedule(table, step_size=1e-3, ramp=ramp)
    assert len(set(np.round(np.diff(plan.time), 12))) > 1
    runs = []
    for loop in (simulate.run_schedule, simulate.run_schedule_python):
        slave = simulate.open_fmu(fmu, parameters={"damping": 1.5}, theta0=0.2)
        try:
            runs.append(loop(slave, plan))
        finally:
            slave.terminate()
            slave.freeInstance()
    native, python = runs
    for name in native.dtype.names:
        assert np.array_equal(native[name], python[name]), name
    # And both are the physics: the scipy oracle of the same schedule.
    oracle = reference_schedule(plan, theta0=0.2, parameters={"damping": 1.5})
    assert np.max(np.abs(native["theta"] - oracle["theta"])) < 1e-9


def test_native_loop_reports_the_failing_step(fmu):
    slave = simulate.open_fmu(fmu)
    try:
        plan = schedule(1.0, stop_time=0.01, step_size=1e-3)
        wrong = plan.time + 0.5  # fmi2DoStep refuses a step from where the instance is not
        with pytest.raises(simulate.FmuError, match=r"fmi2DoStep at t = 0.5 returned ERROR: .*not where"):
            stepper = cs_loop.Stepper(slave, np.array([0], np.uint32), np.array([1, 2, 3], np.uint32))
            stepper.run(wrong, plan.torque[:, None].copy(), None, np.empty((len(wrong), 3)))
    finally:
        slave.freeInstance()


def test_native_restart_matches_a_fresh_instance_bit_for_bit(fmu):
    """A restart in C (fmi2Reset, initialization with new start values, the torque among them)
    gives what a new instance initialized in Python and fed the torque every step gives."""
    plan = schedule(12.0, stop_time=0.2, step_size=1e-3)
    names = ("mass", "damping", "theta", "torque")
    references = np.array([value_reference(n, fmu) for n in names], np.uint32)
    outputs = np.array([value_reference(n, fmu) for n in OUTPUTS], np.uint32)
    slave = simulate.open_fmu(fmu)  # initialized with the defaults, then restarted twice
    try:
        stepper = cs_loop.Stepper(slave, np.empty(0, np.uint32), outputs, references)
        for mass in (30.0, 55.0):
            restarted = np.empty((len(plan.time), 3))
            stepper.run(plan.time, None, None, restarted, start_values=np.array([mass, 2.0, 0.4, 12.0]))
            fresh = simulate.open_fmu(fmu, parameters={"mass": mass, "damping": 2.0}, theta0=0.4)
            try:
                expected = simulate.run_schedule_python(fresh, plan)
            finally:
                fresh.freeInstance()
            for column, name in enumerate(OUTPUTS):
                assert np.array_equal(restarted[:, column], expected[name]), (mass, name)
        with pytest.raises(simulate.FmuError, match="initialization failed: .*mass must be > 0"):
            stepper.run(plan.time, None, None, restarted, start_values=np.array([-1.0, 0.0, 0.0, 0.0]))
    finally:
        slave.freeInstance()


# --- studies on a local cluster -------------------------------------------------------------

@pytest.fixture(scope="module")
def threads_scheduler():
    """Workers as threads of this process: quick to start, and they share its memory:// file system."""
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=":0",
                      silence_logs=logging.WARNING) as cluster:
        yield cluster.scheduler_address



def test_grid_on_a_local_cluster_matches_simulate_bit_for_bit(tmp_path, capsys):
    cases = sweep_grid([5.0, 20.0], [0.0, 9.81])
    summary = run_sweep(cases, output_dir=tmp_path, stop_time=STOP_TIME, step_size=STEP_SIZE,
                        workers=2)
    assert "4/4 cases, 0 failed" in capsys.readouterr().err
    assert (summary["cases"], summary["failed"], summary["chunks_run"]) == (4, 0, summary["chunks"])
    trajectories, table = _table(summary["trajectories"]), _table(summary["cases_table"])
    assert set(trajectories) == {"case", "time", *OUTPUTS} and len(trajectories["case"]) == 4 * POINTS
    assert summary["bytes"] == sum(p.stat().st_size for p in tmp_path.glob("*/part-*.parquet"))
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
    figure = summary["figure"].read_bytes()
    assert figure[:8] == b"\x89PNG\r\n\x1a\n" and len(figure) > 10_000


def test_csv_with_chosen_outputs_and_interval(tmp_path, threads_scheduler):
    cases = [{"torque": 10.0, "damping": 0.0, "theta0": 0.3}, {"torque": 10.0, "damping": 4.0, "theta0": 0.3}]
    summary = run_sweep(cases, output_dir=tmp_path, stop_time=STOP_TIME, step_size=STEP_SIZE,
                        outputs=["theta"], output_interval=0.007, format="csv",
                        scheduler=threads_scheduler, progress=False)
    trajectories = _table(summary["trajectories"], "csv")
    assert set(trajectories) == {"case", "time", "theta"}
    for number, case in enumerate(cases):
        rows = trajectories["case"] == number
        expected = _exact(case, stride=7)
        assert expected["time"][-1] == STOP_TIME and np.diff(expected["time"])[-1] < 0.007
        # The CSV's shortest round-trip digits read back as the same doubles.
        assert np.array_equal(trajectories["time"][rows], expected["time"])
        assert np.array_equal(trajectories["theta"][rows], expected["theta"])
        oracle = reference(10.0, stop_time=STOP_TIME, step_size=STEP_SIZE, theta0=0.3,
                           parameters={"damping": case["damping"]})
        assert abs(expected["theta"][-1] - oracle["theta"][-1]) < 1e-10
    assert _table(summary["cases_table"], "csv")["damping"].tolist() == [0.0, 4.0]


def test_a_case_the_fmu_refuses_is_recorded_and_the_rest_go_on(tmp_path, threads_scheduler):
    cases = sweep_grid([1.0, 2.0], [9.81], {"mass": [0.0, 1.0], "length": [0.0, 0.5], "inertia": [0.0]})
    summary = run_sweep(cases, output_dir=tmp_path, stop_time=0.05, step_size=STEP_SIZE,
                        scheduler=threads_scheduler, progress=False)
    table, trajectories = _table(summary["cases_table"]), _table(summary["trajectories"])
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
    assert summary["failed"] == 6 and len(table["case"]) == 8


def test_resume_runs_only_the_chunks_not_written(tmp_path, threads_scheduler):
    cases = sweep_grid(list(np.linspace(1.0, 40.0, 70)), [9.81])  # 2 cases per chunk, 35 chunks
    first = run_sweep(cases, output_dir=tmp_path, stop_time=0.05, scheduler=threads_scheduler,
                      progress=False)
    parts = sorted(tmp_path.glob("cases/part-*.parquet"))
    assert first["chunks"] == len(parts) == 35
    # As if interrupted: three chunks never finished (one wrote its trajectories only).
    for index in (0, 17, 34):
        parts[index].unlink()
    (tmp_path / "trajectories" / "part-000005.parquet").unlink()  # its cases part still says done
    kept = {p.name: p.stat().st_mtime_ns for p in tmp_path.glob("cases/part-*.parquet")}
    again = run_sweep(cases, output_dir=tmp_path, stop_time=0.05, resume=True,
                      scheduler=threads_scheduler, progress=False)
    assert again["chunks_run"] == 3 and again["cases"] == 70
    assert {p.name: p.stat().st_mtime_ns for p in tmp_path.glob("cases/part-*.parquet") if p.name in kept} == kept
    table = _table(again["cases_table"])
    assert table["case"].tolist() == list(range(70))
    for number in (0, 1, 34, 35, 68, 69):
        run = simulate.simulate(cases[number]["torque"], stop_time=0.05)
        assert table["final_theta"][number] == run["theta"][-1]
    with pytest.raises(ValueError, match="holds a different study .*stop_time"):
        run_sweep(cases, output_dir=tmp_path, stop_time=0.06, resume=True, progress=False)
    # Without --resume a new study replaces the old one.
    fresh = run_sweep(cases[:3], output_dir=tmp_path, stop_time=0.05, scheduler=threads_scheduler,
                      progress=False)
    assert fresh["chunks_run"] == fresh["chunks"] and len(_table(fresh["cases_table"])["case"]) == 3
    assert not list(tmp_path.glob("**/.*"))


def test_output_to_a_file_url(tmp_path):
    summary = run_sweep(sweep_grid([3.0, 6.0]), output_dir=tmp_path.as_uri(), stop_time=0.1,
                        workers=1, progress=False)
    assert summary["figure"] == tmp_path / "sweep.png" and summary["figure"].exists()
    table = _table(tmp_path / "cases")
    run = simulate.simulate(6.0, stop_time=0.1)
    assert table["final_theta"][1] == run["theta"][-1]


def test_output_to_fsspec_memory(threads_scheduler):
    import fsspec

    summary = run_sweep(sweep_grid([3.0, 6.0], [0.0]), output_dir="memory://study", stop_time=0.1,
                        scheduler=threads_scheduler, progress=False)
    assert summary["figure"] == "memory://study/sweep.png"
    filesystem = fsspec.filesystem("memory")
    assert filesystem.cat("/study/sweep.png")[:4] == b"\x89PNG"
    trajectories = _table("/study/trajectories", filesystem=filesystem)
    rows = trajectories["case"] == 1
    assert np.max(np.abs(trajectories["theta"][rows] - 3.0 / I_TOTAL * trajectories["time"][rows] ** 2)) < 1e-12
    assert not [path for path in filesystem.find("/study") if "/." in path]


def test_a_failed_write_to_a_url_leaves_neither_file_nor_temporary():
    import fsspec

    from pendulum_fmu.files import replacing_on

    filesystem = fsspec.filesystem("memory")
    with replacing_on(filesystem, "/writes/kept.bin") as file:
        file.write(b"whole")
    with pytest.raises(RuntimeError), replacing_on(filesystem, "/writes/lost.bin") as file:
        file.write(b"half")
        raise RuntimeError("interrupted")
    assert filesystem.find("/writes") == ["/writes/kept.bin"]
    assert filesystem.cat("/writes/kept.bin") == b"whole"


def test_band_quantiles_are_numpys_per_value():
    from pendulum_fmu.plot import BAND_LEVELS, _quantiles

    rng = np.random.default_rng(7)
    x, y = rng.integers(0, 9, 2000).astype(float), rng.normal(size=2000)
    levels, values = _quantiles(x, y, [0.05, 0.5, 0.75])
    assert levels.tolist() == sorted(set(x.tolist()))
    for i, level in enumerate(levels):
        assert np.allclose([v[i] for v in values], np.quantile(y[x == level], [0.05, 0.5, 0.75]),
                           rtol=0, atol=1e-12)
    many = rng.uniform(0.0, 1.0, 5000)  # more distinct values than levels: pooled into bins
    levels, (median,) = _quantiles(many, many, [0.5])
    assert len(levels) == BAND_LEVELS and np.max(np.abs(median - levels)) < 0.5 / BAND_LEVELS


def test_many_cases_draw_quantile_bands(tmp_path, threads_scheduler):
    cases = sweep_grid(list(np.linspace(0.0, 40.0, 8)), [0.0, 9.81], {"damping": [0.0, 1.0]})
    summary = run_sweep(cases, output_dir=tmp_path, stop_time=0.05, outputs=[],
                        scheduler=threads_scheduler, progress=False)
    assert not (tmp_path / "trajectories").exists()  # no outputs: the cases table alone
    assert summary["figure"].read_bytes()[:4] == b"\x89PNG"


# --- a cluster of separate processes, as on a real cluster ---------------------------------

@pytest.fixture
def dask_processes():
    """`dask scheduler` and two `dask worker`s on localhost, each its own process."""
    with benchmarks.scale.dask_processes(2) as address:
        yield address


def test_a_study_on_a_scheduler_and_workers_started_as_processes(tmp_path, dask_processes, fmu, capsys):
    assert main(["sweep", "--torque", "2", "4", "8", "16", "--gravity", "0", "9.81",
                 "--stop-time", "0.2", "--scheduler", dask_processes,
                 "--output-dir", str(tmp_path)]) == 0
    assert "8 cases" in capsys.readouterr().out
    table = _table(tmp_path / "cases")
    for number, (torque, gravity) in enumerate([(t, g) for t in (2, 4, 8, 16) for g in (0.0, 9.81)]):
        expected = (0.5 * torque / I_TOTAL * 0.2**2 if gravity == 0.0 else
                    reference(float(torque), stop_time=0.2, step_size=STEP_SIZE)["theta"][-1])
        assert abs(table["final_theta"][number] - expected) < 1e-10
    with Client(dask_processes) as client:
        # Both workers ran chunks, each unzipping the FMU once.
        assert list(client.run(lambda: len(simulate._extracted)).values()) == [1, 1]


def test_a_chunk_whose_worker_dies_is_run_again(tmp_path, dask_processes):
    cases = sweep_grid(list(np.linspace(1.0, 40.0, 256)), [9.81])  # 64 chunks of 4 cases
    summary = {}
    study = threading.Thread(target=lambda: summary.update(run_sweep(
        cases, output_dir=tmp_path, stop_time=10.0, outputs=[], scheduler=dask_processes,
        progress=False)))
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
    assert summary["cases"] == 256 and summary["failed"] == 0
    table = _table(tmp_path / "cases")
    assert table["case"].tolist() == list(range(256)) and set(table["status"]) == {"ok"}
    assert table["final_theta"][255] == simulate.simulate(40.0, stop_time=10.0)["theta"][-1]
    assert not list(tmp_path.glob("**/.*"))


def test_an_unreachable_or_wrong_scheduler_is_one_line_within_the_timeout(tmp_path, capsys):
    closed = f"tcp://127.0.0.1:{benchmarks.scale.free_port()}"
    with socket.socket() as impostor:  # answers, but not as a dask scheduler
        impostor.bind(("127.0.0.1", 0))
        impostor.listen()

        def babble():
            connection, _ = impostor.accept()
            connection.sendall(b"HTTP/1.1 400 Bad Request\r\n\r\n" * 100)
            time.sleep(5)
            connection.close()

        threading.Thread(target=babble, daemon=True).start()
        wrong = f"tcp://127.0.0.1:{impostor.getsockname()[1]}"
        for address in (closed, wrong):
            started = time.perf_counter()
            assert main(["sweep", "--torque", "1", "--stop-time", "0.01", "--scheduler", address,
                         "--connect-timeout", "2", "--output-dir", str(tmp_path)]) == 2
            assert time.perf_counter() - started < 10
            err = capsys.readouterr().err
            assert err.count("\n") == 1 and f"no dask scheduler answered at {address} within 2 s" in err


# --- signals and concurrent runs, with real processes --------------------------------------

def _sweep_command(output_dir, *arguments):
    default_fmu()  # built (when stale) here once, not by every process at once
    return [sys.executable, "-m", "pendulum_fmu.cli", "sweep", "--output-dir", str(output_dir), *arguments]


@pytest.mark.parametrize("signal_number, code, word", [(signal.SIGINT, 130, "interrupted"),
                                                       (signal.SIGTERM, 143, "terminated")])
def test_a_signal_stops_a_sweep_cleanly(tmp_path, signal_number, code, word):
    command = _sweep_command(tmp_path, "--torque", *map(str, range(1, 300)), "--gravity", "0", "9.81",
                             "--workers", "2")
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not glob.glob(str(tmp_path / "cases" / "part-*")):
        assert process.poll() is None and time.monotonic() < deadline, process.communicate()
        time.sleep(0.05)
    children = psutil.Process(process.pid).children(recursive=True)
    os.kill(process.pid, signal_number)
    out, err = process.communicate(timeout=60)
    assert process.returncode == code
    assert err.startswith(f"pendulum-fmu sweep: {word}; ") and err.count("\n") == 1, err
    _, alive = psutil.wait_procs(children, timeout=10)
    assert [p for p in alive if p.status() != psutil.STATUS_ZOMBIE] == []  # the cluster is down
    assert not list(tmp_path.glob("**/.*"))  # no temporaries
    written = sorted(p.name for p in tmp_path.glob("cases/part-*"))
    assert written and written == sorted(p.name for p in tmp_path.glob("trajectories/part-*"))
    # And what was written is whole: every part reads, with the cases it should hold (598 cases
    # in chunks of 10).
    chunks = [int(name[5:11]) for name in written]
    assert len(_table(tmp_path / "cases")["case"]) == sum(min(10, 598 - 10 * i) for i in chunks)


def test_eight_sweeps_into_eight_directories_at_once(tmp_path):
    processes = [subprocess.Popen(_sweep_command(tmp_path / f"study{i}", "--torque", str(i + 1.0),
                                                 str(i + 2.0), "--stop-time", "0.05", "--workers", "1"),
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
                 for i in range(8)]
    for i, process in enumerate(processes):
        out, err = process.communicate(timeout=300)
        assert process.returncode == 0, err
        table = _table(tmp_path / f"study{i}" / "cases")
        for number, torque in enumerate((i + 1.0, i + 2.0)):
            run = simulate.simulate(torque, stop_time=0.05)
            assert table["final_theta"][number] == run["theta"][-1]


def test_a_second_run_into_a_folder_in_use_is_refused_and_the_first_is_whole(tmp_path, capsys):
    first = subprocess.Popen(_sweep_command(tmp_path, "--torque", *map(str, range(1, 201)),
                                            "--stop-time", "0.5", "--workers", "1"),
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not (tmp_path / "study.json").exists() and first.poll() is None and time.monotonic() < deadline:
        time.sleep(0.1)
    # A different study into the same folder would replace the first one's parts as it runs.
    assert main(["sweep", "--torque", "1001", "1002", "--stop-time", "0.5", "--workers", "1",
                 "--output-dir", str(tmp_path)]) == 2
    refusal = capsys.readouterr().err.strip().splitlines()
    assert len(refusal) == 1 and "is in use by another run" in refusal[0], refusal
    out, err = first.communicate(timeout=300)
    assert first.returncode == 0, err
    table = _table(tmp_path / "cases")
    assert table["torque"].tolist() == [float(t) for t in range(1, 201)]
    assert table["final_theta"][9] == simulate.simulate(10.0, stop_time=0.5)["theta"][-1]


# --- refused before any cluster starts ------------------------------------------------------

@pytest.mark.parametrize("arguments, message", [
    (([1.0], [9.81], {"colour": [1.0]}), "cannot sweep 'colour': extra takes mass, length, inertia, damping"),
    (([1.0], [9.81], {"gravity": [1.0]}), "give gravity values as the gravities argument"),
    (([], [9.81]), "no values given for torque"),
    (([1.0], [9.81], {"mass": []}), "no values given for mass"),
    (([1.0], [float("nan")]), "gravity values must be finite"),
    (([float("inf")],), "torque values must be finite"),
    ((["heavy"],), "torque values must be numbers"),
    (([[1.0, 2.0]],), "torque values must be a flat list"),
    (([1.0, 2.0, 1.0],), "torque values repeat"),
])
def test_bad_grids(arguments, message):
    with pytest.raises(ValueError, match=message):
        sweep_grid(*arguments)


def test_a_grid_is_the_product_of_its_axes():
    grid = sweep_grid([1.0, 2.0], [0.0, 9.81], {"damping": [0.5, 1.5, 2.5]})
    assert len(grid) == 12 and grid[0] == {"torque": 1.0, "gravity": 0.0, "damping": 0.5}
    assert grid[-1] == {"torque": 2.0, "gravity": 9.81, "damping": 2.5}
    assert grid[7] == {"torque": 2.0, "gravity": 0.0, "damping": 1.5}
    with pytest.raises(IndexError):
        grid[12]


@pytest.mark.parametrize("cases, options, message", [
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
])
def test_bad_runs_are_refused_before_any_cluster_starts(tmp_path, cases, options, message):
    with pytest.raises(ValueError, match=message):
        run_sweep(cases, output_dir=tmp_path, **options)
    assert list(tmp_path.iterdir()) == []
