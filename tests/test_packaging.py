"""The package as a user installs it: the wheel, and the sdist built on the spot, each into its own
fresh virtual environment, used from an empty folder with no source tree in sight.

`python -m build` makes the sdist and builds the wheel from it, so the wheel also shows that the
sdist holds everything a rebuild needs. The fresh environments get their third-party packages
(numpy, fmpy, dask, ...) from this interpreter's site-packages through a .pth line instead of a
download, and `pip check` confirms those satisfy the wheel's requirements; pendulum_fmu itself
is only what the artefact installs.
"""

import csv
import importlib.metadata
import io
import os
import re
import subprocess
import sys
import sysconfig
import tarfile
import zipfile
from pathlib import Path

import fmpy
import lxml.etree
import numpy as np
import pytest
from fmpy import read_model_description
from packaging.requirements import Requirement
from readme_figures import measured_figures

from pendulum_fmu import CONTROLLER_FMU_FILE, FMU_FILES, __version__
from pendulum_fmu.oracle._reference import reference
from pendulum_fmu.ssp._closed_loop import sampled_loop_reference

pytestmark = pytest.mark.packaging

ROOT = Path(__file__).resolve().parent.parent
# In a clean environment: no PYTHONPATH pointing back at the checkout.
ENVIRONMENT = {name: value for name, value in os.environ.items() if name != "PYTHONPATH"}


def _run(command, cwd=None, check=True):
    result = subprocess.run(
        [str(part) for part in command], cwd=cwd, env=ENVIRONMENT, capture_output=True, text=True, timeout=600
    )
    if check and result.returncode != 0:
        raise AssertionError(
            f"{' '.join(map(str, command))} exited {result.returncode}:\n{result.stdout}\n{result.stderr}"
        )
    return result


def _built_artefacts(out: Path) -> dict[str, Path]:
    _run([sys.executable, "-m", "build", "--outdir", out, ROOT])
    [wheel], [sdist] = out.glob("*.whl"), out.glob("*.tar.gz")
    return {"wheel": wheel, "sdist": sdist}


@pytest.fixture(scope="session")
def artefacts(build_once, checkout_build_lock):
    """{'wheel': path, 'sdist': path}, built from this checkout once per session."""

    def built(out: Path) -> dict[str, Path]:
        with checkout_build_lock:  # the sdist's egg_info writes into the checkout
            return _built_artefacts(out)

    return build_once("dist", built)


def _files_under(folder: Path) -> set[Path]:
    return {p for p in folder.rglob("*") if "__pycache__" not in p.parts}


@pytest.fixture(scope="session", params=["wheel", "sdist"])
def installed(request, artefacts, build_once):
    """(venv, its site-packages) with the artefact installed and nothing of the checkout, made
    once per session.
    """
    return build_once(f"venv_{request.param}", lambda venv: _venv_with(artefacts[request.param], venv))


