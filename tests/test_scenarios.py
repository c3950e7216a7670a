"""The scenario kit: its files, its FMI-LS-REF layout, its references against the analytic
solution, and every scenario run through fmpy (a master on FMU2Slave, benchmarks/masters.py, and
simulate_fmu) and through this package's own native loop, each judged a pass.
"""

import itertools
import json
import re
import shutil
import zipfile
from fractions import Fraction
from xml.etree import ElementTree

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.validation import validate_fmu

from benchmarks.masters import run
from pendulum_fmu._errors import InvalidInput
from pendulum_fmu.cli import main
from pendulum_fmu.fmu import _native_loop as cs_loop
from pendulum_fmu.fmu._instance import open_fmu
from pendulum_fmu.fmu._parameters import default_parameters, total_inertia
from pendulum_fmu.fmu._simulate import run_schedule
from pendulum_fmu.judging._diagnoses import AGREES
from pendulum_fmu.judging._judge import judge, judge_kit
from pendulum_fmu.scenarios._scenario_list import SCENARIOS
from pendulum_fmu.scenarios._scenario_settings import KIT_FMU, read_settings
from pendulum_fmu.scenarios._scenarios import LS_REF_FOLDER, LS_REF_VERSION, KitExists, kit_files, write_scenarios
from pendulum_fmu.signals._torque_schedule import TorqueSchedule, schedule

NAMES = [s.name for s in SCENARIOS]
# The role values of the FMI-LS-REF 1.0.0-beta.1 schema (fmi3LayeredStandardReferenceManifest.xsd).
ROLE = re.compile(
    r"(document|requirement|specification|model|parameter|system|testcase|"
    r"experiment(/(smoke-test|validation|uncertainty-analysis))?|result|method|rationale|"
    r"report|request|delivery|configuration|signature|serialized-state(/.*)?|meta-data|other)"
)
LS = "{http://fmi-standard.org/fmi-ls-manifest}"
SSV = "{http://ssp-standard.org/SSP1/SystemStructureParameterValues}"


@pytest.fixture(scope="module")
def kit(tmp_path_factory, fmu):
    folder = tmp_path_factory.mktemp("kit")
    write_scenarios(folder, fmu)
    return folder


def _judged(kit, name):
    settings = read_settings(kit / f"{name}.json")
    return judge(kit / settings.pop("output"), **settings)


def test_the_kit_has_every_scenario_the_issue_asks_for(kit):
    assert set(NAMES) == {"constant_torque", "steps_on_grid", "random_steps", "decimal_steps", "ramp", "resume"}
    for name in NAMES:
        settings = json.loads((kit / f"{name}.json").read_text())
        for key in ("start_time", "stop_time", "step_size", "parameters", "theta0", "omega0", "ramp"):
            assert key in settings
        assert set(settings["parameters"]) == set(default_parameters())
        reference = np.genfromtxt(kit / f"{name}_ref.csv", delimiter=",", names=True)
        assert reference.dtype.names == ("time", "torque", "theta", "omega", "alpha")
        steps = round((settings["stop_time"] - settings["start_time"]) / settings["step_size"])
        assert len(reference) == steps + 1 and reference["time"][-1] == settings["stop_time"]
    assert json.loads((kit / "ramp.json").read_text())["ramp"] is True
    assert json.loads((kit / "resume.json").read_text())["resume_time"] == 1.5
    # Decimal jump times that no binary fraction is: 0.027 is not 3 * 0.009 in doubles.
    assert 3 * 0.009 != 0.027 and "0.027," in (kit / "decimal_steps_in.csv").read_text()


def test_steps_on_grid_reference_is_the_analytic_solution(kit):
    """Gravity off: theta is theta0 + omega0 t + the double integral of the held torque / I."""
    settings = json.loads((kit / "steps_on_grid.json").read_text())
    rows = [line.split(",") for line in (kit / "steps_on_grid_in.csv").read_text().split()[1:]]
    jumps = [(Fraction(t), float(u)) for (t, _), (t2, u) in itertools.pairwise(rows) if t == t2]
    inertia = total_inertia(settings["parameters"])
    alphas = [float(rows[0][1]) / inertia] + [u / inertia for _, u in jumps]
    reference = np.genfromtxt(kit / "steps_on_grid_ref.csv", delimiter=",", names=True)
    for t, theta in zip(reference["time"][::97], reference["theta"][::97], strict=False):
        exact = settings["theta0"] + settings["omega0"] * t + alphas[0] * t**2 / 2
        for (when, _), before, after in zip(jumps, alphas, alphas[1:], strict=False):
            if float(when) <= t:  # from a jump on, the change of alpha adds its own parabola
                exact += (after - before) * (t - float(when)) ** 2 / 2
        assert abs(theta - exact) < 1e-12, t


