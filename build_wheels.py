"""Write every wheel into wheelhouse/: manylinux x86_64 and aarch64, macOS universal2 (x86_64 and
arm64), Windows amd64, all from this Linux machine.

    python build_wheels.py [--output-dir wheelhouse]

One build makes the FMUs (FMI 2.0 and 3.0, a binary for every platform) and every wheel carries
them; each wheel adds the native co-simulation loop built for its own platform
(fmu_build.compile_native_loop). Every Linux binary, the FMUs' and the native loops, is
built by zig for glibc MANYLINUX_GLIBC (fmu_build's linux_glibc), so that the Linux
wheels load on that glibc and every later one. The steps, with the wheel package's own tools:
1. `python -m build --wheel` builds this machine's wheel, the FMUs inside;
2. per platform, `wheel unpack`, its native loop in place of this machine's, `wheel pack`
   (which writes the RECORD), `wheel tags --platform-tag`;
3. the tag is the lowest that holds for every binary the wheel loads on that platform: on Linux
   the manylinux policy `auditwheel show` finds for the native loop and the FMUs' binaries for
   the wheel's machine together (shown to it beside the loop, since it does not look inside an
   .fmu); on macOS the newest minimum macOS of the x86_64 slices (the arm64 slices' 11.0 is
   every Apple Silicon Mac's).
Every wheel is the same bytes from one commit (fmu_build/release_files.py): its entries dated by
$SOURCE_DATE_EPOCH, the commit's time unless given, which `python -m build`, `wheel pack` and
`wheel tags` all read, and its files given fixed permissions before `wheel pack`.
Each wheel is written to a temporary beside its target and renamed into place; a wheel of the
same name from an earlier run is replaced. A missing tool stops the command before anything is
built, with one line naming what installs it.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import re
import shutil
import subprocess
import sys
import tempfile
import zipfile
from dataclasses import dataclass
from pathlib import Path

from fmu_build import PLATFORMS, BuildError, check_toolchain, compile_native_loop
from fmu_build.build_record import source_date_epoch
from fmu_build.release_files import normalize_modes
from pendulum_fmu import CONTROLLER_FMU_FILE, FMU_FILES
from pendulum_fmu._atomic_files import replacing_path

ROOT = Path(__file__).resolve().parent
OBJDUMP = "llvm-objdump-14"
# The oldest glibc the Linux wheels load on: manylinux2014's, the first glibc for ARM64 (its
# aarch64 port began with 2.17) and auditwheel's oldest aarch64 policy.
MANYLINUX_GLIBC = "2.17"
# The tags pip before 20.3 knows for the first manylinux_x_y policies.
LEGACY_MANYLINUX = {(2, 5): "manylinux1", (2, 12): "manylinux2010", (2, 17): "manylinux2014"}
# Every FMU a wheel carries in pendulum_fmu/data/, by its FMI version: the pendulum's and the
# closed loop's controller (setup.py builds them all).
PACKAGED_FMUS = {**{name: version for version, name in FMU_FILES.items()}, CONTROLLER_FMU_FILE: 2}
# Python packages this command runs, and what installs each.
TOOLS = {"build": "pip install build", "wheel": "pip install wheel", "auditwheel": "pip install auditwheel"}


@dataclass(frozen=True)
class WheelPlatform:
    """A wheel: the platform (a key of fmu_build.PLATFORMS) whose native loop and FMU
    binaries it loads.
    """

    platform: str
    system: str  # linux, macos or windows
    machine: str  # the platform tag's machine: x86_64, aarch64, universal2, amd64

    @property
    def native_loop(self) -> str:
        """The native loop's file name in the wheel."""
        return "_cs_loop.pyd" if self.system == "windows" else "_cs_loop.so"


WHEELS = (
    WheelPlatform("linux64", "linux", "x86_64"),
    WheelPlatform("aarch64-linux", "linux", "aarch64"),
    WheelPlatform("darwin64", "macos", "universal2"),
    WheelPlatform("win64", "windows", "amd64"),
)


class WheelhouseError(RuntimeError):
    """A wheel could not be built; the message says why (a missing tool in one line)."""


def _run(command: list, what: str) -> str:
    command = [str(part) for part in command]
    result = subprocess.run(command, capture_output=True, text=True, env=_build_environment())
    if result.returncode != 0:
        raise WheelhouseError(f"{what} failed: {' '.join(command)}\n{result.stdout}{result.stderr}")
    return result.stdout


def check_tools() -> None:
    """WheelhouseError naming the package that installs the first missing tool."""
    for module, hint in TOOLS.items():
        if importlib.util.find_spec(module) is None:
            raise WheelhouseError(f"building the wheels needs the {module} package ({hint})")
    if shutil.which(OBJDUMP) is None:
        raise WheelhouseError(f"building the wheels needs {OBJDUMP} (apt-get install llvm-14)")
    for wheel in WHEELS:
        try:
            for fmi_version in FMU_FILES:
                check_toolchain(PLATFORMS[wheel.platform], fmi_version, MANYLINUX_GLIBC)
        except BuildError as missing:
            raise WheelhouseError(f"the {wheel.system} {wheel.machine} wheel: {missing}") from None


