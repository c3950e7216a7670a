"""The call record and `judge --calls`, against masters that make deliberate mistakes.

Masters installable here (fmpy's API and command line, libcosim) make deliberate mistakes, and
the judge must name each one, at the step it was made, from the FMU's own record and from fmpy's
call log alike.

The expected readings are not computed by the judge's code: each mistake is made on purpose in
the loop below (a torque a step late, a parameter left out), so the step and value it must name
are known from how the loop was written.
"""

import json
import subprocess
import sys

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave

from pendulum_fmu.cli import main
from pendulum_fmu.judging._call_judge import IntendedRun, judge_calls

STEP = 1e-3
N_STEPS = 10
JUMP_STEP = 5  # the intended torque jumps from 0 to 20 N.m at t = 5 ms
VARIABLE_NAMES = {
    0: "torque",
    1: "theta",
    2: "omega",
    3: "alpha",
    4: "mass",
    5: "length",
    6: "inertia",
    7: "gravity",
    8: "damping",
}


@pytest.fixture(scope="module")
def jump_csv(tmp_path_factory):
    path = tmp_path_factory.mktemp("signals") / "jump.csv"
    path.write_text(f"time,torque\n0,0\n{JUMP_STEP * STEP},0\n{JUMP_STEP * STEP},20\n{N_STEPS * STEP},20\n")
    return path


@pytest.fixture(scope="module")
def ramp_csv(tmp_path_factory):
    path = tmp_path_factory.mktemp("signals") / "ramp.csv"
    path.write_text(f"time,torque\n0,0\n{N_STEPS * STEP},10\n")
    return path


def intended_torque(k):
    return 20.0 if k >= JUMP_STEP else 0.0


def drive(fmu, capsys, tmp_path, *, torque_of_step=intended_torque, derivative=None, parameters=None, restore=None):
    """Run N_STEPS by hand through fmpy's FMU2Slave, logging on; return the two logs as files.

    With loggingOn, fmpy's default logger prints the FMU's messages (the record); its call logger
    gives fmpy's own call log.
    """
    description = read_model_description(fmu)
    calls = []
    slave = FMU2Slave(
        guid=description.guid,
        unzipDirectory=extract(fmu),
        modelIdentifier=description.coSimulation.modelIdentifier,
        instanceName="pendulum",
        fmiCallLogger=calls.append,
    )
    slave.instantiate(loggingOn=True)
    slave.setupExperiment(startTime=0.0)
    for name, value in (parameters or {}).items():
        slave.setReal([next(v for v, n in VARIABLE_NAMES.items() if n == name)], [value])
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    saved, t = None, 0.0
    for k in range(N_STEPS):
        slave.setReal([0], [torque_of_step(k)])
        if derivative is not None:
            slave.setRealInputDerivatives([0], [1], [derivative])
        if restore and k == restore[0]:
            saved = slave.getFMUstate()
        if restore and k == restore[1]:
            slave.setFMUstate(saved)
            t = restore[0] * STEP
        slave.doStep(currentCommunicationPoint=t, communicationStepSize=STEP)
        t += STEP
    slave.terminate()
    slave.freeInstance()
    record = tmp_path / "stdout.log"
    record.write_text(capsys.readouterr().out)
    call_log = tmp_path / "fmpy_calls.log"
    call_log.write_text("\n".join(calls) + "\n")
    return record, call_log


def reading(log, intended):
    judged = judge_calls(log, intended, VARIABLE_NAMES)
    assert len(judged) == 1
    return next(iter(judged.values()))


@pytest.mark.parametrize("source", [0, 1], ids=["fmu-record", "fmpy-call-log"])
def test_a_master_that_does_what_was_intended_is_told_so(fmu, capsys, tmp_path, jump_csv, source):
    log = drive(fmu, capsys, tmp_path, parameters={"mass": 3.0})[source]
    result = reading(log, IntendedRun(jump_csv, parameters={"mass": 3.0}))
    assert result["differences"] == []
    assert [step["torque"] for step in result["steps"]] == [intended_torque(k) for k in range(N_STEPS)]
    assert [step["time"] for step in result["steps"]] == pytest.approx([k * STEP for k in range(N_STEPS)], abs=1e-15)


@pytest.mark.parametrize("source", [0, 1], ids=["fmu-record", "fmpy-call-log"])
@pytest.mark.parametrize("shift", [1, 2, -1])
def test_input_applied_late_or_early_is_named_with_its_first_step(fmu, capsys, tmp_path, jump_csv, source, shift):
    log = drive(fmu, capsys, tmp_path, torque_of_step=lambda k: intended_torque(k - shift))[source]
    found = reading(log, IntendedRun(jump_csv))["differences"]
    # The first step whose torque differs: where the jump lands in the shifted run or the intended one.
    first = JUMP_STEP + min(shift, 0)
    word = "late" if shift > 0 else "early"
    assert len(found) == 1, found
    assert found[0].startswith(
        f"input applied {abs(shift)} step{'s' * (abs(shift) > 1)} {word} from step {first} (t = "
    )