def test_the_fmu_carries_the_kit_as_fmi_ls_ref(kit):
    with zipfile.ZipFile(kit / KIT_FMU) as fmu:
        names = set(fmu.namelist())
        manifest = ElementTree.fromstring(fmu.read(LS_REF_FOLDER + "fmi-ls-manifest.xml"))
        experiments = ElementTree.fromstring(fmu.read(LS_REF_FOLDER + "scenarios.exp"))
        ssv = ElementTree.fromstring(fmu.read(LS_REF_FOLDER + "resume.ssv"))
        for name in NAMES:  # the files beside the FMU, byte for byte
            for suffix in ("_in.csv", ".json", "_ref.csv"):
                assert fmu.read(f"{LS_REF_FOLDER}{name}{suffix}") == (kit / f"{name}{suffix}").read_bytes()
    assert "documentation/fmi-ls-ref.txt" in names and "modelDescription.xml" in names
    assert manifest.tag == "fmiReferences"
    assert manifest.get(f"{LS}fmi-ls-name") == "org.fmi-standard.fmi-ls-ref"
    assert manifest.get(f"{LS}fmi-ls-version") == LS_REF_VERSION == "1.0.0-beta.1"
    related = manifest.findall("Related")
    assert {r.get("role") for r in related} == {"experiment/validation", "parameter", "configuration", "result"}
    for item in related:
        assert ROLE.fullmatch(item.get("role")) and LS_REF_FOLDER + item.get("source") in names
    experiment = {e.get("name"): e for e in experiments.findall("Experiment")}
    assert list(experiment) == NAMES
    for name in NAMES:
        settings = json.loads((kit / f"{name}.json").read_text())
        assert float(experiment[name].get("stepSize")) == settings["step_size"]
        assert float(experiment[name].get("stopTime")) == settings["stop_time"]
        for element, suffix in (("Parameters", ".ssv"), ("Stimuli", "_in.csv"), ("References", "_ref.csv")):
            assert experiment[name].find(element).get("source") == f"{name}{suffix}"
    values = {p.get("name"): float(p.find(f"{SSV}Real").get("value")) for p in ssv.iter(f"{SSV}Parameter")}
    assert values == {**default_parameters(), "theta": -0.2, "omega": 1.0}
    assert validate_fmu(str(kit / KIT_FMU)) == []


@pytest.mark.parametrize("name", NAMES)
def test_an_fmpy_master_passes_every_scenario(kit, name):
    run(kit, name)
    judgement = _judged(kit, name)
    assert judgement.passed and judgement.diagnosis == AGREES
    assert judgement.max_abs_dtheta < 1e-10


@pytest.mark.parametrize("name", ["constant_torque", "steps_on_grid", "random_steps", "decimal_steps"])
def test_fmpy_simulate_fmu_passes_the_held_scenarios(kit, name):
    settings = json.loads((kit / f"{name}.json").read_text())
    signal = np.genfromtxt(kit / settings["input"], delimiter=",", names=True)
    run = simulate_fmu(
        str(kit / KIT_FMU),
        start_time=settings["start_time"],
        stop_time=settings["stop_time"],
        step_size=settings["step_size"],
        output_interval=settings["step_size"],
        relative_tolerance=settings["relative_tolerance"],
        input=signal,
        start_values={**settings["parameters"], "theta": settings["theta0"], "omega": settings["omega0"]},
        output=["theta", "omega"],
    )
    np.savetxt(
        kit / settings["output"],
        np.column_stack([run["time"], run["theta"], run["omega"]]),
        delimiter=",",
        header="time,theta,omega",
        comments="",
        fmt="%.17g",
    )
    judgement = _judged(kit, name)
    assert judgement.passed and judgement.max_abs_dtheta < 1e-10


