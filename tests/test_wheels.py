"""The wheelhouse, `python build_wheels.py`: a wheel for Linux x86_64 and aarch64, macOS and
Windows, each tagged for what its binaries need, each with the same FMUs and the native loop of
its own platform. Run here where something can: the x86_64 wheel in a venv, the aarch64 wheel in
Debian's arm64 Python under qemu (tests/arm64_python.py), the Windows wheel's native loop and FMU
under wine by a C harness (tests/c/cs_loop_harness.c; no Windows Python here). No Mac runs the
macOS wheel: its files are only read.
"""

import json
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from importlib import resources
from pathlib import Path

import numpy as np
import pytest
from elftools.elf.elffile import ELFFile
from elftools.elf.gnuversions import GNUVerNeedSection
from fmpy import read_model_description
from packaging import tags
from packaging.utils import parse_wheel_filename

from benchmarks.builds import build_bare_master
from build_wheels import LEGACY_MANYLINUX, MANYLINUX_GLIBC, WHEELS, WheelhouseError, build_wheels, check_tools, main
from fmu_build import PLATFORMS, WASM
from pendulum_fmu import FMU_FILES, __version__
from pendulum_fmu.cli import main as cli
from pendulum_fmu.oracle._reference import reference
from tests.arm64_python import Arm64Python, Unavailable

ROOT = Path(__file__).resolve().parent.parent
STEPS, STEP_SIZE = 3000, 1e-3  # the tutorial case: 20 N.m, gravity on, 3 s
HARNESS = ROOT / "tests/c/cs_loop_harness.c"
# In a clean environment: no PYTHONPATH pointing back at the checkout.
ENVIRONMENT = {name: value for name, value in os.environ.items() if name != "PYTHONPATH"}
# What the first bytes of each platform's native loop say (ELF e_machine, PE Machine, Mach-O
# universal header's CPU types).
ELF_MACHINES = {"x86_64": 62, "aarch64": 183}
PE_MACHINE_AMD64 = 0x8664
MACHO_CPU_TYPES = {0x01000007: "x86_64", 0x0100000C: "arm64"}
# The DLLs every Windows has: the native loop may import nothing else (no mingw runtime).
WINDOWS_SYSTEM_DLLS = {"kernel32.dll", "msvcrt.dll"}

needs_build = pytest.mark.packaging


@pytest.fixture(scope="session")
def wheelhouse(build_once, checkout_build_lock):
    """{platform of fmu_build.PLATFORMS: its wheel}, built once per session."""
    try:
        check_tools()
    except WheelhouseError as missing:
        pytest.skip(str(missing))

    def built(out: Path) -> list[Path]:
        with checkout_build_lock:  # python -m build --wheel writes build/ and *.egg-info into the checkout
            return build_wheels(out)

    wheels = build_once("wheelhouse", built)
    return {target.platform: wheel for target, wheel in zip(WHEELS, wheels, strict=False)}


def _native_loop(wheel: Path) -> tuple[str, bytes]:
    with zipfile.ZipFile(wheel) as archive:
        [name] = [name for name in archive.namelist() if name.startswith("pendulum_fmu/fmu/_cs_loop")]
        return name, archive.read(name)


def _fmu_binary(wheel: Path, fmu_name: str, folder: str) -> bytes:
    with zipfile.ZipFile(wheel) as archive, zipfile.ZipFile(archive.open(f"pendulum_fmu/data/{fmu_name}")) as fmu:
        [name] = [name for name in fmu.namelist() if name.startswith(f"binaries/{folder}/")]
        return fmu.read(name)


def _glibc_needed(elf: bytes, tmp_path: Path) -> tuple[int, int]:
    """The newest GLIBC_x.y version an ELF library needs, read with pyelftools (build_wheels.py
    asks auditwheel).
    """
    path = tmp_path / "elf"
    path.write_bytes(elf)
    with open(path, "rb") as file:
        versions = [
            tuple(map(int, re.match(r"GLIBC_(\d+)\.(\d+)", auxiliary.name).groups()))
            for section in ELFFile(file).iter_sections()
            if isinstance(section, GNUVerNeedSection)
            for _, auxiliaries in section.iter_versions()
            for auxiliary in auxiliaries
            if auxiliary.name.startswith("GLIBC_")
        ]
    return max(versions, default=(0, 0))


