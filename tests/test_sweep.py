"""The parameter study on dask, against the analytic parabola and the scipy oracle."""

import logging

import numpy as np
import pytest
from dask.distributed import Client, LocalCluster

from pendulum_fmu import simulate
from pendulum_fmu.reference import reference
from pendulum_fmu.sweep import run_sweep, sweep_grid

I_TOTAL = 20.0 + 40.0 * 0.5**2  # the tutorial's pendulum about its pivot
STOP_TIME, STEP_SIZE = 0.5, 1e-3
POINTS = 501


def _read(path):
    return np.genfromtxt(path, delimiter=",", names=True)


def test_grid_on_a_local_cluster(fmu, tmp_path, capsys):
    cases = sweep_grid([5.0, 20.0], [0.0, 9.81])
    summary = run_sweep(cases, output_dir=tmp_path, stop_time=STOP_TIME, step_size=STEP_SIZE,
                        workers=2, fmu_path=fmu)
    assert "4/4 cases" in capsys.readouterr().err
    assert summary["cases"] == 4 and summary["seconds"] > 0
    table = _read(summary["results"])
    assert table.dtype.names == ("case", "torque", "gravity", "time", "theta", "omega", "alpha")
    assert len(table) == 4 * POINTS
    for number, case in enumerate(cases):
        rows = table[table["case"] == number]
        assert np.all(rows["torque"] == case["torque"]) and np.all(rows["gravity"] == case["gravity"])
        t = rows["time"]
        if case["gravity"] == 0.0:
            expected = 0.5 * (case["torque"] / I_TOTAL) * t**2
        else:
            expected = reference(case["torque"], stop_time=STOP_TIME, step_size=STEP_SIZE)["theta"]
        assert np.max(np.abs(rows["theta"] - expected)) < (1e-12 if case["gravity"] == 0.0 else 1e-10)
    figure = summary["figure"].read_bytes()
    assert figure[:8] == b"\x89PNG\r\n\x1a\n" and len(figure) > 10_000


@pytest.fixture(scope="module")
def scheduler():
    with LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=":0",
                      silence_logs=logging.WARNING) as cluster:
        yield cluster.scheduler_address


def test_extra_parameters_on_a_running_scheduler(fmu, tmp_path, scheduler):
    cases = sweep_grid([10.0], [9.81], {"damping": [0.0, 4.0], "theta0": [0.3]})
    summary = run_sweep(cases, output_dir=tmp_path, stop_time=STOP_TIME, step_size=STEP_SIZE,
                        scheduler=scheduler, progress=False, fmu_path=fmu)
    table = _read(summary["results"])
    assert table.dtype.names == ("case", "torque", "gravity", "damping", "theta0",
                                 "time", "theta", "omega", "alpha")
    for number, case in enumerate(cases):
        rows = table[table["case"] == number]
        assert np.all(rows["damping"] == case["damping"])
        oracle = reference(10.0, stop_time=STOP_TIME, step_size=STEP_SIZE, theta0=0.3,
                           parameters={"damping": case["damping"]})
        assert np.max(np.abs(rows["theta"] - oracle["theta"])) < 1e-10
    with Client(scheduler) as client:
        # Each worker process unzipped the FMU once, however many cases it ran.
        assert set(client.run(lambda: len(simulate._extracted)).values()) == {1}


def test_a_case_the_fmu_refuses_names_the_case(fmu, tmp_path, scheduler):
    with pytest.raises(simulate.FmuError, match=r"case 1 \(torque = 1, mass = 0\).*mass must be > 0"):
        run_sweep([{"torque": 1.0, "mass": 1.0}, {"torque": 1.0, "mass": 0.0}], output_dir=tmp_path,
                  stop_time=0.01, scheduler=scheduler, progress=False, fmu_path=fmu)
    assert list(tmp_path.iterdir()) == []  # no half-written table


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
])
def test_bad_runs_are_refused_before_any_cluster_starts(tmp_path, cases, options, message):
    with pytest.raises(ValueError, match=message):
        run_sweep(cases, output_dir=tmp_path, **options)