def _venv_with(artefact: Path, venv: Path) -> tuple[Path, Path]:
    _run([sys.executable, "-m", "venv", venv])
    [site_packages] = venv.glob("lib/python*/site-packages")
    (site_packages / "dependencies_from_the_test_environment.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    # The sdist builds its wheel (and the FMU in it) here, in pip's isolated build environment.
    # --ignore-installed: the test environment on the .pth path may hold this package itself
    # (a non-editable install), which pip would otherwise take as already satisfied.
    _run(
        [
            venv / "bin/python",
            "-m",
            "pip",
            "install",
            "--no-deps",
            "--ignore-installed",
            "--no-cache-dir",
            artefact,
        ]
    )
    _run([venv / "bin/python", "-m", "pip", "check"])
    return venv, site_packages


def _csv_columns(path: Path) -> dict[str, np.ndarray]:
    with open(path, newline="") as file:
        rows = list(csv.reader(file))
    return {name.strip('"'): np.array([float(row[i]) for row in rows[1:]]) for i, name in enumerate(rows[0])}


def test_wheel_carries_the_fmu_for_every_platform_built(artefacts, tmp_path):
    # The native loop is no CPython module: one wheel for every Python 3 on this platform.
    platform = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    assert artefacts["wheel"].name == f"pendulum_fmu-{__version__}-py3-none-{platform}.whl"
    with zipfile.ZipFile(artefacts["wheel"]) as wheel:
        names = wheel.namelist()
        assert "pendulum_fmu/data/Pendulum.fmu" in names
        assert not any(name.startswith(("fmu_src/", "fmu_build/", "tests/", "dist/")) for name in names)
        # The build is the repository's (fmu_build/), not the package's; cli/build.py is the command.
        assert "pendulum_fmu/build.py" not in names and "pendulum_fmu/fmi3.py" not in names
        # The MIT text pyproject names travels with the wheel (license-files) and the sdist.
        licence = next(name for name in names if name.endswith(".dist-info/licenses/LICENSE"))
        assert wheel.read(licence) == (ROOT / "LICENSE").read_bytes()
        fmus = {
            version: zipfile.ZipFile(io.BytesIO(wheel.read(f"pendulum_fmu/data/{name}")))
            for version, name in FMU_FILES.items()
        }
        controller = zipfile.ZipFile(io.BytesIO(wheel.read(f"pendulum_fmu/data/{CONTROLLER_FMU_FILE}")))
    with tarfile.open(artefacts["sdist"]) as sdist:
        [top] = {name.split("/")[0] for name in sdist.getnames()}
        assert sdist.extractfile(f"{top}/LICENSE").read() == (ROOT / "LICENSE").read_bytes()
    # Every platform the docs promise, from this source build (zig, a build requirement, makes macOS's).
    assert {name for name in fmus[2].namelist() if name.startswith("binaries/")} == {
        "binaries/linux64/Pendulum.so",
        "binaries/win64/Pendulum.dll",
        "binaries/aarch64-linux/Pendulum.so",
        "binaries/darwin64/Pendulum.dylib",
    }
    # The closed loop's controller for the same platforms (export-ssp from the wheel).
    assert {name for name in controller.namelist() if name.startswith("binaries/")} == {
        f"binaries/{folder}/PIDController.{suffix}"
        for folder, suffix in (("linux64", "so"), ("win64", "dll"), ("aarch64-linux", "so"), ("darwin64", "dylib"))
    }
    assert {name for name in fmus[3].namelist() if name.startswith("binaries/")} == {
        f"binaries/{folder}/Pendulum.{suffix}"
        for folder, suffix in (
            ("x86_64-linux", "so"),
            ("x86_64-windows", "dll"),
            ("aarch64-linux", "so"),
            ("x86_64-darwin", "dylib"),
            ("aarch64-darwin", "dylib"),
            ("wasm32-wasip2", "wasm"),
        )
    }
    # darwin64 is one universal binary of both Mac slices, as LLVM reads it.
    universal = tmp_path / "Pendulum.dylib"
    universal.write_bytes(fmus[2].read("binaries/darwin64/Pendulum.dylib"))
    headers = _run(["llvm-objdump-14", "--macho", "--universal-headers", universal]).stdout
    assert "nfat_arch 2" in headers and "CPU_TYPE_X86_64" in headers and "CPU_TYPE_ARM64" in headers


def test_installed_package_runs_from_an_empty_folder(installed, tmp_path):
    venv, site_packages = installed
    package = site_packages / "pendulum_fmu"
    before = _files_under(package)
    python, cli = venv / "bin/python", venv / "bin/pendulum-fmu"

    assert _run([cli, "--version"], cwd=tmp_path).stdout.strip() == f"pendulum-fmu {__version__}"
    fmu = Path(
        _run([python, "-c", "import pendulum_fmu; print(pendulum_fmu.default_fmu())"], cwd=tmp_path).stdout.strip()
    )
    assert fmu == package / "data" / "Pendulum.fmu"
    assert read_model_description(str(fmu)).generationTool == f"pendulum_fmu {__version__}"
    _run(
        [python, "-c", "from pendulum_fmu.fmu import _native_loop as cs_loop; assert cs_loop.available()"], cwd=tmp_path
    )

    expected = reference(20.0, stop_time=3.0, step_size=1e-3)
    _run([cli, "simulate", "--torque", "20", "--output", "simulated.csv"], cwd=tmp_path)
    simulated = _csv_columns(tmp_path / "simulated.csv")
    assert np.max(np.abs(simulated["theta"] - expected["theta"])) < 1e-9

    _run(
        [
            python,
            "-m",
            "fmpy",
            "simulate",
            fmu,
            "--start-values",
            "torque",
            "20",
            "--stop-time",
            "3",
            "--step-size",
            "1e-3",
            "--output-interval",
            "1e-3",
            "--output-file",
            "fmpy.csv",
        ],
        cwd=tmp_path,
    )
    by_fmpy = _csv_columns(tmp_path / "fmpy.csv")
    assert np.allclose(by_fmpy["time"], expected["time"], rtol=0, atol=1e-12)
    assert np.max(np.abs(by_fmpy["theta"] - expected["theta"])) < 1e-9

    _run([cli, "compare", "--torque", "20", "--tools", "fmu,reference", "--output-dir", "compared"], cwd=tmp_path)
    _run(
        [cli, "sweep", "--torque", "5", "10", "--stop-time", "0.5", "--workers", "1", "--output-dir", "swept"],
        cwd=tmp_path,
    )
    assert (tmp_path / "swept/sweep.png").is_file() and (tmp_path / "compared/differences.csv").is_file()
    assert any((tmp_path / "swept/cases").glob("*.parquet"))

    # The user's way to the FMU: export, from the installed package, into the current folder.
    exported = _run([cli, "export"], cwd=tmp_path).stdout
    assert (tmp_path / "Pendulum.fmu").read_bytes() == fmu.read_bytes()
    assert exported == "wrote Pendulum.fmu (binaries for aarch64-linux, darwin64, linux64, win64)\n"
    assert _run([cli, "export", "--fmi-version", "3"], cwd=tmp_path).stdout == (
        "wrote Pendulum-fmi3.fmu (binaries for aarch64-darwin, aarch64-linux, wasm32-wasip2, x86_64-darwin, "
        "x86_64-linux, x86_64-windows)\n"
    )
    refused = _run([cli, "export"], cwd=tmp_path, check=False)
    assert refused.returncode == 2 and refused.stderr.startswith("pendulum-fmu export: error: Pendulum.fmu exists")
    _closed_loop_ssp_from_the_installed_package(python, cli, tmp_path / "ssp")

    # Building is the repository's (python build_fmu.py): an installed package has no build command.
    assert "invalid choice: 'build'" in _run([cli, "build"], cwd=tmp_path, check=False).stderr

    assert _files_under(package) == before  # nothing written into site-packages


SSP_SCHEMAS = Path(fmpy.__file__).parent / "ssp" / "schema"


def _closed_loop_ssp_from_the_installed_package(python, cli, folder):
    """export-ssp in an empty folder: an SSP that validates and that fmpy.ssp runs as its coupling's reference."""
    folder.mkdir()
    assert _run([cli, "export-ssp", "--stop-time", "2"], cwd=folder).stdout == "wrote ClosedLoop.ssp\n"
    with zipfile.ZipFile(folder / "ClosedLoop.ssp") as archive:
        for name, schema in (
            ("SystemStructure.ssd", "SystemStructureDescription.xsd"),
            ("resources/controller.ssv", "SystemStructureParameterValues.xsd"),
            ("resources/pendulum.ssv", "SystemStructureParameterValues.xsd"),
        ):
            validator = lxml.etree.XMLSchema(file=str(SSP_SCHEMAS / schema))
            assert validator.validate(lxml.etree.fromstring(archive.read(name))), (name, validator.error_log)
    _run(
        [
            python,
            "-c",
            "from fmpy.ssp.simulation import simulate_ssp; from fmpy.util import write_csv; "
            "write_csv('ssp.csv', simulate_ssp('ClosedLoop.ssp', stop_time=2.0, step_size=1e-3))",
        ],
        cwd=folder,
    )
    result = _csv_columns(folder / "ssp.csv")
    # fmpy.ssp applies no bound set (the controller's own setpoint 0.5), holds torque 0 over the
    # first step and labels each row with the start of the step whose end it holds; to 2 s its
    # summed time takes one step more (tests/test_ssp.py).
    expected = sampled_loop_reference(2.001, 1e-3, coupling="jacobi-first-exchange-missing")
    assert len(result["time"]) == 2001
    assert np.max(np.abs(result["pendulum.theta"] - expected["theta"][1:])) < 1e-12


# The set-up's sizes the install page states (benchmarks.install's measured block) hold for
# this build within this fraction: they drift with every build change and dependency release.
SIZE_TOLERANCE = 0.10
INSTALL_BENCHMARK = ".venv/bin/python -m benchmarks.install"


def _bytes_under(folder: Path) -> int:
    return sum(path.stat().st_size for path in folder.rglob("*") if path.is_file() and not path.is_symlink())


def _dependency_closure(name: str, extras=("",), found=None) -> dict:
    """{normalized name: distribution} of name and everything it requires, installed here."""
    found = {} if found is None else found
    key = re.sub(r"[-_.]+", "-", name).lower()
    if key not in found:
        found[key] = distribution = importlib.metadata.distribution(name)
        for text in distribution.requires or []:
            requirement = Requirement(text)
            if requirement.marker is None or any(requirement.marker.evaluate({"extra": extra}) for extra in extras):
                _dependency_closure(requirement.name, ("", *requirement.extras), found)
    return found


def _installed_bytes(distribution) -> int:
    return sum(
        path.stat().st_size for path in map(distribution.locate_file, distribution.files or []) if path.is_file()
    )


def test_the_documented_sizes_are_this_build_s(artefacts, installed):
    """The wheel, the installed package and its environment are the sizes the install page states.

    Each within SIZE_TOLERANCE. The environment `pip install` of the wheel makes is measured as
    the fresh venv (pip) plus the package plus every distribution the wheel requires, as
    installed in the test environment (which the fresh venv borrows through its .pth line).
    """
    venv, site_packages = installed
    stated = measured_figures(INSTALL_BENCHMARK)
    dependencies = {key: dist for key, dist in _dependency_closure("pendulum-fmu").items() if key != "pendulum-fmu"}
    package = _bytes_under(site_packages / "pendulum_fmu")
    measured = {
        "wheel_kb": artefacts["wheel"].stat().st_size / 1e3,
        "package_kb": package / 1e3,
        "environment_mb": (_bytes_under(venv) + sum(map(_installed_bytes, dependencies.values()))) / 1e6,
    }
    drifted = {
        name: f"stated {stated[name]}, measured {value:.0f}"
        for name, value in measured.items()
        if abs(value - float(stated[name])) > SIZE_TOLERANCE * value
    }
    assert not drifted, f"docs/install.md's sizes drifted (rerun `{INSTALL_BENCHMARK}`): {drifted}"
