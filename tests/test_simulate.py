"""simulate() through its per-thread Simulator: the numbers of a fresh instance bit for bit, one
instance per thread, and an FMU file rebuilt on disk is noticed.
"""

import re
import shutil
import threading

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from fmu_build import MODEL_DESCRIPTION, build_fmu
from pendulum_fmu.fmu._instance import open_fmu
from pendulum_fmu.fmu._simulate import RECORDED, run_schedule_python, simulate, simulate_plan, simulator
from pendulum_fmu.signals._torque_csv import TorqueTable
from pendulum_fmu.signals._torque_schedule import schedule

# Runs one after the other through the same cached instance: each must come out as a fresh one.
RUNS = [
    dict(parameters={"damping": 2.0, "mass": 25.0}, theta0=0.3, omega0=-1.0, tolerance=None),
    dict(parameters=None, theta0=0.0, omega0=0.0, tolerance=None),
    dict(parameters={"inertia": 5.0}, theta0=1.0, omega0=0.5, tolerance=1e-6),
    dict(parameters=None, theta0=0.0, omega0=0.0, tolerance=None),
]


def _fresh_fmpy_run(fmu, plan, parameters, theta0, omega0, tolerance, tmp_path):
    """The schedule through a new fmpy FMU2Slave, driven call by call as a master would."""
    description = read_model_description(str(fmu))
    refs = {v.name: v.valueReference for v in description.modelVariables}
    start = {
        v.name: float(v.start) for v in description.modelVariables if v.causality == "parameter" and v.type == "Real"
    }
    start.update(parameters or {}, theta=theta0, omega=omega0)
    slave = FMU2Slave(
        guid=description.guid,
        unzipDirectory=extract(str(fmu), str(tmp_path / "fresh")),
        modelIdentifier=description.coSimulation.modelIdentifier,
        instanceName="fresh",
    )
    slave.instantiate()
    slave.setupExperiment(tolerance=tolerance, startTime=float(plan.time[0]))
    slave.enterInitializationMode()
    slave.setReal([refs[name] for name in start], list(start.values()))
    slave.exitInitializationMode()
    recorded = [refs[name] for name in RECORDED]
    rows = []
    for t, h, u, rate in zip(plan.time[:-1], np.diff(plan.time), plan.torque, plan.torque_rate, strict=False):
        slave.setReal([refs["torque"]], [float(u)])
        if plan.torque_rate.any():
            slave.setRealInputDerivatives([refs["torque"]], [1], [float(rate)])
        rows.append(slave.getReal(recorded))
        slave.doStep(float(t), float(h))
    rows.append(slave.getReal(recorded))
    slave.terminate()
    slave.freeInstance()
    return np.array(rows)


@pytest.mark.parametrize("ramp", [False, True])
def test_runs_through_the_cached_instance_match_a_fresh_fmpy_instance_bit_for_bit(fmu, ramp, tmp_path):
    # Steps of 50 ms, where the tolerance decides the internal steps; a jump between two points.
    table = TorqueTable(time=np.array([0.0, 0.305, 0.305, 0.8]), torque=np.array([5.0, 30.0, -8.0, 12.0]))
    plan = schedule(table, step_size=0.05, ramp=ramp)
    for number, run in enumerate(RUNS):
        cached = simulate_plan(plan, fmu_path=fmu, **run)
        fresh = _fresh_fmpy_run(fmu, plan, tmp_path=tmp_path / str(number), **run)
        for column, name in enumerate(RECORDED):
            assert np.array_equal(cached[name], fresh[:, column]), (run, name)
    assert simulator(fmu) is simulator(fmu)  # one instance served every run
    at_default = simulate_plan(plan, fmu_path=fmu, **{**RUNS[2], "tolerance": None})
    assert not np.array_equal(at_default, simulate_plan(plan, fmu_path=fmu, **RUNS[2]))  # it mattered


def test_an_fmi3_fmu_restarted_matches_a_fresh_instance_bit_for_bit(fmu3):
    plan = schedule(20.0, stop_time=0.05)
    for run in RUNS:
        cached = simulate_plan(plan, fmu_path=fmu3, **run)
        fresh = open_fmu(
            fmu3, parameters=run["parameters"], theta0=run["theta0"], omega0=run["omega0"], tolerance=run["tolerance"]
        )
        try:
            assert np.array_equal(cached, run_schedule_python(fresh, plan)), run
        finally:
            fresh.freeInstance()


def test_each_thread_has_its_own_instance_and_the_same_numbers(fmu):
    torques = [float(u) for u in np.linspace(-40.0, 40.0, 12)]
    alone = {u: simulate(u, stop_time=0.2, fmu_path=fmu, parameters={"damping": 0.5}) for u in torques}
    results, instances, failures = {}, {}, []
    start = threading.Barrier(4)

    def worker(number):
        try:
            start.wait()
            instances[number] = simulator(fmu)
            for _ in range(5):
                for u in torques[number::4]:
                    results[(number, u)] = simulate(u, stop_time=0.2, fmu_path=fmu, parameters={"damping": 0.5})
        except BaseException as error:  # reported by the main thread
            failures.append(error)

    threads = [threading.Thread(target=worker, args=(n,)) for n in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert not failures
    assert len({id(instance) for instance in instances.values()}) == 4
    assert simulator(fmu) not in instances.values()
    for (number, u), run in results.items():
        assert np.array_equal(run, alone[u]), (number, u)


def test_an_fmu_file_rebuilt_on_disk_is_noticed(fmu, tmp_path):
    path = tmp_path / "Pendulum.fmu"
    shutil.copy(fmu, path)
    before = simulate(20.0, stop_time=0.5, fmu_path=path)
    first = simulator(path)
    # The same pendulum with a mass of 10 kg by default, built and renamed over the file in use.
    xml = tmp_path / "modelDescription.xml"
    text = MODEL_DESCRIPTION.read_text()
    xml.write_text(re.sub(r'(name="mass".*?start=")40"', r'\g<1>10"', text, count=1, flags=re.S))
    assert xml.read_text() != text
    rebuilt = build_fmu(tmp_path / "rebuilt" / "Pendulum.fmu", model_description_file=xml, platforms=("linux64",))
    rebuilt.replace(path)
    after = simulate(20.0, stop_time=0.5, fmu_path=path)
    assert simulator(path) is not first
    assert np.array_equal(after, simulate(20.0, stop_time=0.5, fmu_path=fmu, parameters={"mass": 10.0}))
    assert not np.array_equal(after["theta"], before["theta"])
