"""Our FMU through fmpy's own paths (`fmpy simulate` and `fmpy.simulate_fmu`) beside
`pendulum-fmu simulate`, on the same signals, judged by the independent oracle.

These pin where fmpy 0.3.32 agrees with the signal definition (docs/signals.md) and where it
does not, so the README's table of paths stays true: a change in fmpy shows up here.
"""

import subprocess
import sys

import numpy as np
import pytest
from fmpy import simulate_fmu

from pendulum_fmu.fmu._simulate import simulate
from pendulum_fmu.oracle._reference import reference


def write(path, rows):
    path.write_text("time,torque\n" + "".join(f"{t},{u}\n" for t, u in rows))
    return path


def fmpy_command_line(fmu, csv, out, *extra):
    subprocess.run(
        [
            sys.executable,
            "-m",
            "fmpy",
            "simulate",
            str(fmu),
            "--input-file",
            str(csv),
            "--output-file",
            str(out),
            *extra,
        ],
        check=True,
        capture_output=True,
    )
    result = np.genfromtxt(out, delimiter=",", names=True)
    # fmpy records both sides of an input event at the same time: keep the first of each time.
    return result[np.unique(result["time"], return_index=True)[1]]


def error_against_oracle(result, csv, **arguments):
    oracle = reference(csv, at=result["time"], **arguments)
    return float(np.max(np.abs(result["theta"] - oracle["theta"])))


@pytest.mark.parametrize("fixture", ["fmu", "fmu3"])
def test_both_command_lines_agree_on_decimal_jumps_at_awkward_steps(request, fixture, fmu, tmp_path):
    # fmpy snaps input events to the grid (math.isclose), so 3 * 0.009 meets the jump at 0.027;
    # the FMI 2.0 and 3.0 FMUs alike (fmpy passes the description's default tolerance, 1e-8).
    csv = write(tmp_path / "j.csv", [(0, 10), (0.027, 10), (0.027, -20), (0.5, -20), (0.5, 15), (2, 15)])
    fmpy_run = fmpy_command_line(
        request.getfixturevalue(fixture), csv, tmp_path / "fmpy.csv", "--output-interval", "0.009", "--stop-time", "2"
    )
    assert error_against_oracle(fmpy_run, csv, step_size=0.009, stop_time=2) < 1e-9
    ours = simulate(csv, step_size=0.009, fmu_path=fmu)
    assert error_against_oracle(ours, csv, step_size=0.009) < 1e-9


def test_fmpy_misreads_a_first_row_jump(fmu, tmp_path):
    # fmpy holds the first row's value when t equals the first time, so a jump in the first two
    # rows is applied one step late; pendulum-fmu applies the value after the jump.
    csv = write(tmp_path / "j.csv", [(0, 0), (0, 20), (1, 20)])
    fmpy_run = fmpy_command_line(fmu, csv, tmp_path / "fmpy.csv", "--output-interval", "0.001", "--stop-time", "1")
    assert error_against_oracle(fmpy_run, csv, step_size=1e-3, stop_time=1) > 1e-4
    ours = simulate(csv, step_size=1e-3, fmu_path=fmu)
    assert error_against_oracle(ours, csv, step_size=1e-3) < 1e-9


def test_default_stop_time_differs(fmu, tmp_path):
    # fmpy stops at the model description's DefaultExperiment (3 s); pendulum-fmu at the CSV's end.
    csv = write(tmp_path / "t.csv", [(0, 5), (2, 5)])
    fmpy_run = fmpy_command_line(fmu, csv, tmp_path / "fmpy.csv", "--output-interval", "0.001")
    assert fmpy_run["time"][-1] == pytest.approx(3.0)
    assert simulate(csv, fmu_path=fmu)["time"][-1] == 2.0


def test_simulate_fmu_holds_each_steps_start_value(fmu, tmp_path):
    signals = np.array([(0.0, 10.0), (0.3, 10.0), (0.3, -5.0), (1.0, -5.0)], dtype=[("time", float), ("torque", float)])
    result = simulate_fmu(str(fmu), input=signals, output_interval=1e-3, stop_time=1.0, output=["theta"])
    result = result[np.unique(result["time"], return_index=True)[1]]
    csv = write(tmp_path / "s.csv", signals.tolist())
    assert error_against_oracle(result, csv, step_size=1e-3, stop_time=1.0) < 1e-9


def test_simulate_fmu_cannot_set_input_derivatives_on_a_one_input_fmu(fmu):
    # fmpy 0.3.32's Input allocates room for nine input derivatives, (fmi2Real * 9)(), and
    # assigns one per continuous input: any FMU without exactly nine continuous inputs fails.
    # The bug is fmpy's, not our model description's; `pendulum-fmu simulate --ramp` ramps.
    signals = np.array([(0.0, 0.0), (1.0, 10.0)], dtype=[("time", float), ("torque", float)])
    with pytest.raises(ValueError, match="Can only assign sequence of same size"):
        simulate_fmu(str(fmu), input=signals, output_interval=1e-2, stop_time=1.0, set_input_derivatives=True)
