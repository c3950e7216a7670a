"""Builds that survive a user's toolchain: LTO only where the compiler has it (CMake's
CheckIPOSupported asks), CC and CFLAGS with arguments, eight builds into one path at once, an FMU
older than its sources rebuilt; and the FMU's own model description, not the repository's,
wherever an FMU is passed.
"""

import os
import shutil
import stat
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description

from fmu_build import MODEL_DESCRIPTION, build_fmu
from pendulum_fmu import __version__
from pendulum_fmu.cli import main
from pendulum_fmu.fmu._parameters import default_parameters
from pendulum_fmu.fmu._simulate import simulate
from pendulum_fmu.oracle._reference import reference

ROOT = Path(__file__).resolve().parent.parent
ENVIRONMENT = {name: value for name, value in os.environ.items() if name != "PYTHONPATH"}


def _launcher(folder: Path, refuse_lto: bool) -> Path:
    """A compiler launcher like ccache: logs each command, then runs it; or, like a gcc without
    its LTO plug-in, fails any command with -flto (or -flto=...).
    """
    script = folder / "launcher"
    refusal = (
        'for a in "$@"; do case "$a" in -flto*) echo "lto-wrapper: not found" >&2; exit 1;; esac; done\n'
        if refuse_lto
        else ""
    )
    script.write_text(f'#!/bin/sh\necho "$@" >> "{folder}/commands.log"\n{refusal}exec "$@"\n')
    script.chmod(script.stat().st_mode | stat.S_IXUSR)
    return script


def _logged_commands(folder: Path, output: str) -> list[list[str]]:
    """The logged commands that wrote output (CMake's checks of the compiler wrote others)."""
    return [line.split() for line in (folder / "commands.log").read_text().splitlines() if f"-o {output}" in line]


def _theta_error(fmu: Path) -> float:
    run = simulate(20.0, stop_time=1.0, fmu_path=fmu)
    return float(np.max(np.abs(run["theta"] - reference(20.0, stop_time=1.0)["theta"])))


@pytest.mark.parametrize("refuse_lto", [False, True], ids=["with-lto", "without-lto-plugin"])
def test_cc_and_cflags_with_arguments_and_lto_only_where_it_links(tmp_path, monkeypatch, refuse_lto):
    launcher = _launcher(tmp_path, refuse_lto)
    monkeypatch.setenv("CC", f"{launcher} gcc")
    monkeypatch.setenv("CFLAGS", "-g  -fno-omit-frame-pointer")
    fmu = build_fmu(tmp_path / "Pendulum.fmu", platforms=("linux64",))
    [link] = _logged_commands(tmp_path, "Pendulum.so")
    [compile_model] = _logged_commands(tmp_path, "CMakeFiles/fmu.dir/fmu_src/pendulum/model.c.o")
    for command in (link, compile_model):
        assert command[0] == "gcc" and "-g" in command and "-fno-omit-frame-pointer" in command
        assert any(argument.startswith("-flto") for argument in command) is not refuse_lto
    assert _theta_error(fmu) < 1e-9


@pytest.mark.build
def test_eight_builds_into_one_path_at_once_all_succeed(tmp_path):
    target = tmp_path / "Pendulum.fmu"
    builds = [
        subprocess.Popen(
            [sys.executable, "build_fmu.py", "--output", str(target), "--platforms", "linux64"],
            cwd=ROOT,
            env=ENVIRONMENT,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for _ in range(8)
    ]
    for build in builds:
        _out, err = build.communicate(timeout=300)
        assert build.returncode == 0, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["Pendulum.fmu"]  # no temporaries left
    with zipfile.ZipFile(target) as fmu:
        assert fmu.testzip() is None
    assert _theta_error(target) < 1e-9


@pytest.mark.build
def test_checkout_fmu_is_rebuilt_when_a_source_is_newer(tmp_path):
    for name in ("pendulum_fmu", "fmu_build", "fmu_src", "cmake"):
        shutil.copytree(ROOT / name, tmp_path / name, ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy2(MODEL_DESCRIPTION, tmp_path)
    shutil.copy2(ROOT / "CMakeLists.txt", tmp_path)
    ask = [sys.executable, "-c", "import pendulum_fmu; print(pendulum_fmu.default_fmu())"]

    def default_fmu_mtime():
        path = Path(
            subprocess.run(
                ask, cwd=tmp_path, env=ENVIRONMENT, capture_output=True, text=True, check=True
            ).stdout.strip()
        )
        assert path == tmp_path / "dist" / "Pendulum.fmu"
        return path.stat().st_mtime_ns

    built = default_fmu_mtime()
    assert default_fmu_mtime() == built  # up to date: used as is
    future = time.time() + 60
    os.utime(tmp_path / "fmu_src" / "pendulum" / "model.c", (future, future))
    assert default_fmu_mtime() > built


def test_fmu_carries_the_package_version(fmu, capsys):
    assert read_model_description(str(fmu)).generationTool == f"pendulum_fmu {__version__}"
    with pytest.raises(SystemExit) as exit:
        main(["--version"])
    assert exit.value.code == 0 and capsys.readouterr().out.strip() == f"pendulum-fmu {__version__}"


@pytest.fixture(scope="module")
def heavier_pendulum(tmp_path_factory):
    """Another build of the pendulum: the same model with a 50 kg head by default."""
    work = tmp_path_factory.mktemp("heavier")
    xml = work / "modelDescription.xml"
    text = MODEL_DESCRIPTION.read_text()
    original = '<Real unit="kg" start="40" min="0"/>'
    assert text.count(original) == 1
    xml.write_text(text.replace(original, '<Real unit="kg" start="50" min="0"/>'))
    return build_fmu(work / "Heavier.fmu", model_description_file=xml, platforms=("linux64",))


def test_a_passed_fmu_brings_its_own_parameters(heavier_pendulum, tmp_path):
    assert default_parameters(heavier_pendulum)["mass"] == 50.0
    expected = reference(20.0, parameters={**default_parameters(), "mass": 50.0})
    for run in (simulate(20.0, fmu_path=heavier_pendulum), reference(20.0, fmu_path=heavier_pendulum)):
        assert np.max(np.abs(run["theta"] - expected["theta"])) < 1e-9
    assert (
        main(["simulate", "--torque", "20", "--fmu", str(heavier_pendulum), "--output", str(tmp_path / "heavier.csv")])
        == 0
    )
    theta = np.genfromtxt(tmp_path / "heavier.csv", delimiter=",", names=True)["theta"]
    assert np.max(np.abs(theta - expected["theta"])) < 1e-9
    # And 50 kg is not 40 kg: the check above can tell the builds apart.
    assert np.max(np.abs(reference(20.0)["theta"] - expected["theta"])) > 1e-3
