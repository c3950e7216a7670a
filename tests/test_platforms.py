"""One FMU for every platform, in both FMI versions: the win64 binary (mingw-w64) run under wine
and the aarch64-linux binary (gcc-aarch64-linux-gnu) run under qemu-aarch64, each by the same bare
C master that runs the linux64 binary, with the same numbers; and a build that skips a platform
whose compiler is missing."""

import os
import re
import shutil
import subprocess
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description

import pendulum_fmu.build
from benchmarks.builds import build_step_master
from pendulum_fmu.build import FMI_VERSIONS, PLATFORMS, BuildError, Platform, PlatformSkipped, build_fmu
from pendulum_fmu.cli import main
from pendulum_fmu.reference import reference

STEPS, STEP_SIZE = 3000, 1e-3  # the tutorial case: 20 N.m, gravity on, 3 s
# How each platform's master runs here: natively, under wine, under qemu with the cross libc.
RUNNERS = {"linux64": [], "win64": ["wine"], "aarch64-linux": ["qemu-aarch64", "-L", "/usr/aarch64-linux-gnu"]}
CROSS = [pytest.param(platform, marks=pytest.mark.skipif(
    shutil.which(PLATFORMS[platform].cross_compiler) is None or shutil.which(RUNNERS[platform][0]) is None,
    reason=f"needs Debian's {PLATFORMS[platform].package} and {RUNNERS[platform][0]} (.ci/run installs them)"))
    for platform in ("win64", "aarch64-linux")]
EACH_FMI_VERSION = pytest.mark.parametrize("fmi_version", FMI_VERSIONS, ids=lambda version: f"fmi{version}")
# The value references benchmarks/bare_master.h hard-codes (VR_TORQUE, VR_THETA).
MASTER_VALUE_REFERENCES = {"torque": 0, "theta": 1}


@dataclass(frozen=True)
class UnzippedBuild:
    """A default build (every platform whose compiler is here) of one FMI version, unzipped into
    work/, where its masters and their trajectories go too."""

    fmi_version: int
    work: Path
    token: str  # the FMI 2.0 guid, the FMI 3.0 instantiationToken
    value_references: dict

    def library(self, platform):
        folder = platform if self.fmi_version == 2 else PLATFORMS[platform].fmi3_folder
        return self.work / "unzipped/binaries" / folder / f"Pendulum{PLATFORMS[platform].suffix}"


@pytest.fixture(scope="module")
def every_platform(tmp_path_factory):
    """{FMI version: its UnzippedBuild}."""
    builds = {}
    for fmi_version in FMI_VERSIONS:
        work = tmp_path_factory.mktemp(f"platforms_fmi{fmi_version}")
        fmu = build_fmu(work / "Pendulum.fmu", fmi_version=fmi_version)
        with zipfile.ZipFile(fmu) as archive:
            archive.extractall(work / "unzipped")
        description = read_model_description(str(fmu))
        assert description.fmiVersion == f"{fmi_version}.0"
        builds[fmi_version] = UnzippedBuild(fmi_version, work, description.guid,
                                            {v.name: v.valueReference for v in description.modelVariables})
    return builds


def _exports_of_dll(dll):
    table = subprocess.run(["x86_64-w64-mingw32-objdump", "-p", str(dll)], capture_output=True,
                           text=True, check=True).stdout
    names = table.split("[Ordinal/Name Pointer] Table", 1)[1].split("\n\n", 1)[0]
    return set(re.findall(r"\]\s+(\w+)", names))


def _exports_of_so(library, nm="nm"):
    symbols = subprocess.run([nm, "-D", "--defined-only", str(library)], capture_output=True,
                             text=True, check=True).stdout
    return {line.split()[-1] for line in symbols.splitlines()}


def _exports(platform, library):
    if platform == "win64":
        return _exports_of_dll(library)
    return _exports_of_so(library, "aarch64-linux-gnu-nm" if platform == "aarch64-linux" else "nm")


