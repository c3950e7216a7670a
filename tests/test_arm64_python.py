"""The arm64 Python of tests/arm64_python.py (Debian's python3.11 under qemu-aarch64): it is an
aarch64 interpreter, and it runs this checkout's package as a wheel lays it out (the Python
modules, data/Pendulum.fmu; no sources beside it) with the x86-64 numbers.
"""

import shutil
import tomllib
import zipfile
from pathlib import Path

import numpy as np
import pytest

from pendulum_fmu.cli import main
from pendulum_fmu.oracle._reference import reference
from tests.arm64_python import ROOT, Arm64Python, Unavailable

pytestmark = [pytest.mark.packaging, pytest.mark.qemu]

ELF_MACHINE_AARCH64 = 183  # e_machine in the ELF header


@pytest.fixture(scope="module")
def arm64():
    try:
        return Arm64Python()
    except Unavailable as missing:
        pytest.skip(str(missing))


def test_the_interpreter_is_an_aarch64_elf_that_says_so(arm64, tmp_path):
    header = arm64.python.read_bytes()[:20]
    assert header[:4] == b"\x7fELF" and int.from_bytes(header[18:20], "little") == ELF_MACHINE_AARCH64
    said = arm64.run(["-c", "import platform; print(platform.machine(), *platform.libc_ver())"], cwd=tmp_path)
    assert said.stdout.split() == ["aarch64", "glibc", "2.36"], said.stderr


def _dependencies() -> list[str]:
    listed = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"]
    return [requirement.split("#")[0].strip() for requirement in listed]


def _theta(csv: Path) -> np.ndarray:
    return np.loadtxt(csv, delimiter=",", skiprows=1, usecols=2)


def test_the_checkout_package_simulates_on_arm64_as_on_x86_64(arm64, fmu, tmp_path, monkeypatch):
    with zipfile.ZipFile(fmu) as archive:
        if "binaries/aarch64-linux/Pendulum.so" not in archive.namelist():
            pytest.skip("the FMU has no aarch64-linux binary (apt-get install gcc-aarch64-linux-gnu)")
    site = arm64.install(_dependencies(), tmp_path / "site")
    package = site / "pendulum_fmu"
    shutil.copytree(ROOT / "pendulum_fmu", package, ignore=shutil.ignore_patterns("__pycache__", "_cs_loop*"))
    (package / "data").mkdir()
    shutil.copy(fmu, package / "data/Pendulum.fmu")

    ran = arm64.run(
        [
            "-c",
            "import sys; sys.argv[0] = 'pendulum-fmu'; from pendulum_fmu._entry import run; run()",
            "simulate",
            "--torque",
            "20",
            "--output",
            "arm64.csv",
        ],
        site=site,
        cwd=tmp_path,
    )
    assert ran.returncode == 0, ran.stderr
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", "--torque", "20", "--fmu", str(fmu), "--output", "x86_64.csv"]) == 0

    # Both platforms' binaries come from the same sources with gcc -std=c99 -O2 (no contraction
    # into fused multiply-adds in ISO C mode): the same operations, so the same bits.
    assert (tmp_path / "arm64.csv").read_bytes() == (tmp_path / "x86_64.csv").read_bytes()
    expected = reference(20.0, stop_time=3.0, step_size=1e-3)["theta"]
    assert np.max(np.abs(_theta(tmp_path / "arm64.csv") - expected)) < 1e-9