@pytest.mark.parametrize("source", [0, 1], ids=["fmu-record", "fmpy-call-log"])
def test_a_missing_parameter_is_named(fmu, capsys, tmp_path, jump_csv, source):
    log = drive(fmu, capsys, tmp_path, parameters={"mass": 3.0})[source]
    found = reading(log, IntendedRun(jump_csv, parameters={"mass": 3.0, "damping": 0.5}))["differences"]
    assert found == ["parameter damping not set (intended 0.5; the FMU used its start value)"]


@pytest.mark.parametrize("source", [0, 1], ids=["fmu-record", "fmpy-call-log"])
def test_held_where_it_should_ramp(fmu, capsys, tmp_path, ramp_csv, source):
    log = drive(fmu, capsys, tmp_path, torque_of_step=lambda k: k * STEP * 1000.0)[source]
    found = reading(log, IntendedRun(ramp_csv, ramp=True))["differences"]
    assert found == ["held where it should ramp from step 0 (t = 0): intended der(torque) = 1000 N.m/s"]


@pytest.mark.parametrize("source", [0, 1], ids=["fmu-record", "fmpy-call-log"])
def test_ramped_where_it_should_hold(fmu, capsys, tmp_path, jump_csv, source):
    log = drive(fmu, capsys, tmp_path, derivative=5.0)[source]
    found = reading(log, IntendedRun(jump_csv))["differences"]
    assert "ramped where it should hold from step 0 (t = 0): der(torque) = 5 N.m/s" in found


def test_a_state_restored_to_another_time_is_named(fmu, capsys, tmp_path, jump_csv):
    # Saved before step 3 (t = 3 ms), restored before step 7 (t = 7 ms): the master then steps
    # from 3 ms with the torque of steps 7 to 9 (20 N.m), where the run meant 0 until 5 ms.
    record, call_log = drive(fmu, capsys, tmp_path, restore=(3, 7))
    from_record = reading(record, IntendedRun(jump_csv))
    from_call_log = reading(call_log, IntendedRun(jump_csv))
    assert from_record["differences"][0].endswith(
        "an FMU state restored to t = 0.0030000000000000001 at t = 0.0070000000000000001"
    )
    assert from_call_log["differences"][0].endswith(
        "the master went back from t = 0.0070000000000000001 to t = 0.0030000000000000001 (an FMU "
        "state restored to another time)"
    )
    for result in (from_record, from_call_log):
        # The kept steps: 0-2 as meant, then the redone ones from 3 ms.
        assert [round(step["time"] / STEP) for step in result["steps"]] == list(range(6))
        assert [step["torque"] for step in result["steps"]] == [0, 0, 0, 20, 20, 20]
        assert result["differences"][1].startswith("input applied 2 steps early from step 3")


def test_fmpy_simulate_command_line_late_first_jump(fmu, tmp_path):
    """A first-row jump, which fmpy 0.3.32 applies one step late, is named from its command line's log.

    docs/signals.md has the behaviour; fmpy's own call log, from `fmpy simulate --fmi-logging`,
    shows where.
    """
    csv = tmp_path / "first_row_jump.csv"
    csv.write_text("time,torque\n0,0\n0,20\n0.01,20\n")
    completed = subprocess.run(
        [
            sys.executable,
            "-m",
            "fmpy",
            "simulate",
            str(fmu),
            "--input-file",
            str(csv),
            "--output-interval",
            str(STEP),
            "--stop-time",
            "0.01",
            "--fmi-logging",
            "--debug-logging",
            "--output-file",
            str(tmp_path / "out.csv"),
        ],
        check=True,
        capture_output=True,
        text=True,
    )
    log = tmp_path / "fmpy_stdout.log"
    log.write_text(completed.stdout)
    found = reading(log, IntendedRun(csv))["differences"]
    assert found == [
        "input applied 1 step late from step 0 (t = 0): step n holds the torque meant "
        "for step n-1 (set after the step it was meant for)"
    ]
    assert main(["judge", "--calls", str(log), "--torque-file", str(csv), "--fmu", str(fmu)]) == 1
    assert main(["judge", "--calls", str(log), "--fmu", str(fmu)]) == 0
    figure, numbers = tmp_path / "calls.png", tmp_path / "calls.json"
    arguments = ["--torque-file", str(csv), "--fmu", str(fmu), "--plot", str(figure), "--json", str(numbers)]
    assert main(["judge", "--calls", str(log), *arguments]) == 1
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    written = json.loads(numbers.read_text())["Pendulum"]
    assert written["differences"] == found
    assert [step["torque"] for step in written["steps"]] == [0] + [20] * 9
    assert written["intended_torque"] == [20] * 10