def _manylinux_policies(machine: str) -> list[tuple[int, int]]:
    """The glibc (x, y) of every manylinux_x_y policy auditwheel has for machine: its own table."""
    policies = json.loads((resources.files("auditwheel.policy") / "manylinux-policy.json").read_text())
    return [
        tuple(map(int, re.fullmatch(r"manylinux_(\d+)_(\d+)", policy["name"]).groups()))
        for policy in policies
        if machine in policy["symbol_versions"]
    ]


@needs_build
def test_every_wheel_has_the_same_fmus_and_its_own_native_loop(wheelhouse, tmp_path):
    assert {target.platform for target in WHEELS} == set(PLATFORMS)  # a wheel for every platform
    contents = {}
    for platform, wheel in wheelhouse.items():
        # wheel unpack checks every file against the RECORD's hash and size.
        subprocess.run(
            [sys.executable, "-m", "wheel", "unpack", "--dest", tmp_path / platform, wheel],
            check=True,
            capture_output=True,
        )
        with zipfile.ZipFile(wheel) as archive:
            names = set(archive.namelist())
            contents[platform] = {
                name: archive.read(name)
                for name in names
                if name.startswith("pendulum_fmu/") and "_cs_loop" not in name
            }
        native_loop, _ = _native_loop(wheel)
        assert native_loop == f"pendulum_fmu/fmu/_cs_loop{'.pyd' if platform == 'win64' else '.so'}"
        assert not any(name.startswith(("fmu_src/", "tests/", "dist/")) for name in names)
    first = contents["linux64"]
    assert all(files == first for files in contents.values())  # one build of the FMUs and modules
    for fmi_version, name in FMU_FILES.items():
        description = read_model_description(str(_extracted(wheelhouse["linux64"], name, tmp_path)))
        assert (
            description.generationTool == f"pendulum_fmu {__version__}" and description.fmiVersion == f"{fmi_version}.0"
        )
        with zipfile.ZipFile(_extracted(wheelhouse["linux64"], name, tmp_path)) as fmu:
            folders = {entry.split("/")[1] for entry in fmu.namelist() if entry.startswith("binaries/")}
        assert folders == {
            folder
            for platform in PLATFORMS.values()
            for folder in ((platform.fmi2_folder,) if fmi_version == 2 else platform.fmi3_folders)
        } | ({WASM} if fmi_version == 3 else set())  # the WebAssembly component: FMI 3.0 FMUs alone


def _extracted(wheel: Path, fmu_name: str, tmp_path: Path) -> Path:
    path = tmp_path / fmu_name
    with zipfile.ZipFile(wheel) as archive:
        path.write_bytes(archive.read(f"pendulum_fmu/data/{fmu_name}"))
    return path


@needs_build
def test_each_native_loop_is_built_for_its_wheels_machine(wheelhouse):
    for platform in ("linux64", "aarch64-linux"):
        _, elf = _native_loop(wheelhouse[platform])
        machine = "x86_64" if platform == "linux64" else "aarch64"
        assert elf[:4] == b"\x7fELF" and int.from_bytes(elf[18:20], "little") == ELF_MACHINES[machine]
    _, pe = _native_loop(wheelhouse["win64"])
    header = int.from_bytes(pe[0x3C:0x40], "little")
    assert pe[:2] == b"MZ" and pe[header : header + 4] == b"PE\0\0"
    assert int.from_bytes(pe[header + 4 : header + 6], "little") == PE_MACHINE_AMD64
    _, macho = _native_loop(wheelhouse["darwin64"])
    assert macho[:4] == bytes.fromhex("cafebabe")  # universal, big-endian header
    count = int.from_bytes(macho[4:8], "big")
    cpu_types = {int.from_bytes(macho[8 + 20 * i : 12 + 20 * i], "big") for i in range(count)}
    assert {MACHO_CPU_TYPES.get(cpu) for cpu in cpu_types} == {"x86_64", "arm64"}