def _build_environment() -> dict:
    """The environment with SOURCE_DATE_EPOCH set (the commit's time unless given), which dates
    the entries of every wheel written, and with the ziglang package's zig on PATH, so that the
    isolated build environment of `python -m build` compiles the macOS binaries of the FMUs too.
    """
    environment = {**os.environ, "SOURCE_DATE_EPOCH": str(source_date_epoch())}
    spec = importlib.util.find_spec("ziglang")
    if spec is not None and spec.origin is not None:
        environment["PATH"] = os.pathsep.join([str(Path(spec.origin).parent), os.environ["PATH"]])
    return environment


def _extract_fmu_binaries(wheel: Path, out_dir: Path) -> None:
    """The binaries of the wheel's FMUs into out_dir/<FMU file>/binaries/<folder>/; WheelhouseError
    unless they are there for every platform of fmu_build.PLATFORMS.
    """
    with zipfile.ZipFile(wheel) as archive:
        for name, fmi_version in PACKAGED_FMUS.items():
            with zipfile.ZipFile(archive.open(f"pendulum_fmu/data/{name}")) as fmu:
                binaries = [
                    entry for entry in fmu.namelist() if entry.startswith("binaries/") and not entry.endswith("/")
                ]
                fmu.extractall(out_dir / name, binaries)
            wanted = {folder for platform in PLATFORMS.values() for folder in _fmu_folders(platform, fmi_version)}
            missing = wanted - {entry.split("/")[1] for entry in binaries}
            if missing:
                raise WheelhouseError(f"{name} in the built wheel has no binaries for {', '.join(sorted(missing))}")


def _fmu_folders(platform, fmi_version: int) -> tuple[str, ...]:
    return (platform.fmi2_folder,) if fmi_version == 2 else platform.fmi3_folders


def fmu_binaries_for(platform: str, extracted: Path) -> list[Path]:
    """The binaries of every packaged FMU that a wheel for platform loads, from _extract_fmu_binaries."""
    return sorted(
        binary
        for name, fmi_version in PACKAGED_FMUS.items()
        for folder in _fmu_folders(PLATFORMS[platform], fmi_version)
        for binary in (extracted / name / "binaries" / folder).iterdir()
    )


def _objdump(binary: Path, *options: str) -> str:
    return _run([OBJDUMP, *options, binary], f"reading {binary.name}")


def macos_minimums(binary: Path) -> dict[str, tuple[int, int]]:
    """{slice's architecture: its minimum macOS} of a Mach-O, thin or universal."""
    minimums = {}
    for header in _objdump(binary, "--macho", "--private-headers", "--arch=all").split("Mach header")[1:]:
        architecture = re.search(r"MH_MAGIC_64\s+(\w+)", header)[1].lower()
        version = re.search(r"LC_VERSION_MIN_MACOSX.*?version (\d+)\.(\d+)|minos (\d+)\.(\d+)", header, re.S)
        minimums[architecture] = tuple(int(number) for number in version.groups() if number is not None)
    return minimums


def manylinux_tag(wheel: Path, machine: str, binaries: list[Path]) -> str:
    """The lowest manylinux policy auditwheel finds the wheel's own libraries and the FMU binaries
    for its machine consistent with, with its legacy alias where it has one. auditwheel reads
    every library a wheel's RECORD lists but none inside an .fmu: it is shown the wheel packed
    again with those binaries added.
    """
    with tempfile.TemporaryDirectory(prefix="pendulum_fmu_auditwheel_") as tmp:
        _run([sys.executable, "-m", "wheel", "unpack", "--dest", Path(tmp, "unpacked"), wheel], "wheel unpack")
        [tree] = Path(tmp, "unpacked").iterdir()
        for index, binary in enumerate(binaries):
            Path(tree, "fmu_binaries", str(index)).mkdir(parents=True)
            shutil.copyfile(binary, Path(tree, "fmu_binaries", str(index), binary.name))
        _run([sys.executable, "-m", "wheel", "pack", "--dest-dir", tmp, tree], "wheel pack")
        [shown_wheel] = Path(tmp).glob("*.whl")
        shown = " ".join(_run([sys.executable, "-m", "auditwheel", "show", shown_wheel], "auditwheel show").split())
    policy = re.search(r'platform tag: "manylinux_(\d+)_(\d+)_', shown)
    if policy is None:
        raise WheelhouseError(
            f"auditwheel finds {wheel.name} with its FMU binaries consistent with no manylinux tag: {shown}"
        )
    glibc = (int(policy[1]), int(policy[2]))
    tag = f"manylinux_{glibc[0]}_{glibc[1]}_{machine}"
    return f"{tag}.{LEGACY_MANYLINUX[glibc]}_{machine}" if glibc in LEGACY_MANYLINUX else tag


