"""OSP libcosim (through libcosimpy) as the master: a master nobody here wrote."""

import numpy as np
import pytest
from fmpy import read_model_description

from pendulum_fmu.oracle._reference import reference
from pendulum_fmu.ssp._closed_loop import WIRES, sampled_loop_reference

libcosim = pytest.importorskip("libcosimpy", reason="libcosimpy not installed: pip install -e '.[test]'")
from libcosimpy.CosimEnums import CosimVariableType
from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
from libcosimpy.CosimManipulator import CosimManipulator
from libcosimpy.CosimObserver import CosimObserver
from libcosimpy.CosimSlave import CosimLocalSlave

STEP_NS = 1_000_000  # libcosim counts time in nanoseconds: a 1 ms master step


@pytest.fixture(autouse=True)
def quiet_libcosim():
    log_output_level(CosimLogLevel.WARNING)


def _references(fmu):
    return {v.name: v.valueReference for v in read_model_description(str(fmu)).modelVariables}


def test_override_manipulator_and_observer_match_the_reference(fmu):
    vr = _references(fmu)
    execution = CosimExecution.from_step_size(step_size=STEP_NS)
    pendulum = execution.add_local_slave(CosimLocalSlave(fmu_path=str(fmu), instance_name="pendulum"))
    manipulator = CosimManipulator.create_override()
    execution.add_manipulator(manipulator)
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)

    # A step-wise torque: the override each step holds over that step, as overrideActuation does.
    def signal(t):
        return 20.0 if t < 1.0 else (-30.0 if t < 2.0 else 10.0)

    theta = [0.0]
    for k in range(3000):
        manipulator.slave_real_values(pendulum, [vr["torque"]], [signal(k * 1e-3)])
        assert execution.step()
        theta.append(observer.last_real_values(pendulum, [vr["theta"]])[0])
    expected = reference(signal, stop_time=3.0, step_size=1e-3)
    assert np.max(np.abs(np.array(theta) - expected["theta"])) < 1e-10


def test_two_slaves_close_the_loop_through_connections(fmu, pid_controller):
    execution = CosimExecution.from_step_size(step_size=STEP_NS)
    slaves = {
        "pendulum": execution.add_local_slave(CosimLocalSlave(fmu_path=str(fmu), instance_name="pendulum")),
        "controller": execution.add_local_slave(
            CosimLocalSlave(fmu_path=str(pid_controller), instance_name="controller")
        ),
    }
    vr = {"pendulum": _references(fmu), "controller": _references(pid_controller)}
    for source, output, target, into in WIRES:
        execution.connect_real_variables(slaves[source], vr[source][output], slaves[target], vr[target][into])
    series = CosimObserver.create_time_series()
    execution.add_observer(series)
    series.start_time_series(
        slaves["pendulum"], value_reference=vr["pendulum"]["theta"], variable_type=CosimVariableType.REAL
    )
    assert execution.simulate_until(target_time=4 * 10**9)
    times, _, theta = series.time_series_real_samples(
        slaves["pendulum"], vr["pendulum"]["theta"], from_step=0, sample_count=4001
    )
    # libcosim hands the controller's torque over one step after the theta it came from.
    expected = sampled_loop_reference(stop_time=4.0, coupling="jacobi")
    index = np.rint(np.array(times) / STEP_NS).astype(int)
    assert len(index) >= 3000
    assert np.max(np.abs(np.array(theta) - expected["theta"][index])) < 1e-9
    assert abs(theta[-1] - 0.5) < 5e-4