def _llvm(tool: str, binary: bytes, tmp_path: Path, *options: str) -> str:
    path = tmp_path / f"binary_{tool}"
    path.write_bytes(binary)
    return subprocess.run([f"{tool}-14", *options, str(path)], capture_output=True, text=True, check=True).stdout


@needs_build
def test_each_native_loop_exports_the_loop_and_needs_only_the_systems_libraries(wheelhouse, tmp_path):
    for platform, wheel in wheelhouse.items():
        _, binary = _native_loop(wheel)
        if platform == "win64":
            table = _llvm("llvm-objdump", binary, tmp_path, "-p")
            exports = re.findall(r"^\s+\d+\s+0x[0-9a-f]+\s+(\w+)$", table.split("Export Table:")[1], re.M)
            imported = {name.lower() for name in re.findall(r"DLL Name: (\S+)", table)}
            assert imported <= WINDOWS_SYSTEM_DLLS, imported
        elif platform == "darwin64":
            symbols = _llvm("llvm-nm", binary, tmp_path, "--defined-only", "--extern-only", "--arch=all")
            exports = re.findall(r" T _(\w+)$", symbols, re.M)
            used = _llvm("llvm-objdump", binary, tmp_path, "--macho", "--dylibs-used", "--arch=all")
            assert set(re.findall(r"^\s+(/\S+) \(", used, re.M)) == {"/usr/lib/libSystem.B.dylib"}, used
        else:
            symbols = _llvm("llvm-nm", binary, tmp_path, "--defined-only", "-D")
            exports = re.findall(r" T (\w+)$", symbols, re.M)
        slices = 2 if platform == "darwin64" else 1
        expected = [
            "cs_loop_interface",
            "cs_loop_run",
            "cs_loop_run_cases",
            "cs_loop_batch_pool_new",
            "cs_loop_batch_pool_free",
            "cs_loop_batch_advance",
            "cs_loop_taylor_interface",
            "cs_loop_taylor_window",
            "cs_loop_euler_interface",
            "cs_loop_euler_steps",
        ] * slices
        assert sorted(exports) == sorted(expected), (platform, exports)


