"""The pendulum-fmu command line, run in-process through main(argv)."""

import subprocess
import sys
from importlib import import_module

import numpy as np
import pyarrow.parquet as pq
import pytest

from pendulum_fmu._errors import InvalidInput
from pendulum_fmu.cli import build_parser, main
from pendulum_fmu.oracle._reference import reference

I_TOTAL = 30.0


def test_every_command_has_help():
    parser = build_parser()
    commands = parser._subparsers._group_actions[0].choices
    assert set(commands) == {
        "build",
        "export",
        "cross-check",
        "simulate",
        "compare",
        "sweep",
        "demo",
        "judge",
        "scenarios",
        "export-ssp",
        "verify",
    }
    for name, command in commands.items():
        assert command.description, name
        for action in command._actions:
            assert action.help, f"{name} {action.option_strings}"


@pytest.mark.build
def test_build(tmp_path, capsys):
    assert main(["build", "--output", str(tmp_path / "P.fmu")]) == 0
    assert (tmp_path / "P.fmu").stat().st_size > 10_000
    assert "wrote" in capsys.readouterr().out


def test_simulate_writes_csv_and_plot(tmp_path, capsys):
    out, png = tmp_path / "out.csv", tmp_path / "out.png"
    assert (
        main(
            [
                "simulate",
                "--torque",
                "20",
                "--set",
                "gravity=0",
                "--theta0",
                "0.1",
                "--output",
                str(out),
                "--plot",
                str(png),
            ]
        )
        == 0
    )
    data = np.genfromtxt(out, delimiter=",", names=True)
    assert data.dtype.names == ("time", "torque", "theta", "omega", "alpha")
    assert np.max(np.abs(data["theta"] - (0.1 + 10 / I_TOTAL * data["time"] ** 2))) < 1e-12
    assert png.read_bytes()[:4] == b"\x89PNG"
    assert "theta = 3.1" in capsys.readouterr().out


def test_simulate_reports_the_outputs_of_the_fmu_that_ran(tmp_path, capsys):
    """An FMU whose outputs are theta and omega (alpha a local variable): the summary line and the
    file name its outputs, and the values are the analytic ones (gravity 0: theta = tau t^2 / 2I).
    """
    from bad_inputs import _edited_fmu, alpha_not_an_output

    fmu, out = tmp_path / "NoAlphaOutput.fmu", tmp_path / "out.csv"
    fmu.write_bytes(_edited_fmu(alpha_not_an_output))
    arguments = ["simulate", "--torque", "20", "--set", "gravity=0", "--stop-time", "1", "--fmu", str(fmu)]
    assert main([*arguments, "--output", str(out)]) == 0
    line, wrote = capsys.readouterr().out.splitlines()
    theta, omega = 20 / (2 * I_TOTAL), 20 / I_TOTAL
    assert line.startswith("1000 steps to t = 1 s: theta = ") and "alpha" not in line, line
    assert abs(float(line.split("theta = ")[1].split(" rad,")[0]) - theta) < 1e-9, line
    assert abs(float(line.split("omega = ")[1].split(" rad/s;")[0]) - omega) < 1e-9, line
    assert wrote == f"wrote {out} (time,torque,theta,omega; units s, N.m, rad, rad/s)"


def test_simulate_torque_file(tmp_path):
    csv = tmp_path / "t.csv"
    csv.write_text("time,torque\n0,5\n1,5\n1,-5\n2,-5\n")
    out = tmp_path / "out.csv"
    assert main(["simulate", "--torque-file", str(csv), "--step-size", "0.01", "--output", str(out)]) == 0
    data = np.genfromtxt(out, delimiter=",", names=True)
    assert data["time"][-1] == 2.0
    assert np.max(np.abs(data["theta"] - reference(csv, step_size=0.01)["theta"])) < 1e-10


def test_a_users_error_is_one_line_and_anything_else_an_internal_error(monkeypatch, capsys):
    def refuse(*arguments, **options):
        raise InvalidInput("stop time -1 must be after start time 0")

    monkeypatch.setattr(import_module("pendulum_fmu.fmu._simulate"), "simulate", refuse)
    assert main(["simulate", "--torque", "1"]) == 2
    assert capsys.readouterr().err == "pendulum-fmu simulate: error: stop time -1 must be after start time 0\n"

    def fail(*arguments, **options):
        raise ValueError("a bug of ours")  # a ValueError, but no user's error

    monkeypatch.setattr(import_module("pendulum_fmu.fmu._simulate"), "simulate", fail)
    assert main(["simulate", "--torque", "1"]) == 3
    err = capsys.readouterr().err
    assert err.startswith("pendulum-fmu simulate: internal error: ValueError: a bug of ours") and "report it" in err
    assert err.count("\n") == 1