def test_a_master_one_step_late_at_10_ms_passes_the_tube_while_the_judge_names_it_late(fmu, tmp_path):
    """The 5 s jump fed to fmpy's API at 5.01 s, steps of 10 ms over 10 s: its call log is read.

    csv-compare's tube is 0.002 * 10 s = +-20 ms wide, two steps: it passes the late run.
    """
    intended = tmp_path / "jump_at_5_s.csv"
    intended.write_text("time,torque\n0,0\n5,0\n5,20\n10,20\n")
    late = np.array([(0, 0), (5.01, 0), (5.01, 20), (10, 20)], dtype=[("time", float), ("torque", float)])
    calls = []
    simulate_fmu(
        str(fmu), stop_time=10.0, step_size=0.01, output_interval=0.01, input=late, fmi_call_logger=calls.append
    )
    log = tmp_path / "fmpy_calls.log"
    log.write_text("\n".join(calls) + "\n")
    result = reading(log, IntendedRun(intended))
    assert [line.split(" (t")[0] for line in result["differences"]] == ["input applied 1 step late from step 500"]
    tube, band = result["regression_tools"]
    assert (tube["tool"], tube["passed"], tube["outside"], tube["points"]) == ("csv-compare tube", True, 0, 1001)
    assert tube["half_width"] == pytest.approx(0.02, abs=1e-15)
    assert (band["tool"], band["passed"]) == ("FMI cross-check band", True)


@pytest.mark.parametrize("source", [0, 1], ids=["fmu-record", "fmpy-call-log"])
def test_a_step_late_on_a_short_run_fails_the_tube_after_the_jump(fmu, capsys, tmp_path, jump_csv, source):
    # 10 steps of 1 ms: the tube is +-0.002 * 10 ms = +-20 us, far inside a step, so every
    # point after the late step (t = 6 .. 10 ms, 5 of 11) is outside: the late run has
    # 1 ms less of 20 N.m, a difference of the order of the whole range of theta there.
    log = drive(fmu, capsys, tmp_path, torque_of_step=lambda k: intended_torque(k - 1))[source]
    tube, _ = reading(log, IntendedRun(jump_csv))["regression_tools"]
    assert (tube["passed"], tube["outside"], tube["points"]) == (False, 5, 11)
    assert tube["half_width"] == pytest.approx(2e-5, rel=1e-12)


@pytest.mark.parametrize("fixture", ["fmu", "fmu3"])
def test_the_record_file_a_parameter_names_is_read_by_the_judge(request, fixture, tmp_path, jump_csv):
    """The start value callRecordFile set through fmpy, with the jump fed one step late (at 6 ms)."""
    fmu = request.getfixturevalue(fixture)
    record = tmp_path / "calls.log"
    late = np.array([(0, 0), (0.006, 0), (0.006, 20), (0.01, 20)], dtype=[("time", float), ("torque", float)])
    calls = []
    simulate_fmu(
        str(fmu),
        stop_time=N_STEPS * STEP,
        step_size=STEP,
        output_interval=STEP,
        input=late,
        start_values={"callRecordFile": str(record)},
        fmi_call_logger=calls.append,
    )
    # fmpy's own call log holds the fmi*SetString call too; the judge reads past it.
    call_log = tmp_path / "fmpy_calls.log"
    call_log.write_text("\n".join(calls) + "\n")
    assert [line.split(" (t")[0] for line in reading(call_log, IntendedRun(jump_csv))["differences"]] == [
        "input applied 1 step late from step 5"
    ]
    lines = record.read_text().splitlines()
    prefix = "fmi2" if fixture == "fmu" else "fmi3"
    assert lines[0].startswith(f'[pendulum-calls] instance="Pendulum" {prefix}SetString(file="{record}") ')
    assert sum(f"{prefix}DoStep(" in line for line in lines) == N_STEPS
    found = reading(record, IntendedRun(jump_csv))["differences"]
    assert [line.split(" (t")[0] for line in found] == ["input applied 1 step late from step 5"]
    assert main(["judge", "--calls", str(record), "--torque-file", str(jump_csv), "--fmu", str(fmu)]) == 1


def test_a_record_file_that_cannot_be_opened_is_one_warning_and_the_run_completes(fmu, tmp_path, capsys):
    missing = tmp_path / "no such folder" / "calls.log"
    result = simulate_fmu(
        str(fmu),
        stop_time=N_STEPS * STEP,
        step_size=STEP,
        output_interval=STEP,
        start_values={"callRecordFile": str(missing), "torque": 20.0},
    )
    warnings = [line for line in capsys.readouterr().out.splitlines() if "callRecordFile" in line]
    assert warnings == [
        f'[WARNING] fmi2SetString: callRecordFile "{missing}" cannot be opened for appending '
        "(No such file or directory): the FMU writes no record file (name a new file, or one of its records)"
    ]
    assert not missing.parent.exists()
    assert result["time"].tolist() == pytest.approx([k * STEP for k in range(N_STEPS + 1)], abs=1e-15)


