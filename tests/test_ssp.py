"""ClosedLoop.ssp: the export, the couplings' references, the masters and the judge.

Every SSP master installable here is held to its coupling's reference, and the judge names it.
"""

import json
import os
import zipfile

import fmpy
import lxml.etree
import numpy as np
import pytest

from pendulum_fmu.cli import main
from pendulum_fmu.judging._call_record import read_calls, reconstruct
from pendulum_fmu.ssp._closed_loop import COUPLINGS, controller_defaults, sampled_loop_reference
from pendulum_fmu.ssp._ssp import DEFAULT_SETPOINT, export_ssp, read_ssp, rebind_ssp
from pendulum_fmu.ssp._ssp_calls import judge_ssp_calls
from pendulum_fmu.ssp._ssp_judge import judge_coupling

SCHEMAS = os.path.join(os.path.dirname(fmpy.__file__), "ssp", "schema")


@pytest.fixture(scope="module")
def ssp(tmp_path_factory):
    return export_ssp(tmp_path_factory.mktemp("ssp") / "ClosedLoop.ssp", stop_time=2.0)


def _reference(ssp_settings, coupling, applied=True):
    return sampled_loop_reference(
        ssp_settings.stop_time + ssp_settings.step_size,
        ssp_settings.step_size,
        controller=ssp_settings.controller if applied else None,
        parameters=ssp_settings.pendulum if applied else None,
        coupling=coupling,
    )


def test_export_validates_against_the_ssp_1_0_schemas_and_reads_back(ssp):
    with zipfile.ZipFile(ssp) as archive:
        names = set(archive.namelist())
        documents = {
            name: lxml.etree.fromstring(archive.read(name)) for name in names if name.endswith((".ssd", ".ssv"))
        }
    assert {"resources/Pendulum.fmu", "resources/PIDController.fmu"} <= names
    assert sorted(documents) == ["SystemStructure.ssd", "resources/controller.ssv", "resources/pendulum.ssv"]
    for name, document in documents.items():
        schema = lxml.etree.XMLSchema(
            file=os.path.join(
                SCHEMAS,
                "SystemStructureDescription.xsd" if name.endswith(".ssd") else "SystemStructureParameterValues.xsd",
            )
        )
        assert schema.validate(document), (name, schema.error_log)
    settings = read_ssp(ssp)
    assert (settings.stop_time, settings.step_size) == (2.0, 1e-3)
    assert settings.controller == {**controller_defaults(), "setpoint": DEFAULT_SETPOINT}
    assert settings.pendulum == {"mass": 40.0, "length": 0.5, "inertia": 20.0, "gravity": 9.81, "damping": 0.0}


def test_export_refuses_to_replace_an_ssp_unless_asked(tmp_path, capsys):
    target = tmp_path / "ClosedLoop.ssp"
    target.write_bytes(b"mine")
    assert main(["export-ssp", str(target), "--controller", "setpoint=0.4"]) == 2
    error = capsys.readouterr().err.strip()
    assert "exists: pass --overwrite" in error and len(error.splitlines()) == 1
    assert target.read_bytes() == b"mine"
    assert main(["export-ssp", str(target), "--controller", "setpoint=0.4", "--overwrite"]) == 0
    assert read_ssp(target).controller["setpoint"] == 0.4
    assert [p.name for p in tmp_path.iterdir()] == ["ClosedLoop.ssp"]  # no temporary left