def test_a_file_name_holding_a_line_end_stays_on_the_errors_one_line(tmp_path, capsys):
    missing = tmp_path / "no\nsuch\r.csv"
    assert main(["judge", str(missing), "--torque", "20"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "\r" not in err
    assert err.startswith("pendulum-fmu judge: error: ") and "no\\nsuch\\r.csv" in err


def test_argument_errors_exit_2_without_traceback():
    result = subprocess.run(
        [sys.executable, "-m", "pendulum_fmu", "simulate", "--torque", "abc"], capture_output=True, text=True
    )
    assert result.returncode == 2
    assert "'abc' is not a number" in result.stderr and "Traceback" not in result.stderr


def test_compare_passes_and_fails_on_tolerance(tmp_path, capsys):
    args = ["compare", "--torque", "20", "--tools", "fmu,reference", "--stop-time", "1", "--output-dir", str(tmp_path)]
    assert main(args) == 0
    table = np.genfromtxt(tmp_path / "differences.csv", delimiter=",", names=True, dtype=None, encoding=None)
    assert float(table["theta_max"]) < 1e-10 and str(table["against"]) == "reference"
    trajectories = np.genfromtxt(tmp_path / "trajectories.csv", delimiter=",", names=True)
    assert {"theta_fmu", "omega_reference", "alpha_fmu", "torque_fmu"} <= set(trajectories.dtype.names)
    assert (tmp_path / "comparison.png").exists()
    assert main([*args, "--tol", "1e-16"]) == 1
    assert "DIFFER" in capsys.readouterr().out


def test_sweep_command(tmp_path, capsys):
    assert (
        main(
            [
                "sweep",
                "--torque",
                "5",
                "20",
                "--gravity",
                "0",
                "--set",
                "damping=0,2",
                "--stop-time",
                "0.2",
                "--workers",
                "1",
                "--output-dir",
                str(tmp_path),
            ]
        )
        == 0
    )
    assert "4 cases" in capsys.readouterr().out
    cases = pq.read_table(tmp_path / "cases").sort_by("case").to_pydict()
    assert cases["case"] == [0, 1, 2, 3]
    undamped = cases["case"][cases["damping"].index(0.0, cases["torque"].index(20.0))]
    table = pq.read_table(tmp_path / "trajectories").to_pydict()
    rows = np.array(table["case"]) == undamped
    time, theta = np.array(table["time"])[rows], np.array(table["theta"])[rows]
    assert np.max(np.abs(theta - 10 / I_TOTAL * time**2)) < 1e-12
    assert main(["sweep", "--torque", "5", "--set", "mass=heavy", "--output-dir", str(tmp_path)]) == 2


def test_sweep_with_a_refused_case_runs_the_rest_and_exits_1(tmp_path, capsys):
    import pyarrow.parquet as pq

    assert (
        main(
            [
                "sweep",
                "--torque",
                "5",
                "--set",
                "mass=0,40",
                "--stop-time",
                "0.1",
                "--workers",
                "1",
                "--output-dir",
                str(tmp_path),
            ]
        )
        == 1
    )
    assert "1 of 2 cases failed" in capsys.readouterr().err
    cases = pq.read_table(tmp_path / "cases").to_pydict()
    assert sorted(zip(cases["mass"], cases["status"], strict=False)) == [(0.0, "failed"), (40.0, "ok")]


def test_an_output_nothing_can_be_written_to_is_refused_before_the_run(tmp_path, capsys):
    """/proc/self: a folder in which nothing can be created. The error names the user's path, not
    the temporary beside it, and comes before the run (no summary line).
    """
    for argv in (
        ["simulate", "--torque", "1", "--output", "/proc/self/out.csv"],
        ["simulate", "--torque", "1", "--output", str(tmp_path / "fine.csv"), "--plot", "/proc/self/out.png"],
        ["compare", "--torque", "1", "--tools", "fmu,reference", "--output-dir", "/proc/self/out"],
        ["build", "--output", "/proc/self/Pendulum.fmu", "--platforms", "linux64"],
    ):
        assert main(argv) == 2, argv
        out, err = capsys.readouterr()
        assert out == "" and err.count("\n") == 1 and "/proc/self/" in err and "partial" not in err, (argv, err)
    assert list(tmp_path.iterdir()) == []


def _simulate_printing_to(stdout, folder):
    process = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "pendulum_fmu",
            "simulate",
            "--torque",
            "3",
            "--set",
            "gravity=0",
            "--stop-time",
            "0.01",
            "--output",
            "out.csv",
        ],
        cwd=folder,
        stdout=stdout,
        stderr=subprocess.PIPE,
    )
    if stdout is subprocess.PIPE:
        process.stdout.close()  # the reader is gone before the command prints (`| head -0`)
    error = process.stderr.read()
    return process.wait(timeout=120), error


def test_a_reader_of_stdout_that_goes_away_does_not_cost_the_files(tmp_path):
    # What a command prints only reports its files: piped into a reader that closed (BrokenPipe)
    # or sent to a full device, the command still writes them, says nothing more and succeeds.
    outputs = [("pipe", subprocess.PIPE)]
    if sys.platform.startswith("linux"):
        outputs.append(("/dev/full", open("/dev/full", "w")))
    for name, stdout in outputs:
        folder = tmp_path / name.strip("/").replace("/", "_")
        folder.mkdir()
        code, error = _simulate_printing_to(stdout, folder)
        assert (code, error) == (0, b""), name
        data = np.genfromtxt(folder / "out.csv", delimiter=",", names=True)
        # From rest with gravity off: theta = torque t^2 / (2 I), I = 20 + 40 * 0.5^2 kg.m2.
        assert len(data) == 11 and abs(data["theta"][-1] - 3 * 0.01**2 / (2 * 30)) < 1e-15, name
