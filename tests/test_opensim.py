"""OpenSim 4.6 running the tutorial's model agrees with the FMU and the reference."""

import re

import numpy as np
import pytest

from pendulum_fmu.cli import main
from pendulum_fmu.comparing._compare import compare
from pendulum_fmu.engines.opensim import _build_pendulum_model, _import_opensim, opensim_simulate

try:
    osim = _import_opensim()
except ImportError as error:
    pytest.skip(str(error), allow_module_level=True)


@pytest.mark.parametrize("gravity", [0.0, 9.81])
def test_tutorial_case_three_tools_agree(fmu, tmp_path, gravity):
    comparison = compare(
        20.0, ("fmu", "reference", "opensim"), output_dir=tmp_path, parameters={"gravity": gravity}, fmu_path=fmu
    )
    assert comparison.worst < 1e-9
    if gravity == 0.0:
        t = comparison.runs["opensim"]["time"]
        assert np.max(np.abs(comparison.runs["opensim"]["theta"] - t**2 / 3)) < 1e-12


def test_stepwise_signal_with_damping_and_start_values(fmu, tmp_path):
    csv = tmp_path / "t.csv"
    csv.write_text("time,torque\n0,20\n0.4,20\n0.4,-15\n1.2345,-15\n1.2345,40\n2,40\n2,0\n3,0\n")
    comparison = compare(
        csv,
        ("fmu", "reference", "opensim"),
        output_dir=tmp_path,
        step_size=2.5e-3,
        parameters={"damping": 2.0},
        theta0=0.5,
        omega0=-1.0,
        fmu_path=fmu,
    )
    assert comparison.worst < 1e-9


def test_tutorial_loop_verbatim_fails_on_opensim_46():
    # Why opensim_simulate calls manager.initialize(state) before each integrate().
    model, _coordinate, actuator = _build_pendulum_model(osim, 40.0, 0.5, 20.0, 9.81, 0.0)
    state = model.initSystem()
    actuator.overrideActuation(state, True)
    manager = osim.Manager(model)
    manager.initialize(state)
    t = 0.0
    with pytest.raises(RuntimeError, match="realized only to stage Instance"):
        for _ in range(3):
            actuator.setOverrideActuation(state, 20.0)
            state = manager.integrate(t + 0.001)
            t = state.getTime()


def test_opensim_rejects_bad_arguments(tmp_path):
    with pytest.raises(ValueError, match="one value per step"):
        opensim_simulate([0, 1, 2], [1.0])
    with pytest.raises(ValueError, match="opensim holds the torque over each step and cannot ramp"):
        compare(lambda t: t, ("fmu", "opensim"), output_dir=tmp_path, stop_time=0.1, step_size=0.01, ramp=True)


def test_cli_compare_three_tools(tmp_path, capsys):
    csv = tmp_path / "t.csv"
    csv.write_text("time,torque\n0,10\n1,10\n1,-10\n2,-10\n")
    assert main(["compare", "--torque-file", str(csv), "--output-dir", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    assert re.search(r"^fmu +reference ", out, re.M) and re.search(r"^opensim +reference ", out, re.M)
    assert re.search(r"^fmu +opensim ", out, re.M) and "tools agree" in out