@pytest.mark.parametrize("coupling", COUPLINGS)
def test_each_couplings_reference_is_the_exact_sampled_double_integrator(coupling):
    # Without gravity and damping the pendulum is J theta'' = u: a held torque moves it exactly
    # by h omega + h^2 u / 2J per step, so the sampled loop has a closed form per coupling.
    h, n, inertia = 1e-2, 200, 20.0 + 40.0 * 0.5**2
    gains = {"setpoint": 0.3, "kp": 638.0, "ki": 810.0, "kd": 270.0}
    theta = omega = integral = 0.0
    sent = (0.0, 0.0)  # theta and omega a Jacobi master last exchanged
    expected = [theta]
    for k in range(n):
        error_integral_after = integral + h * (gains["setpoint"] - theta)
        measured, used_integral = {
            "gauss-seidel-pendulum-first": ((theta, omega), integral),
            "gauss-seidel-controller-first": ((theta, omega), error_integral_after),
        }.get(coupling, (sent, integral))
        u = gains["kp"] * (gains["setpoint"] - measured[0]) + gains["ki"] * used_integral - gains["kd"] * measured[1]
        if coupling == "jacobi-first-exchange-missing" and k == 0:
            u = 0.0
        sent, integral = (theta, omega), error_integral_after
        theta, omega = theta + h * omega + h * h * u / (2 * inertia), omega + h * u / inertia
        expected.append(theta)
    result = sampled_loop_reference(n * h, h, controller=gains, parameters={"gravity": 0.0}, coupling=coupling)
    assert np.max(np.abs(result["theta"] - expected)) < 1e-12


def test_libcosim_runs_the_ssp_as_it_is_jacobi_with_its_parameter_sets(ssp):
    pytest.importorskip("libcosimpy")
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level

    from pendulum_fmu.ssp._ssp_masters import run_libcosim

    log_output_level(CosimLogLevel.WARNING)
    time, theta = run_libcosim(ssp)
    settings = read_ssp(ssp)
    expected = _reference(settings, "jacobi")
    assert np.allclose(time, expected["time"][:-1], rtol=0, atol=1e-12)
    assert np.max(np.abs(theta - expected["theta"][:-1])) < 1e-12
    verdict = judge_coupling(time, theta, settings)
    assert (verdict.coupling, verdict.parameter_set_applied, verdict.problems) == ("jacobi", True, [])


def test_fmpy_ssp_is_jacobi_without_the_first_exchange_and_ignores_the_bound_sets(ssp):
    from pendulum_fmu.ssp._ssp_masters import run_fmpy_ssp

    settings = read_ssp(ssp)
    for given, applied in ((False, False), (True, True)):
        time, theta = run_fmpy_ssp(ssp, parameter_set=given)
        expected = _reference(settings, "jacobi-first-exchange-missing", applied)
        # fmpy labels each row with the start of the step whose end it holds, one step past the stop.
        assert len(time) == len(expected) - 1 == 2001
        assert np.max(np.abs(theta - expected["theta"][1:])) < 1e-12
        verdict = judge_coupling(time, theta, settings)
        assert (verdict.coupling, verdict.parameter_set_applied, verdict.labelled_at_step_start) == (
            "jacobi-first-exchange-missing",
            applied,
            True,
        )
        assert verdict.end_time == pytest.approx(2.001)
        assert any("ran to 2.001 s" in problem for problem in verdict.problems)


def test_fmucontainer_is_jacobi_and_ignores_the_parameter_bindings(ssp):
    pytest.importorskip("fmu_manipulation_toolbox")
    from pendulum_fmu.ssp._ssp_masters import run_fmucontainer

    settings = read_ssp(ssp)
    time, theta = run_fmucontainer(ssp)
    expected = _reference(settings, "jacobi", applied=False)
    assert np.allclose(time, expected["time"][:-1], rtol=0, atol=1e-9)
    assert np.max(np.abs(theta - expected["theta"][:-1])) < 1e-12
    verdict = judge_coupling(time, theta, settings)
    assert (verdict.coupling, verdict.parameter_set_applied) == ("jacobi", False)
    assert verdict.problems == ["the SSP's parameter sets were not applied: the FMUs ran on their own defaults"]