def _native(kit, name):
    """The scenario through this package's schedule and native loop; resume through a serialized
    FMU state restored into a new instance.
    """
    s = read_settings(kit / f"{name}.json")
    plan = schedule(
        s["torque"], start_time=s["start_time"], stop_time=s["stop_time"], step_size=s["step_size"], ramp=s["ramp"]
    )
    resume = json.loads((kit / f"{name}.json").read_text())["resume_time"]
    cut = len(plan.time) - 1 if resume is None else int(np.argmin(np.abs(plan.time - resume)))
    start = dict(parameters=s["parameters"], theta0=s["theta0"], omega0=s["omega0"], fmu_path=kit / KIT_FMU)
    slave = open_fmu(**start)
    assert cs_loop.drives(slave), "build the native loop: pip install -e ."
    parts = [run_schedule(slave, _part(plan, 0, cut))]
    if resume is not None:
        blob = slave.serializeFMUstate(slave.getFMUstate())
        slave.terminate()
        slave.freeInstance()
        slave = open_fmu(**start, start_time=resume)
        slave.setFMUstate(slave.deSerializeFMUstate(blob))
        parts.append(run_schedule(slave, _part(plan, cut, len(plan.time) - 1))[1:])
    slave.terminate()
    slave.freeInstance()
    result = np.concatenate(parts)
    columns = [result["time"], result["theta"], result["omega"], result["alpha"]]
    np.savetxt(
        kit / f"{name}_out.csv",
        np.column_stack(columns),
        delimiter=",",
        header="time,theta,omega,alpha",
        comments="",
        fmt="%.17g",
    )


def _part(plan, first, last):
    return TorqueSchedule(
        time=plan.time[first : last + 1], torque=plan.torque[first:last], torque_rate=plan.torque_rate[first:last]
    )


def test_the_native_loop_passes_every_scenario_and_judge_says_so_per_line(kit, capsys, tmp_path):
    own = tmp_path / "kit"
    shutil.copytree(kit, own)
    for path in own.glob("*_out.csv"):
        path.unlink()
    for name in NAMES:
        _native(own, name)
    verdicts = judge_kit(own)
    assert all(j.passed and j.max_abs_dtheta < 1e-10 for j in verdicts.values())
    assert main(["judge", str(own), "--json", str(tmp_path / "kit.json")]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line.split()[:3] for line in lines[: len(NAMES)]] == [[n, "pass", AGREES] for n in sorted(NAMES)]
    assert lines[len(NAMES)] == f"{len(NAMES)} of {len(NAMES)} results pass"
    assert json.loads((tmp_path / "kit.json").read_text())["scenarios"]["resume"]["verdict"] == "pass"


