"""The pendulum and the PID controller FMU in one co-simulation: fmpy's container FMU."""

import numpy as np
from fmpy import simulate_fmu
from fmpy.validation import validate_fmu

from pendulum_fmu.ssp._closed_loop import create_closed_loop_fmu, sampled_loop_reference


def test_controller_fmu_is_valid(pid_controller):
    assert validate_fmu(str(pid_controller)) == []


def test_container_fmu_settles_on_the_setpoint_like_the_sampled_reference(tmp_path):
    container = create_closed_loop_fmu(tmp_path / "ClosedLoop.fmu")
    result = simulate_fmu(str(container), stop_time=4.0, output_interval=1e-3)
    expected = sampled_loop_reference(stop_time=4.0)
    assert np.allclose(result["time"], expected["time"], rtol=0, atol=1e-9)
    assert np.max(np.abs(result["theta"] - expected["theta"])) < 1e-9
    assert np.max(np.abs(result["torque"] - expected["torque"])) < 1e-6
    assert abs(result["theta"][-1] - 0.5) < 5e-4
    assert result["theta"].max() < 0.5 * 1.15  # overshoot under 15 %
    # Holding 0.5 rad against gravity takes m g L sin(0.5).
    assert abs(result["torque"][-1] - 40 * 9.81 * 0.5 * np.sin(0.5)) < 1.0