def _theta_by_step_master(build, platform):
    """theta at every communication point, from the C master of build's FMI version built for and
    run on platform."""
    assert {name: build.value_references[name] for name in MASTER_VALUE_REFERENCES} == MASTER_VALUE_REFERENCES
    master = build_step_master(build.work, platform, build.fmi_version)
    trajectory = build.work / f"theta_{platform}.txt"
    # One wine prefix for both FMI versions: making one takes wine seconds.
    environment = {**os.environ, "WINEPREFIX": str(build.work.parent / "wineprefix"), "WINEDEBUG": "-all"}
    subprocess.run([*RUNNERS[platform], str(master), str(build.library(platform)), build.token, str(STEPS),
                    repr(STEP_SIZE), "0", str(trajectory)], check=True, capture_output=True,
                   env=environment, timeout=300)
    return np.loadtxt(trajectory)


@pytest.mark.parametrize("platform", CROSS)
@EACH_FMI_VERSION
def test_binary_exports_exactly_the_functions_of_the_linux_binary(every_platform, fmi_version, platform):
    build = every_platform[fmi_version]
    exports = _exports(platform, build.library(platform))
    assert exports == _exports_of_so(build.library("linux64"))
    assert all(name.startswith(f"fmi{fmi_version}") for name in exports) and f"fmi{fmi_version}DoStep" in exports


# linux64 too: there the master of each FMI version checks the other's, and scipy, with no cross tools.
@pytest.mark.parametrize("platform", ["linux64", *CROSS])
@EACH_FMI_VERSION
def test_binary_on_its_platform_matches_linux64_in_both_fmi_versions(every_platform, fmi_version, platform):
    run = _theta_by_step_master(every_platform[fmi_version], platform)
    assert len(run) == STEPS + 1
    # Both versions are the same plumbing and model behind other entry points, so the same numbers.
    for version, build in every_platform.items():
        assert np.max(np.abs(run - _theta_by_step_master(build, "linux64"))) <= 1e-15, version
    # And the pendulum: scipy's DOP853 at 1e-12 on the same held torque.
    expected = reference(20.0, stop_time=STEPS * STEP_SIZE, step_size=STEP_SIZE)["theta"]
    assert np.max(np.abs(run - expected)) < 1e-9


def _without_compiler(monkeypatch, platform):
    missing = Platform(**{**PLATFORMS[platform].__dict__, "cross_compiler": "no-such-cross-gcc"})
    monkeypatch.setitem(pendulum_fmu.build.PLATFORMS, platform, missing)


@pytest.mark.parametrize("platform", ["win64", "aarch64-linux"])
def test_default_build_skips_a_platform_without_its_compiler_in_one_line(tmp_path, monkeypatch, platform):
    _without_compiler(monkeypatch, platform)
    with pytest.warns(PlatformSkipped) as skipped:
        fmu = build_fmu(tmp_path / "Pendulum.fmu")
    [message] = [str(warning.message) for warning in skipped if platform in str(warning.message)]
    assert message == (f"{platform}: C compiler no-such-cross-gcc not found "
                       f"(apt-get install {PLATFORMS[platform].package}); skipped")
    with zipfile.ZipFile(fmu) as archive:
        folders = {name.split("/")[1] for name in archive.namelist() if name.startswith("binaries/")}
    assert "linux64" in folders and platform not in folders


def test_a_platform_named_explicitly_must_build(tmp_path, monkeypatch):
    _without_compiler(monkeypatch, "aarch64-linux")
    with pytest.raises(BuildError, match="apt-get install gcc-aarch64-linux-gnu"):
        build_fmu(tmp_path / "Pendulum.fmu", platforms=("linux64", "aarch64-linux"))
    assert not (tmp_path / "Pendulum.fmu").exists()


def test_build_command_says_what_it_skipped_in_one_line(tmp_path, monkeypatch, capsys):
    _without_compiler(monkeypatch, "aarch64-linux")
    assert main(["build", "--output", str(tmp_path / "Pendulum.fmu")]) == 0
    assert capsys.readouterr().err.splitlines() == [
        "pendulum-fmu build: aarch64-linux: C compiler no-such-cross-gcc not found "
        "(apt-get install gcc-aarch64-linux-gnu); skipped"]