def test_judge_names_a_wrong_step_and_an_early_stop_from_the_command_line(ssp, tmp_path, capsys):
    settings = read_ssp(ssp)
    # A Gauss-Seidel master at twice the SSP's step that stopped at 1 s (OMSimulator's CLI without
    # --stopTime), its columns named its own way.
    run = sampled_loop_reference(1.0, 2e-3, controller=settings.controller, coupling="gauss-seidel-pendulum-first")
    result = tmp_path / "out.csv"
    np.savetxt(
        result, np.column_stack([run["time"], run["theta"]]), delimiter=",", header="t,phi", comments="", fmt="%.17g"
    )
    assert main(["judge", str(result), "--ssp", str(ssp), "--map", "time=t,theta=phi"]) == 1
    printed = capsys.readouterr().out
    assert "coupling: gauss-seidel-pendulum-first" in printed
    assert "parameter set applied: yes" in printed
    assert "step 0.002 s where the SSP asks 0.001 s" in printed
    assert "ran to 1 s where the DefaultExperiment stops at 2 s" in printed
    # A result of none of the couplings: the nearest is named, and it fails.
    np.savetxt(
        result,
        np.column_stack([run["time"], run["theta"] * 1.001]),
        delimiter=",",
        header="t,phi",
        comments="",
        fmt="%.17g",
    )
    assert main(["judge", str(result), "--ssp", str(ssp), "--map", "time=t,theta=phi"]) == 1
    assert "matches no coupling: nearest" in capsys.readouterr().out
    not_an_ssp = tmp_path / "ClosedLoop.ssp"
    not_an_ssp.write_text("time,theta\n")
    assert main(["judge", str(result), "--ssp", str(not_an_ssp), "--map", "time=t,theta=phi"]) == 2
    error = capsys.readouterr().err.strip()
    assert "is not the closed loop's SSP" in error and len(error.splitlines()) == 1


def test_the_kits_closed_loop_names_each_couplings_reference_as_that_coupling(tmp_path, capsys):
    kit = tmp_path / "kit"
    assert main(["scenarios", "--output-dir", str(kit), "--closed-loop"]) == 0
    assert "wrote" in capsys.readouterr().out
    settings = json.loads((kit / "ClosedLoop.json").read_text())
    ssp_settings = read_ssp(kit / settings["ssp"])
    assert (settings["stop_time"], settings["step_size"]) == (ssp_settings.stop_time, ssp_settings.step_size)
    assert settings["controller"] == ssp_settings.controller and settings["pendulum"] == ssp_settings.pendulum
    references = np.genfromtxt(kit / settings["reference"], delimiter=",", names=True, deletechars="")
    assert references.dtype.names == ("time", *COUPLINGS)
    for coupling in COUPLINGS:
        # Each column, handed to the judge as a master's result, is that coupling and right.
        verdict = judge_coupling(references["time"], references[coupling], ssp_settings)
        assert (verdict.coupling, verdict.problems) == (coupling, [])
    assert main(["scenarios", "--output-dir", str(kit), "--closed-loop"]) == 2
    assert "--overwrite" in capsys.readouterr().err


def test_an_installed_package_without_its_packaged_controller_is_one_line(tmp_path, monkeypatch, capsys):
    # An installed package (no fmu_src/ beside it) whose data/ lacks the controller: reinstall.
    monkeypatch.setattr("pendulum_fmu.ssp._closed_loop.ROOT", tmp_path)
    monkeypatch.setattr("pendulum_fmu.ssp._closed_loop.is_source_checkout", lambda: False)
    monkeypatch.setattr("pendulum_fmu.CONTROLLER_FMU_FILE", "Absent.fmu")
    assert main(["export-ssp", str(tmp_path / "ClosedLoop.ssp")]) == 2
    [line] = capsys.readouterr().err.strip().splitlines()
    assert line.startswith("pendulum-fmu export-ssp: error: pendulum_fmu ")
    assert "has neither its packaged data/Absent.fmu" in line and "reinstall it" in line
    assert not (tmp_path / "ClosedLoop.ssp").exists()