def macos_tag(binaries: list[Path]) -> str:
    """macosx_<the oldest macOS every x86_64 slice loads on>_universal2. An arm64 slice may ask
    no more than 11.0, the first macOS on Apple Silicon, which the tag then says nothing about.
    """
    x86_64 = []
    for binary in binaries:
        for architecture, minimum in macos_minimums(binary).items():
            if architecture == "x86_64":
                x86_64.append(minimum)
            elif architecture != "arm64" or minimum > (11, 0):
                raise WheelhouseError(
                    f"{binary.name}: a {architecture} slice for macOS {minimum}: a "
                    "universal2 wheel holds x86_64 and arm64 (macOS 11.0) slices"
                )
    major, minor = max(x86_64)
    return f"macosx_{major}_{minor}_universal2"


def _build_base_wheel(out_dir: Path) -> Path:
    """The wheel of this machine, the FMUs inside, built as pip would (an isolated environment)."""
    command = [
        sys.executable,
        "-m",
        "build",
        "--wheel",
        "--outdir",
        out_dir,
        f"--config-setting=--build-option=--linux-glibc={MANYLINUX_GLIBC}",
        ROOT,
    ]
    result = subprocess.run([str(part) for part in command], capture_output=True, text=True, env=_build_environment())
    if result.returncode != 0:
        raise WheelhouseError(f"python -m build --wheel failed:\n{result.stdout[-4000:]}{result.stderr[-4000:]}")
    [wheel] = out_dir.glob("*.whl")
    return wheel


def _retagged(wheel: Path, platform_tag: str) -> Path:
    """Wheel tags: the wheel under another platform tag (the old file removed)."""
    printed = _run(
        [sys.executable, "-m", "wheel", "tags", "--platform-tag", platform_tag, "--remove", wheel], "wheel tags"
    )
    return wheel.parent / printed.strip()


def _tagged(target: WheelPlatform, wheel: Path, native_loop: Path, binaries: list[Path]) -> Path:
    if target.system == "windows":
        return _retagged(wheel, "win_amd64")
    if target.system == "macos":
        return _retagged(wheel, macos_tag([native_loop, *binaries]))
    # auditwheel takes the architecture from the tag as well as from the ELF files.
    wheel = _retagged(wheel, f"linux_{target.machine}")
    return _retagged(wheel, manylinux_tag(wheel, target.machine, binaries))


def build_wheels(output_dir: str | os.PathLike = ROOT / "wheelhouse") -> list[Path]:
    """Build every wheel of WHEELS into output_dir; return their paths.

    Parameters
    ----------
    output_dir : str or os.PathLike
        Where the wheels go (created when missing).

    Returns
    -------
    list of Path
        The wheels, in the order of WHEELS.

    Raises
    ------
    WheelhouseError
        When a tool is missing (before anything is built) or a step fails.
    """
    check_tools()
    written = []
    with tempfile.TemporaryDirectory(prefix="pendulum_fmu_wheels_") as tmp:
        tmp = Path(tmp)
        base = _build_base_wheel(tmp / "base")
        _extract_fmu_binaries(base, tmp / "fmus")
        _run([sys.executable, "-m", "wheel", "unpack", "--dest", tmp / "unpacked", base], "wheel unpack")
        [tree] = (tmp / "unpacked").iterdir()
        for built_here in (tree / "pendulum_fmu" / "fmu").glob("_cs_loop*"):
            built_here.unlink()
        for target in WHEELS:
            native_loop = compile_native_loop(target.platform, tmp / target.platform, MANYLINUX_GLIBC)
            placed = Path(shutil.copyfile(native_loop, tree / "pendulum_fmu" / "fmu" / target.native_loop))
            normalize_modes(tree)
            packed = tmp / "packed" / target.platform
            packed.mkdir(parents=True)
            _run([sys.executable, "-m", "wheel", "pack", "--dest-dir", packed, tree], "wheel pack")
            placed.unlink()
            [wheel] = packed.glob("*.whl")
            wheel = _tagged(target, wheel, native_loop, fmu_binaries_for(target.platform, tmp / "fmus"))
            with replacing_path(Path(output_dir, wheel.name)) as partial:
                shutil.copyfile(wheel, partial)
            written.append(Path(output_dir, wheel.name))
            print(written[-1], flush=True)
    return written


def main(argv: list[str] | None = None) -> int:
    """The command line: build_wheels into --output-dir; 0, or 2 after one line saying what failed."""
    parser = argparse.ArgumentParser(prog="build_wheels.py", description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--output-dir",
        default=str(ROOT / "wheelhouse"),
        help="folder the wheels are written into (default: wheelhouse/ of this checkout)",
    )
    args = parser.parse_args(argv)
    try:
        build_wheels(args.output_dir)
    except (WheelhouseError, BuildError) as error:
        print(f"build_wheels.py: {error}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