LIBCOSIM_RUN = """
import sys
from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
from libcosimpy.CosimManipulator import CosimManipulator
from libcosimpy.CosimSlave import CosimLocalSlave
log_output_level(CosimLogLevel.TRACE)
execution = CosimExecution.from_step_size(step_size=1_000_000)
pendulum = execution.add_local_slave(CosimLocalSlave(fmu_path=sys.argv[1], instance_name="pendulum"))
manipulator = CosimManipulator.create_override()
execution.add_manipulator(manipulator)
for k in range(10):
    # The override for step k set {late} step(s) late: the value meant for step k - {late}.
    manipulator.slave_real_values(pendulum, [0], [20.0 if k - {late} >= 5 else 0.0])
    execution.step()
"""


@pytest.mark.parametrize("late", [0, 1])
def test_libcosim_trace_log(fmu, tmp_path, jump_csv, late):
    """The record inside libcosim's trace log: an override a step late is named.

    libcosim passes loggingOn and prints the record at its trace level, inside its own format;
    its ns clock makes step sizes differ from 1 ms in the last bits, which is no difference.
    """
    pytest.importorskip("libcosimpy", reason="libcosimpy not installed: pip install -e '.[test]'")
    completed = subprocess.run(
        [sys.executable, "-c", LIBCOSIM_RUN.replace("{late}", str(late)), str(fmu)],
        check=True,
        capture_output=True,
        text=True,
    )
    log = tmp_path / "libcosim.log"
    log.write_text(completed.stdout + completed.stderr)
    result = reading(log, IntendedRun(jump_csv))
    assert [step["torque"] for step in result["steps"]] == [intended_torque(k - late) for k in range(N_STEPS)]
    expected = (
        []
        if not late
        else [
            "input applied 1 step late from step 5 (t = 0.0050000000000000001): step n holds the torque "
            "meant for step n-1 (set after the step it was meant for)"
        ]
    )
    assert result["differences"] == expected


@pytest.mark.parametrize("solver", ["Euler", "CVode"])
def test_a_model_exchange_masters_integrator_is_read_from_its_calls(fmu, capsys, tmp_path, solver):
    """The integrator of fmpy's Model Exchange solvers is read from their calls.

    Its fixed-step explicit Euler sets each state to the last plus h times the derivatives
    returned there; its CVODE does not.
    """
    simulate_fmu(
        fmu,
        fmi_type="ModelExchange",
        solver=solver,
        stop_time=10 * STEP,
        step_size=STEP,
        output_interval=STEP,
        debug_logging=True,
        start_values={"theta": 0.5},
    )
    log = tmp_path / "stdout.log"
    log.write_text(capsys.readouterr().out)
    found = reading(log, IntendedRun(0.0, start_values={"theta0": 0.5}))["differences"]
    assert len(found) == 1
    if solver == "Euler":
        assert found[0].startswith(
            "Model Exchange master: explicit Euler at step 0.001 s, one "
            "derivative evaluation per step (10 fmi2SetTime calls"
        )
    else:
        assert found[0].startswith("Model Exchange master: not explicit Euler")


@pytest.mark.parametrize("source", ["fmu-record", "fmpy-call-log"])
def test_fmi3_first_row_jump_through_fmpy(fmu3, capsys, tmp_path, source):
    """The FMI 3.0 FMU's record and fmpy's FMI 3.0 call log name fmpy's first-row jump alike.

    fmpy's FMI 3.0 call log names instances and variables its own way (instance=,
    valueReferences=, values=).
    """
    csv = tmp_path / "first_row_jump.csv"
    csv.write_text("time,torque\n0,0\n0,20\n0.005,20\n")
    calls = []
    simulate_fmu(
        fmu3, stop_time=0.005, output_interval=STEP, input=_table(csv), debug_logging=True, fmi_call_logger=calls.append
    )
    log = tmp_path / "run.log"
    log.write_text(capsys.readouterr().out if source == "fmu-record" else "\n".join(calls) + "\n")
    result = reading(log, IntendedRun(csv))
    assert [step["torque"] for step in result["steps"]] == [0, 20, 20, 20, 20]
    assert result["differences"] == [
        "input applied 1 step late from step 0 (t = 0): step n holds the torque meant for step n-1 "
        "(set after the step it was meant for)"
    ]


def _table(csv):
    return np.genfromtxt(csv, delimiter=",", names=True)