def _recorded_torques(log):
    """The torque held over each step of the pendulum's instance, read from its record."""
    [pendulum] = [r for r in reconstruct(read_calls(log, {0: "torque"})).values() if any(s.torque for s in r.steps)]
    return np.array([step.torque for step in pendulum.steps])


def _libcosim_quiet():
    pytest.importorskip("libcosimpy")
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level

    log_output_level(CosimLogLevel.WARNING)


# What each master here does with the SSP (docs/ssp.md's table): its coupling, whether the
# controller's setpoint and the pendulum's set reach the FMUs, and whether it stops a step late.
MASTERS_AS_KNOWN = {
    "libcosim": ("jacobi", True, False),
    "fmpy.ssp": ("jacobi-first-exchange-missing", False, True),
    "fmpy.ssp parameter_set": ("jacobi-first-exchange-missing", True, True),
    "fmucontainer": ("jacobi", False, False),
}


@pytest.mark.parametrize("master", MASTERS_AS_KNOWN)
def test_the_pendulums_call_record_names_each_masters_coupling_and_sets(master, ssp, tmp_path):
    from pendulum_fmu.ssp import _ssp_masters

    if master == "libcosim":
        _libcosim_quiet()
    if master == "fmucontainer":
        pytest.importorskip("fmu_manipulation_toolbox")
    run = {
        "libcosim": _ssp_masters.run_libcosim,
        "fmpy.ssp": _ssp_masters.run_fmpy_ssp,
        "fmpy.ssp parameter_set": lambda path: _ssp_masters.run_fmpy_ssp(path, parameter_set=True),
        "fmucontainer": _ssp_masters.run_fmucontainer,
    }[master]
    coupling, applied, one_step_more = MASTERS_AS_KNOWN[master]
    settings = read_ssp(ssp)
    log = tmp_path / "calls.log"
    time, theta = run(rebind_ssp(ssp, tmp_path / "ClosedLoop.ssp", call_record=log))
    # The torques the record holds are the coupling's, by the reference alone.
    torques = _recorded_torques(log)
    steps = round(settings.stop_time / settings.step_size) + one_step_more
    expected = sampled_loop_reference(
        steps * settings.step_size,
        settings.step_size,
        controller=settings.controller if applied else None,
        coupling=coupling,
    )["torque"][:-1]
    assert len(torques) == steps
    assert np.max(np.abs(torques - expected)) < 1e-9
    verdict = judge_ssp_calls(log, settings)
    assert verdict.coupling == coupling == judge_coupling(time, theta, settings).coupling
    assert verdict.controller_missing == (() if applied else ("setpoint",))
    assert verdict.pendulum_set == (settings.pendulum if applied else {})
    assert verdict.max_difference < 1e-9
    expected_problems = [
        *(
            []
            if applied
            else [
                "the controller's setpoint did not arrive: the torques are those of its default 0.5, "
                "the SSP's set has 0.3",
                "the pendulum's parameter set did not arrive: the record shows no mass, length, inertia, gravity, "
                "damping set before initialization ended (the FMU ran on its start values)",
            ]
        ),
        *(["ran to 2.001 s where the DefaultExperiment stops at 2 s"] if one_step_more else []),
    ]
    assert verdict.problems == expected_problems


@pytest.mark.parametrize("target", ["a file of the user's", "a link to it"])
def test_a_received_ssp_cannot_make_fmucontainers_record_replace_a_users_file(target, ssp, tmp_path):
    # Issue 38: the record's path is the SSP author's choice; before, the user's file became the log.
    from pendulum_fmu import CannotWrite
    from pendulum_fmu.ssp._ssp_masters import run_fmucontainer

    pytest.importorskip("fmu_manipulation_toolbox")
    bashrc = tmp_path / "bashrc"
    bashrc.write_text("echo my settings\n")
    named = bashrc if target == "a file of the user's" else tmp_path / "link"
    if named != bashrc:
        named.symlink_to(bashrc)
    received = rebind_ssp(ssp, tmp_path / "Received.ssp", call_record=named)
    fault = "a file that is no call record" if named == bashrc else "a symbolic link"
    with pytest.raises(CannotWrite, match=f"names {named} as the pendulum's call record, but it is {fault}"):
        run_fmucontainer(received)
    assert bashrc.read_text() == "echo my settings\n"
    assert {path.name for path in tmp_path.iterdir()} == {"bashrc", "Received.ssp", named.name}