@needs_build
def test_each_tag_is_the_lowest_that_holds_for_every_binary_of_the_wheel(wheelhouse, tmp_path):
    for target in WHEELS:
        wheel = wheelhouse[target.platform]
        name, version, _, wheel_tags = parse_wheel_filename(wheel.name)
        assert (name, str(version)) == ("pendulum-fmu", __version__)
        assert {(tag.interpreter, tag.abi) for tag in wheel_tags} == {("py3", "none")}
        platforms = {tag.platform for tag in wheel_tags}
        if target.system == "linux":
            shown = " ".join(
                subprocess.run(
                    [sys.executable, "-m", "auditwheel", "show", str(wheel)], capture_output=True, text=True, check=True
                ).stdout.split()
            )
            policy = tuple(map(int, re.search(r'platform tag: "manylinux_(\d+)_(\d+)_', shown).groups()))
            fmu_binaries = [
                _fmu_binary(wheel, FMU_FILES[2], target.platform),
                *(_fmu_binary(wheel, FMU_FILES[3], folder) for folder in PLATFORMS[target.platform].fmi3_folders),
            ]
            needed = max(policy, *(_glibc_needed(binary, tmp_path) for binary in fmu_binaries))
            # The lowest policy that admits every binary: the native loop's, the FMUs' for the machine.
            glibc = min(version for version in _manylinux_policies(target.machine) if version >= needed)
            legacy = LEGACY_MANYLINUX.get(glibc)
            assert platforms == {
                f"manylinux_{glibc[0]}_{glibc[1]}_{target.machine}",
                *([f"{legacy}_{target.machine}"] if legacy else []),
            }, (policy, needed)
            # Built by zig for the wheels' glibc floor, the wheel installs on that glibc.
            assert glibc <= tuple(map(int, MANYLINUX_GLIBC.split("."))), glibc
        elif target.system == "macos":
            [platform] = platforms
            # The native loop and every FMU binary for a Mac, x86_64 slices and arm64 ones.
            macho = [
                _native_loop(wheel)[1],
                _fmu_binary(wheel, FMU_FILES[2], target.platform),
                *(_fmu_binary(wheel, FMU_FILES[3], folder) for folder in PLATFORMS[target.platform].fmi3_folders),
            ]
            headers = "".join(
                _llvm("llvm-objdump", binary, tmp_path, "--macho", "--private-headers", "--arch=all")
                for binary in macho
            )
            x86_64 = re.findall(r"cmd LC_VERSION_MIN_MACOSX\n\s+cmdsize \d+\n\s+version (\d+)\.(\d+)", headers)
            arm64 = re.findall(r"cmd LC_BUILD_VERSION\n(?:.*\n){3}\s+minos (\S+)", headers)
            assert len(x86_64) == len(arm64) == 3 and set(arm64) == {"11.0"}, headers
            oldest = max((int(major), int(minor)) for major, minor in x86_64)
            assert platform == f"macosx_{oldest[0]}_{oldest[1]}_universal2"
            # pip installs it on the oldest Intel Mac the slices load on, and on every Apple Silicon one.
            assert platform in tags.mac_platforms(oldest, "x86_64")
            assert platform in tags.mac_platforms((11, 0), "arm64")
        else:
            assert platforms == {"win_amd64"}


def _simulated_theta(csv: Path) -> np.ndarray:
    return np.loadtxt(csv, delimiter=",", skiprows=1, usecols=2)


@pytest.fixture(scope="module")
def x86_64_csv(tmp_path_factory, fmu):
    """`pendulum-fmu simulate --torque 20` of this checkout, here (x86-64)."""
    folder = tmp_path_factory.mktemp("x86_64")
    assert cli(["simulate", "--torque", "20", "--fmu", str(fmu), "--output", str(folder / "out.csv")]) == 0
    return folder / "out.csv"


def _check_simulated(csv: Path, x86_64_csv: Path) -> None:
    # The same FMU binaries' sources and loop: bit for bit x86-64's CSV, and the pendulum itself.
    assert csv.read_bytes() == x86_64_csv.read_bytes()
    expected = reference(20.0, stop_time=STEPS * STEP_SIZE, step_size=STEP_SIZE)["theta"]
    assert np.max(np.abs(_simulated_theta(csv) - expected)) < 1e-9


