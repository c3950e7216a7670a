"""--tools / --map parsing, and another FMU (ours rebuilt with other names) as a tool."""

import csv
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from fmu_build import MODEL_DESCRIPTION, PENDULUM_DIR, SOURCE_DIR, build_fmu
from pendulum_fmu._errors import NotComputed, Skipped
from pendulum_fmu.cli import main
from pendulum_fmu.comparing import _compare_tools as compare_tools
from pendulum_fmu.comparing._compare import compare, run_tools
from pendulum_fmu.comparing._mapped_fmu import MapError, Mapped, MappedFmu, parse_map
from pendulum_fmu.oracle._reference import reference_schedule
from pendulum_fmu.signals._torque_schedule import schedule, schedule_windows

RENAMES = {
    "torque": "u",
    "theta": "phi",
    "omega": "w",
    "alpha": "a",
    "mass": "m",
    "length": "L",
    "inertia": "J",
    "gravity": "g",
    "damping": "d",
}
FULL_MAP = ",".join(f"{ours}={theirs}" for ours, theirs in RENAMES.items())
PLAN = schedule(lambda t: 50.0 if t < 0.25 else -80.0, stop_time=0.5, step_size=1e-3)


@pytest.fixture(scope="session")
def renamed_fmu(build_once):
    """The pendulum under other variable names and another model identifier, built over the same
    plumbing from a copied model.c and modelDescription.xml, once per session, for this machine.
    """
    return build_once("renamed", _renamed_build)


def _renamed_build(folder):
    model = folder / "model"
    model.mkdir()
    shutil.copy2(PENDULUM_DIR / "config.h", model)
    code = (PENDULUM_DIR / "model.c").read_text()
    xml = MODEL_DESCRIPTION.read_text().replace('modelIdentifier="Pendulum"', 'modelIdentifier="Renamed"')
    for ours, theirs in RENAMES.items():
        code = code.replace(f"VR_{ours.upper()}", f"VR_{theirs.upper()}")
        xml = xml.replace(f'name="{ours}"', f'name="{theirs}"')
    (model / "model.c").write_text(code)
    (model / "modelDescription.xml").write_text(xml)
    description = model / "modelDescription.xml"
    return build_fmu(
        folder / "Renamed.fmu", model_dir=model, model_description_file=description, platforms=("linux64",)
    )


def max_error(run, expected, field="theta"):
    return float(np.max(np.abs(run[field] - expected[field])))


def test_tools_parse_in_order_with_modes():
    pytest.importorskip("pydrake")
    pytest.importorskip("mujoco")
    parsed = compare_tools.parse_tools("fmu, reference,drake:default,mujoco:accurate")
    assert [tool.label for tool in parsed] == ["fmu", "reference", "drake:default", "mujoco"]


@pytest.mark.parametrize(
    "spec, message",
    [
        ("fmu,matlab,simulink", "unknown tool(s) matlab, simulink"),
        ("reference,fmu,reference", "--tools names reference twice"),
        ("drake:fast", "drake has modes accurate, default, not 'fast'"),
        ("fmu:default", "fmu has mode accurate, not 'default'"),
        (" , ", "--tools is empty"),
        ("fmu=x.fmu", "the label must be a name"),
        ("theirs=missing.fmu", "theirs: no FMU at missing.fmu"),
    ],
)
def test_bad_tool_lists_are_refused_in_one_line(spec, message):
    with pytest.raises(ValueError) as raised:
        compare_tools.parse_tools(spec)
    assert message in str(raised.value) and "\n" not in str(raised.value)


def test_a_missing_extra_names_the_pip_command(monkeypatch):
    monkeypatch.setattr(compare_tools, "installed", lambda name: name != "pybullet")
    with pytest.raises(
        compare_tools.ToolSpecError,
        match=r"pybullet is not installed; install it with: "
        r'pip install "\.\[pybullet\]" in a clone',
    ):
        compare_tools.parse_tools("fmu,pybullet")