def test_a_kit_is_replaced_only_when_asked_and_the_results_stay(tmp_path, capsys):
    folder = tmp_path / "kit"
    assert main(["scenarios", "--output-dir", str(folder)]) == 0
    assert capsys.readouterr().out.count("wrote") == 2 + 3 * len(NAMES)
    (folder / "ramp_out.csv").write_text("time,theta\n0,0\n")
    (folder / "ReadMe.md").write_text("my notes\n")
    (folder / "random_steps_in.csv").write_text("time,torque\n0,1\n4,1\n")
    assert main(["scenarios", "--output-dir", str(folder)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err == [
        f"pendulum-fmu scenarios: error: {folder} already holds a scenario kit (Pendulum.fmu, "
        "ReadMe.md, constant_torque_in.csv and 17 more): choose another output directory, or add "
        "--overwrite to write the kit again in its place (the results NAME_out.csv beside it "
        "are kept)"
    ]
    assert (folder / "ReadMe.md").read_text() == "my notes\n"
    assert (folder / "random_steps_in.csv").read_text() == "time,torque\n0,1\n4,1\n"
    assert main(["scenarios", "--output-dir", str(folder), "--overwrite"]) == 0
    assert (folder / "ReadMe.md").read_text().startswith("# Scenarios for a master")
    assert (folder / "random_steps_in.csv").read_text().count("\n") == len(SCENARIOS[2].rows) + 1
    assert (folder / "ramp_out.csv").read_text() == "time,theta\n0,0\n"
    assert not list(folder.glob(".*"))  # no temporary or staging folder left


def test_a_folder_without_a_kit_is_written_into(tmp_path):
    """Only the kit's own files make a folder a kit's: others are neither refused nor touched."""
    (tmp_path / "notes.txt").write_text("mine\n")
    written = write_scenarios(tmp_path)
    assert sorted(path.name for path in written) == sorted(kit_files())
    assert (tmp_path / "notes.txt").read_text() == "mine\n"
    with pytest.raises(KitExists, match="already holds a scenario kit"):
        write_scenarios(tmp_path)


def test_a_kit_that_fails_to_write_leaves_the_folder_as_it_was(tmp_path, monkeypatch):
    from pendulum_fmu.scenarios import _scenarios as scenarios

    write_scenarios(tmp_path)
    before = {path.name: path.read_bytes() for path in tmp_path.iterdir()}

    def broken(steps):
        raise RuntimeError("stopped while writing")

    monkeypatch.setattr(scenarios, "_readme", broken)
    with pytest.raises(RuntimeError):
        write_scenarios(tmp_path, overwrite=True)
    assert {path.name: path.read_bytes() for path in tmp_path.iterdir()} == before


# NAME.json as `scenarios` writes it, then edited by hand: each bad field refused naming file and field.
BAD_SETTINGS = {
    "stop_time three": ({"stop_time": "three"}, 'stop_time is "three"; it must be a finite number (s)'),
    "stop_time NaN text": ({"stop_time": "NaN"}, 'stop_time is "NaN"; it must be a finite number (s)'),
    "stop_time NaN": ({"stop_time": float("nan")}, "stop_time is NaN; it must be a finite number (s)"),
    "stop_time true": ({"stop_time": True}, "stop_time is true; it must be a finite number (s)"),
    "stop before start": ({"stop_time": -1.0}, "stop_time -1.0 is not after start_time 0.0"),
    "step_size 0": ({"step_size": 0}, "step_size is 0; it must be a positive finite number (s)"),
    "tolerance x": ({"tolerance": "x"}, 'tolerance is "x"; it must be a positive finite number (rad)'),
    "output null": ({"output": None}, "output is null; it must be a file name (a JSON string)"),
    "input null": ({"input": None}, "input is null; it must be a file name (a JSON string)"),
    "ramp text": ({"ramp": "yes"}, 'ramp is "yes"; it must be true or false'),
    "parameters list": ({"parameters": []}, "parameters is []; it must be an object {name: value}"),
    "parameter text": ({"parameters": {"mass": "x"}}, 'parameters: mass is "x"; it must be a finite number'),
    "theta0 null": ({"theta0": None}, "theta0 is null; it must be a finite number (rad)"),
}


@pytest.mark.parametrize("edit", BAD_SETTINGS, ids=list(BAD_SETTINGS))
def test_hand_edited_settings_are_refused_naming_the_file_and_field(kit, tmp_path, edit):
    changes, message = BAD_SETTINGS[edit]
    settings = json.loads((kit / "constant_torque.json").read_text())
    path = tmp_path / "constant_torque.json"
    path.write_text(json.dumps({**settings, **changes}))
    with pytest.raises(InvalidInput) as refused:
        read_settings(path)
    assert str(refused.value).startswith(f"{path}: {message}")
    assert str(refused.value).endswith(
        "write the kit again with pendulum-fmu scenarios --output-dir FOLDER --overwrite"
    )


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("[]", "not a scenario's settings: it holds a JSON array, not an object"),
        ("null", "not a scenario's settings: it holds a JSON null, not an object"),
        ('{"input": "a_in.csv"}', "not a scenario's settings: no 'output', 'start_time'"),
        ("{", "not a scenario's settings: Expecting property name"),
    ],
)
def test_settings_that_are_no_settings_are_refused(tmp_path, text, message):
    (tmp_path / "s.json").write_text(text)
    with pytest.raises(InvalidInput, match=f"^{tmp_path / 's.json'}: {message}"):
        read_settings(tmp_path / "s.json")


def test_settings_as_written_read_back_as_floats(kit):
    settings = read_settings(kit / "steps_on_grid.json")
    assert settings["torque"] == kit / "steps_on_grid_in.csv" and settings["output"] == "steps_on_grid_out.csv"
    assert settings["stop_time"] == 3.0 and settings["step_size"] == 1e-3 and settings["ramp"] is False
    assert settings["parameters"]["gravity"] == 0.0 and settings["theta0"] == 0.2
    assert settings["tolerance"] == 1e-9


def test_a_kit_without_results_and_an_fmi3_fmu_are_refused(kit, fmu3, tmp_path, capsys):
    empty = tmp_path / "empty"
    write_scenarios(empty)
    assert main(["judge", str(empty)]) == 2
    assert "no result to judge" in capsys.readouterr().err
    assert main(["scenarios", "--output-dir", str(tmp_path / "k3"), "--fmu", str(fmu3)]) == 2
    assert "is FMI 3.0: the kit is for the FMI 2.0 FMU" in capsys.readouterr().err