def _one_torque_a_step_late(log, step):
    """The record with the torque set before step `step` moved after that step."""
    lines = log.read_text().splitlines(keepends=True)
    do_steps = [i for i, line in enumerate(lines) if "fmi2DoStep(" in line]
    at = do_steps[step]
    [set_torque] = [i for i in range(do_steps[step - 1], at) if "fmi2SetReal(torque=" in lines[i]]
    lines.insert(at, lines.pop(set_torque))  # now after the step
    log.write_text("".join(lines))


def test_a_doctored_record_with_a_late_torque_and_no_setpoint_is_named(ssp, tmp_path, capsys):
    _libcosim_quiet()
    from pendulum_fmu.ssp._ssp_masters import run_libcosim

    settings = read_ssp(ssp)
    log = tmp_path / "calls.log"
    # The master ran a set without the setpoint (the controller's own 0.5 in force) ...
    without_setpoint = {name: value for name, value in settings.controller.items() if name != "setpoint"}
    run_libcosim(rebind_ssp(ssp, tmp_path / "NoSetpoint.ssp", call_record=log, controller=without_setpoint))
    # ... and set the torque of step 700 after that step.
    _one_torque_a_step_late(log, 700)
    torques = _recorded_torques(log)
    reference = sampled_loop_reference(2.0, 1e-3, coupling="jacobi")["torque"]  # setpoint 0.5
    assert abs(torques[700] - reference[699]) < 1e-9 < abs(reference[700] - reference[699])
    assert main(["judge", "--calls", str(log), "--ssp", str(ssp)]) == 1
    printed = capsys.readouterr().out.splitlines()
    assert "coupling: jacobi (" in printed[1]
    assert "controller's parameter set arrived: no: setpoint at the controller's default" in printed
    [late] = [line for line in printed if line.startswith("problem: step")]
    assert late.startswith(f"problem: step 700 (t = {0.7:.17g}) ")
    assert late.endswith(f"holds {torques[700]:.17g} N.m, the torque jacobi gives step 699: set a step late")
    assert (
        "problem: the controller's setpoint did not arrive: the torques are those of its default 0.5, "
        "the SSP's set has 0.3" in printed
    )
    assert printed[-1] == "FAIL"


def test_fmpys_container_fmu_read_from_its_log_is_gauss_seidel_pendulum_first(ssp, tmp_path):
    # fmpy's container (create_closed_loop_fmu) is the Gauss-Seidel master here: it takes no
    # parameter set, and with logging on its log carries both FMUs' records.
    import contextlib

    from fmpy import simulate_fmu

    from pendulum_fmu.ssp._closed_loop import create_closed_loop_fmu

    container, log = create_closed_loop_fmu(tmp_path / "ClosedLoop.fmu"), tmp_path / "container.log"
    with open(log, "w") as file, contextlib.redirect_stdout(file):
        simulate_fmu(str(container), stop_time=2.0, output_interval=1e-3, debug_logging=True)
    expected = sampled_loop_reference(2.0, 1e-3, coupling="gauss-seidel-pendulum-first")["torque"][:-1]
    assert np.max(np.abs(_recorded_torques(log) - expected)) < 1e-9
    verdict = judge_ssp_calls(log, read_ssp(ssp))
    assert (verdict.instance, verdict.coupling, verdict.controller_missing) == (
        "pendulum",
        "gauss-seidel-pendulum-first",
        ("setpoint",),
    )
    assert [problem.split(":")[0] for problem in verdict.problems] == [
        "the controller's setpoint did not arrive",
        "the pendulum's parameter set did not arrive",
    ]