def test_cli_refuses_a_duplicate_tool_in_one_line(tmp_path, capsys):
    assert main(["compare", "--torque", "1", "--tools", "fmu,fmu", "--output-dir", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "--tools names fmu twice" in err and err.count("\n") == 1


def test_map_parsing():
    assert parse_map("torque=u, theta=phi*0.0174532925,alpha=der(w)") == {
        "torque": Mapped("u"),
        "theta": Mapped("phi", 0.0174532925),
        "alpha": Mapped("der(w)"),
    }
    for text, message in [
        ("speed=w", "unknown quantity 'speed'"),
        ("theta", "not QUANTITY=VARIABLE"),
        ("theta=a,theta=b", "theta is mapped twice"),
        ("theta=phi*0", "finite and nonzero"),
    ]:
        with pytest.raises(MapError, match=message):
            parse_map(text)
    with pytest.raises(compare_tools.ToolSpecError, match="--map applies to FMUs"):
        compare_tools.parse_tools("fmu,reference", mapping="torque=u")


@pytest.mark.parametrize("interface", ["CoSimulation", "ModelExchange"])
def test_another_fmu_under_other_names_matches_the_reference(renamed_fmu, interface):
    parameters = {"damping": 3.0, "length": 0.7}
    expected = reference_schedule(PLAN, parameters=parameters, theta0=0.2, omega0=-1.0)
    run = MappedFmu(renamed_fmu, FULL_MAP, interface=interface).run(
        PLAN, parameters=parameters, theta0=0.2, omega0=-1.0
    )
    assert max_error(run, expected) < 1e-9
    assert max_error(run, expected, "alpha") < 1e-7


def test_a_co_simulation_fmu_walked_in_windows_is_its_whole_run(renamed_fmu, tmp_path):
    signal = lambda t: 50.0 if t < 0.25 else -80.0  # noqa: E731  PLAN's
    windows = schedule_windows(signal, stop_time=0.5, step_size=1e-3, window_steps=37)
    theirs = MappedFmu(renamed_fmu, FULL_MAP, interface="CoSimulation")
    blocks = list(theirs.run_windows(windows, parameters={"damping": 3.0}, theta0=0.2))
    assert len(blocks) == 14
    assert np.array_equal(np.concatenate(blocks), theirs.run(PLAN, parameters={"damping": 3.0}, theta0=0.2))
    comparison = compare(
        signal, f"theirs={renamed_fmu},reference", mapping=FULL_MAP, output_dir=tmp_path, stop_time=0.5, window_steps=37
    )
    assert comparison.whole == () and comparison.agree  # Co-Simulation, the FMU's first interface


def test_a_scale_factor_converts_both_ways(renamed_fmu):
    # theta = phi * 0.5: the start value 0.1 sets phi to 0.2, and theta reads back half of phi,
    # which swings as the pendulum started at 0.2.
    half = FULL_MAP.replace("theta=phi", "theta=phi*0.5")
    run = MappedFmu(renamed_fmu, half).run(PLAN, theta0=0.1)
    from_double = reference_schedule(PLAN, theta0=0.2)
    assert np.max(np.abs(run["theta"] - 0.5 * from_double["theta"])) < 1e-10


def test_an_unmapped_quantity(renamed_fmu):
    with pytest.raises(MapError, match="has no variable 'torque': name it with --map torque=VARIABLE"):
        MappedFmu(renamed_fmu, "theta=phi")
    with pytest.raises(MapError, match="has no variable 'psi' \\(mapped to theta\\)"):
        MappedFmu(renamed_fmu, "torque=u,theta=psi")
    partial = MappedFmu(renamed_fmu, "torque=u,theta=phi")
    with pytest.raises(MapError, match="no variable for gravity = 0: map it with --map gravity=VARIABLE"):
        partial.run(PLAN, parameters={"gravity": 0.0})
    # omega and alpha unmapped: reported as NaN; the FMU's own parameters are the defaults.
    run = partial.run(PLAN)
    assert np.all(np.isnan(run["omega"])) and np.all(np.isnan(run["alpha"]))
    assert max_error(run, reference_schedule(PLAN)) < 1e-9


def test_compare_runs_another_fmu_beside_ours(renamed_fmu):
    runs = run_tools(
        PLAN, ["fmu", "reference", f"theirs={renamed_fmu}"], mapping=FULL_MAP, parameters={"gravity": 3.0}, theta0=0.4
    )
    assert list(runs) == ["fmu", "reference", "theirs"]
    assert max_error(runs["theirs"], runs["fmu"]) < 1e-12
    assert max_error(runs["theirs"], runs["reference"]) < 1e-9


DEGREE = 0.017453292519943295
DEGREES_MAP = (
    f"torque=tau,theta=phi*{DEGREE!r},omega=w*{DEGREE!r},alpha=a*{DEGREE!r},"
    f"theta0=phi_start*{DEGREE!r},omega0=w_start*{DEGREE!r},"
    "mass=m,length=L,inertia=J,gravity=g,damping=c"
)


@pytest.fixture(scope="module")
def degrees_fmu(tmp_path_factory):
    """tests/fmus/degrees_pendulum.py built by pythonfmu3: FMI 3.0, CS and ME, angles in degrees,
    the start values as parameters of their own.
    """
    builder = pytest.importorskip("pythonfmu3.builder")
    return builder.FmuBuilder.build_FMU(
        SOURCE_DIR.parent / "tests" / "fmus" / "degrees_pendulum.py", dest=tmp_path_factory.mktemp("degrees")
    )


@pytest.mark.parametrize("interface", ["CoSimulation", "ModelExchange"])
def test_an_fmi3_fmu_in_degrees_matches_the_reference(degrees_fmu, interface):
    parameters = {"damping": 3.0, "mass": 25.0}
    theirs = MappedFmu(degrees_fmu, DEGREES_MAP, interface=interface)
    run = theirs.run(PLAN, parameters=parameters, theta0=0.2, omega0=-1.0)
    expected = reference_schedule(PLAN, parameters=parameters, theta0=0.2, omega0=-1.0)
    assert max_error(run, expected) < 1e-10
    assert max_error(run, expected, "omega") < 1e-9
    assert max_error(run, expected, "alpha") < 1e-9


def test_compare_takes_an_fmi3_fmu_by_path(degrees_fmu):
    runs = run_tools(PLAN, ["reference", f"theirs={degrees_fmu}"], mapping=DEGREES_MAP, theta0=0.1)
    assert max_error(runs["theirs"], runs["reference"]) < 1e-10


def test_every_tool_takes_its_defaults_from_the_fmu_compared(tmp_path):
    """An FMU whose description gives another default mass: the reference beside it (and the
    judge) use that mass too, not the packaged FMU's.
    """
    description = tmp_path / "modelDescription.xml"
    xml = MODEL_DESCRIPTION.read_text()
    assert xml.count('<Real unit="kg" start="40" min="0"/>') == 1
    description.write_text(xml.replace('<Real unit="kg" start="40" min="0"/>', '<Real unit="kg" start="10" min="0"/>'))
    lighter = build_fmu(tmp_path / "Lighter.fmu", model_description_file=description, platforms=("linux64",))
    runs = run_tools(PLAN, "fmu,reference", fmu_path=lighter)
    assert max_error(runs["fmu"], runs["reference"]) < 1e-9
    expected = reference_schedule(PLAN, parameters={"mass": 10.0})
    assert max_error(runs["reference"], expected) < 1e-12
    assert max_error(runs["reference"], reference_schedule(PLAN)) > 1e-3  # the mass matters here


def test_compare_on_a_plain_install_runs_the_tools_installed_and_says_which_it_skipped(tmp_path):
    # A fresh interpreter in which OpenSim and the engines cannot be imported, as on an install
    # without the extras: a None in sys.modules is what Python's import reads as "not there".
    script = (
        "import sys\n"
        "sys.modules.update(dict.fromkeys(['opensim', 'mujoco', 'pydrake', 'pybullet']))\n"
        "from pendulum_fmu.cli import main\n"
        f"sys.exit(main(['compare', '--torque', '20', '--output-dir', {str(tmp_path)!r}]))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], cwd=Path(__file__).resolve().parents[1], capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    assert done.stderr == (
        "pendulum-fmu compare: skipped opensim (opensim is not installed: pip install "
        '".[opensim]" in a clone of pendulum-fmu (or "WHEEL.whl[opensim]" for its wheel))\n'
    )
    with open(tmp_path / "differences.csv", newline="") as file:
        rows = list(csv.DictReader(file))
    # The FMU ran, and against the reference it agrees to the default tolerance.
    assert [(row["tool"], row["against"]) for row in rows] == [("fmu", "reference")]
    assert 0 < float(rows[0]["theta_max"]) < 1e-9


def test_the_default_tools_leave_out_what_is_not_installed_with_a_warning(monkeypatch):
    monkeypatch.setattr(compare_tools, "installed", lambda name: name != "opensim")
    with pytest.warns(Skipped, match=r'^skipped opensim \(opensim is not installed: pip install "\.\[opensim\]"'):
        assert compare_tools.installed_defaults() == ["fmu", "reference"]


@pytest.mark.parametrize("tool", ["fmu", "reference", "theirs", "mujoco"])
def test_a_tool_asked_for_an_output_it_cannot_compute_says_so(tool, renamed_fmu):
    """An output added to the set a tool is asked for (energy, which no tool computes) comes back
    as a NaN column with a one-line warning naming the tool, never zeros; the outputs it does
    compute stay the same numbers, checked against the reference's.
    """
    if tool == "mujoco":
        pytest.importorskip("mujoco")
    spec = f"theirs={renamed_fmu}" if tool == "theirs" else tool
    (parsed,) = compare_tools.parse_tools(spec, mapping=FULL_MAP if tool == "theirs" else None)
    with pytest.warns(NotComputed, match=rf"^{tool} cannot compute energy: its column is NaN") as caught:
        run = parsed.run(PLAN, outputs=("theta", "omega", "alpha", "energy"))
    assert len(caught) == 1 and "\n" not in str(caught[0].message)
    assert run.dtype.names == ("time", "torque", "theta", "omega", "alpha", "energy")
    assert np.all(np.isnan(run["energy"]))
    assert max_error(run, reference_schedule(PLAN)) < 1e-8
    # Asked for what it computes (the FMU's outputs, the default), it says nothing.
    with warnings.catch_warnings():
        warnings.simplefilter("error", NotComputed)
        assert parsed.run(PLAN).dtype.names == ("time", "torque", "theta", "omega", "alpha")
