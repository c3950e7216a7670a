"""The win64 binary: cross-compiled with mingw-w64, run under wine by the same bare C master
that runs the linux64 binary, with the same numbers."""

import os
import re
import shutil
import subprocess
import zipfile

import numpy as np
import pytest
from fmpy import read_model_description

from benchmarks.builds import build_step_master
import pendulum_fmu.build
from pendulum_fmu.build import MINGW_COMPILER, build_fmu

needs_mingw_and_wine = pytest.mark.skipif(
    shutil.which(MINGW_COMPILER) is None or shutil.which("wine") is None,
    reason="needs Debian's gcc-mingw-w64-x86-64 and wine (.ci/run installs them)")

STEPS, STEP_SIZE = 3000, 1e-3  # the tutorial case: 20 N.m, gravity on, 3 s


@pytest.fixture(scope="module")
def both_platforms(tmp_path_factory):
    work = tmp_path_factory.mktemp("win64")
    fmu = build_fmu(work / "Pendulum.fmu", platforms=("linux64", "win64"))
    with zipfile.ZipFile(fmu) as archive:
        archive.extractall(work / "unzipped")
    return work, read_model_description(str(fmu)).guid


def _exports_of_dll(dll):
    table = subprocess.run(["x86_64-w64-mingw32-objdump", "-p", str(dll)], capture_output=True,
                           text=True, check=True).stdout
    names = table.split("[Ordinal/Name Pointer] Table", 1)[1].split("\n\n", 1)[0]
    return set(re.findall(r"\]\s+(\w+)", names))


def _exports_of_so(library):
    symbols = subprocess.run(["nm", "-D", "--defined-only", str(library)], capture_output=True,
                             text=True, check=True).stdout
    return {line.split()[-1] for line in symbols.splitlines()}


@needs_mingw_and_wine
def test_dll_exports_exactly_the_fmi2_functions_of_the_linux_binary(both_platforms):
    work, _ = both_platforms
    exports = _exports_of_dll(work / "unzipped/binaries/win64/Pendulum.dll")
    assert exports == _exports_of_so(work / "unzipped/binaries/linux64/Pendulum.so")
    assert all(name.startswith("fmi2") for name in exports) and "fmi2DoStep" in exports


@needs_mingw_and_wine
def test_dll_under_wine_matches_linux64(both_platforms):
    work, guid = both_platforms
    unzipped = work / "unzipped" / "binaries"
    environment = {**os.environ, "WINEPREFIX": str(work / "wineprefix"), "WINEDEBUG": "-all"}
    runs = {}
    for platform, library, runner in (("linux64", unzipped / "linux64/Pendulum.so", []),
                                      ("win64", unzipped / "win64/Pendulum.dll", ["wine"])):
        master = build_step_master(work, platform)
        trajectory = work / f"theta_{platform}.txt"
        subprocess.run([*runner, str(master), str(library), guid, str(STEPS), repr(STEP_SIZE), "0",
                        str(trajectory)], check=True, capture_output=True, env=environment, timeout=300)
        runs[platform] = np.loadtxt(trajectory)
    assert len(runs["win64"]) == STEPS + 1
    assert np.max(np.abs(runs["win64"] - runs["linux64"])) < 1e-12
    assert abs(runs["linux64"][-1] - 0.0814310964678) < 1e-12  # theta(3 s), as in the tutorial case


def test_without_mingw_the_build_says_so_and_still_builds_linux64(tmp_path, monkeypatch):
    monkeypatch.setattr(pendulum_fmu.build, "MINGW_COMPILER", "no-such-mingw-gcc")
    with pytest.warns(UserWarning, match="win64 left out: no-such-mingw-gcc not found: install Debian's gcc-mingw-w64"):
        fmu = build_fmu(tmp_path / "Pendulum.fmu", platforms=("linux64", "win64"))
    with zipfile.ZipFile(fmu) as archive:
        binaries = [name for name in archive.namelist() if name.startswith("binaries/")]
    assert binaries == ["binaries/linux64/Pendulum.so"]
