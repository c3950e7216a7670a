"""One binary built by CMake for one platform target: the FMU's library or the native loop.

The one build description is CMakeLists.txt (with a toolchain file per cross target in cmake/);
this module drives it. Per target, CMake configures, builds and installs in a private temporary
folder; the two macOS slices are merged into one universal binary (macho.py).
"""

from __future__ import annotations

import os
import shlex
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from pendulum_fmu._atomic_files import replacing_path
from pendulum_fmu._errors import BuildError

from .macho import MachOError, merge_universal
from .platforms import PLATFORMS, Target, check_platforms, check_toolchain, find_zig
from .sources import FMI_HEADERS, ROOT, TOOLCHAINS, check_sources_present


def _cmake() -> str:
    """Cmake from PATH, else from the PyPI cmake package (which fmpy requires), as in a pip
    build environment.
    """
    found = shutil.which("cmake")
    if found is None:
        try:
            import cmake
        except ImportError:
            raise BuildError("cmake not found (pip install cmake, or apt-get install cmake)") from None
        found = str(Path(cmake.CMAKE_BIN_DIR) / "cmake")
    return found


def run_tool(command: list, what: str, environment: dict | None = None) -> None:
    """Run a build command; BuildError with the end of its output when it fails."""
    command = [str(part) for part in command]
    try:
        result = subprocess.run(command, capture_output=True, text=True, env=environment)
    except OSError as error:
        raise BuildError(f"building {what} failed: {shlex.join(command[:1])}: {error.strerror}") from None
    if result.returncode != 0:
        raise BuildError(f"building {what} failed:\n{shlex.join(command)}\n{(result.stdout + result.stderr)[-4000:]}")


def cmake_build(
    target: Target,
    work: Path,
    cmake_target: str,
    definitions: dict | None = None,
    project: Path = ROOT,
    linux_glibc: str | None = None,
) -> Path:
    """Configure, build and install one target of a CMake project (CMakeLists.txt, or another
    that includes cmake/flags.cmake) for one platform target in the empty folder work; return
    the binary.

    On a machine of the target's kind the compiler is CMake's choice, $CC with $CFLAGS when set;
    elsewhere, and for a Linux target with linux_glibc (a glibc version such as 2.17: the oldest
    glibc the binary loads on, cmake/linux.cmake's LINUX_GLIBC) everywhere, the target's toolchain
    file (cmake/), without the host's $CFLAGS, which a cross-compiler may not take. The CMake
    target's install component has its name.
    """
    cmake = _cmake()
    build, installed = work / "build", work / "installed"
    environment = dict(os.environ)
    # This Python runs the variables' generator (fmu_build/model_variables.py), as CMake would find it.
    configure = [
        cmake,
        "-S",
        project,
        "-B",
        build,
        f"-DFMI_HEADERS={FMI_HEADERS}",
        f"-DPython3_EXECUTABLE={sys.executable}",
        # The commands, for the FMU's build record (build_record.py).
        "-DCMAKE_EXPORT_COMPILE_COMMANDS=ON",
        *(f"-D{name}={value}" for name, value in (definitions or {}).items()),
    ]
    cross = not target.native or target.built_by_zig(linux_glibc)
    # On a Mac too: its toolchain file sets the architecture and the oldest macOS.
    if cross or target.system == "darwin":
        configure.append(f"-DCMAKE_TOOLCHAIN_FILE={TOOLCHAINS / target.toolchain}")
    if cross:
        for name in ("CC", "CFLAGS", "LDFLAGS"):
            environment.pop(name, None)
    if target.built_by_zig(linux_glibc):
        configure.append(f"-DZIG={find_zig()}")
    if target.glibc_floor(linux_glibc):
        configure.append(f"-DLINUX_GLIBC={target.glibc_floor(linux_glibc)}")
    what = f"{cmake_target} for {target.name}"
    run_tool(configure, what, environment)
    run_tool([cmake, "--build", build, "--target", cmake_target, "--config", "Release"], what, environment)
    run_tool(
        [cmake, "--install", build, "--prefix", installed, "--component", cmake_target, "--config", "Release"],
        what,
        environment,
    )
    [binary] = [path for path in installed.iterdir() if path.is_file()]
    return binary


def merged_binary(slices: list[Path], out_file: Path) -> Path:
    """One binary of the slices: the slice itself, or a universal Mach-O (fmu_build/macho.py)."""
    if len(slices) == 1:
        return slices[0]
    try:
        return merge_universal(slices, out_file)
    except MachOError as error:
        raise BuildError(f"the universal {out_file.name}: {error}") from None


def compile_native_loop(platform: str, out_dir: str | os.PathLike, linux_glibc: str | None = None) -> Path:
    """Build the native co-simulation loop (pendulum_fmu/fmu/_cs_loop.c) for a platform of PLATFORMS
    into out_dir, named as that platform's Python loads it (_cs_loop.so, or _cs_loop.pyd on
    Windows); for darwin64 one universal binary.

    Parameters
    ----------
    platform : str
        An FMI 2.0 platform folder name, a key of PLATFORMS.
    out_dir : str or os.PathLike
        The folder to write into; the file is renamed into place whole.
    linux_glibc : str, optional
        For a Linux platform, the oldest glibc the loop is to load on, such as "2.17": zig's C
        compiler builds it against that glibc's symbol versions. None: gcc (or $CC), against
        the build machine's glibc.

    Returns
    -------
    Path
        The native loop's file.

    Raises
    ------
    BuildError
        When the platform is unknown, its compiler is missing, linux_glibc is not a glibc
        version or the build fails.
    """
    check_sources_present()
    check_platforms([platform])
    check_toolchain(PLATFORMS[platform], linux_glibc=linux_glibc)
    with tempfile.TemporaryDirectory(prefix="pendulum_fmu_native_loop_") as tmp:
        slices = [
            cmake_build(target, Path(tmp, target.name), "_cs_loop", {"MODEL_DIR": ""}, linux_glibc=linux_glibc)
            for target in PLATFORMS[platform].targets
        ]
        built = merged_binary(slices, Path(tmp, slices[0].name))
        out_file = Path(out_dir, built.name)
        with replacing_path(out_file) as partial:
            shutil.copyfile(built, partial)
    return out_file