@needs_build
def test_x86_64_wheel_installs_and_simulates_in_a_venv(wheelhouse, x86_64_csv, tmp_path):
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", venv], check=True)
    [site_packages] = venv.glob("lib/python*/site-packages")
    (site_packages / "dependencies_from_the_test_environment.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    # pip checks the manylinux tag against this machine's glibc.
    subprocess.run(
        [
            venv / "bin/python",
            "-m",
            "pip",
            "install",
            "--no-deps",
            "--ignore-installed",
            "--no-cache-dir",
            wheelhouse["linux64"],
        ],
        check=True,
        capture_output=True,
        env=ENVIRONMENT,
    )
    loaded = subprocess.run(
        [
            venv / "bin/python",
            "-c",
            "from pendulum_fmu.fmu import _native_loop as cs_loop; print(cs_loop.__file__, cs_loop.available())",
        ],
        check=True,
        cwd=tmp_path,
        capture_output=True,
        text=True,
        env=ENVIRONMENT,
    )
    assert loaded.stdout.split() == [str(site_packages / "pendulum_fmu/fmu/_native_loop.py"), "True"]
    subprocess.run(
        [venv / "bin/pendulum-fmu", "simulate", "--torque", "20", "--output", "out.csv"],
        check=True,
        cwd=tmp_path,
        capture_output=True,
        env=ENVIRONMENT,
    )
    _check_simulated(tmp_path / "out.csv", x86_64_csv)


@needs_build
@pytest.mark.qemu
def test_aarch64_wheel_installs_and_simulates_on_arm64_python_under_qemu(wheelhouse, x86_64_csv, tmp_path):
    try:
        arm64 = Arm64Python()
    except Unavailable as missing:
        pytest.skip(str(missing))
    site = arm64.install([wheelhouse["aarch64-linux"]], tmp_path / "site")  # pip there judges the tag
    loaded = arm64.run(
        ["-c", "from pendulum_fmu.fmu import _native_loop as cs_loop; print(cs_loop.available())"],
        site=site,
        cwd=tmp_path,
    )
    assert loaded.stdout.split()[-1:] == ["True"], loaded.stderr
    ran = arm64.run(
        [site / "bin/pendulum-fmu", "simulate", "--torque", "20", "--output", "out.csv"], site=site, cwd=tmp_path
    )
    assert ran.returncode == 0, ran.stderr
    _check_simulated(tmp_path / "out.csv", x86_64_csv)


def _theta_by_harness(platform: str, wheel: Path, folder: Path) -> np.ndarray:
    """Theta at every point from the wheel's native loop stepping the wheel's FMI 2.0 binary for
    platform, both loaded by tests/c/cs_loop_harness.c built for platform (wine runs win64's).
    """
    folder.mkdir()
    name, loop = _native_loop(wheel)
    (folder / Path(name).name).write_bytes(loop)
    library = folder / f"Pendulum{PLATFORMS[platform].suffix}"
    library.write_bytes(_fmu_binary(wheel, FMU_FILES[2], platform))
    guid = read_model_description(str(_extracted(wheel, FMU_FILES[2], folder))).guid
    harness = build_bare_master(folder, HARNESS, platform)
    environment = {**os.environ, "WINEPREFIX": str(folder / "wineprefix"), "WINEDEBUG": "-all"}
    subprocess.run(
        [
            *(["wine"] if platform == "win64" else []),
            harness,
            folder / Path(name).name,
            library,
            guid,
            str(STEPS),
            repr(STEP_SIZE),
            "0",
            folder / "theta.txt",
        ],
        check=True,
        capture_output=True,
        env=environment,
        timeout=300,
    )
    return np.loadtxt(folder / "theta.txt")


@needs_build
@pytest.mark.wine
@pytest.mark.skipif(shutil.which("wine") is None, reason="needs wine (apt-get install wine64)")
def test_windows_wheels_native_loop_steps_its_fmu_binary_under_wine_as_on_linux(wheelhouse, x86_64_csv, tmp_path):
    windows = _theta_by_harness("win64", wheelhouse["win64"], tmp_path / "win64")
    linux = _theta_by_harness("linux64", wheelhouse["linux64"], tmp_path / "linux64")
    assert len(windows) == STEPS + 1
    # mingw's and gcc's builds of the same sources, without FMA contraction: the same bits, and
    # those of the Python package's run (the native loop through ctypes) here.
    assert np.array_equal(windows, linux), np.max(np.abs(windows - linux))
    assert np.array_equal(linux, _simulated_theta(x86_64_csv))


def test_a_missing_tool_stops_the_wheelhouse_in_one_line_naming_its_package(monkeypatch, capsys, tmp_path):
    monkeypatch.setattr("build_wheels.TOOLS", {"no_such_packaging_tool": "pip install no-such-packaging-tool"})
    assert main(["--output-dir", str(tmp_path / "wheelhouse")]) == 2
    assert capsys.readouterr().err.splitlines() == [
        "build_wheels.py: building the wheels needs the no_such_packaging_tool package "
        "(pip install no-such-packaging-tool)"
    ]
    assert not (tmp_path / "wheelhouse").exists()
