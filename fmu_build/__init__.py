"""The repository's build of Pendulum.fmu from fmu_src/ and modelDescription.xml, for every platform
we can compile for: `python build_fmu.py`, the wheel build (setup.py, build_wheels.py), and a
checkout's pendulum_fmu.default_fmu() when a source is newer than dist/Pendulum.fmu.
It is a tool of the repository, not part of the installed package.

The one build description is CMakeLists.txt (with a toolchain file per cross target in cmake/);
this module drives it. The C code takes its value references, names and start values from the
model's modelDescription.xml: this module generates them (model_variables.h/.c), so the XML stays
the single source of truth. fmu_src/src/ and fmu_src/include/ hold the FMI plumbing, which knows
nothing of pendulums; each model has its own folder (config.h, model.c), listed in MODELS.
Per platform, CMake configures and builds in a private temporary folder; fmu_build/macho.py merges the two
macOS slices into one universal binary; the FMU's zip is renamed into place whole. With a glibc
floor (linux_glibc, CMake's LINUX_GLIBC) zig builds the Linux binaries to load on that glibc and
every later one, as the manylinux wheels need.

Builds only ever run from a source tree (a clone or the sdist): an installed package carries the
built FMU as package data instead (see pendulum_fmu.default_fmu).
"""

from __future__ import annotations

import html
import os
import platform as host
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import warnings
import zipfile
from dataclasses import dataclass
from pathlib import Path

from fmpy import read_model_description

from pendulum_fmu import CONTROLLER_FMU_FILE, FMU_FILES, __version__
from pendulum_fmu._atomic_files import check_writable, replacing_path
from pendulum_fmu._errors import BuildError, PlatformSkipped

from . import fmi3
from .macho import MachOError, merge_universal
from .model_variables import ModelDescriptionError, generate_variables

ROOT = Path(__file__).resolve().parent.parent
CMAKE_LISTS = ROOT / "CMakeLists.txt"
TOOLCHAINS = ROOT / "cmake"
SOURCE_DIR = ROOT / "fmu_src"
PLUMBING_DIR = SOURCE_DIR / "src"
HEADERS_DIR = SOURCE_DIR / "include"
MODEL_DESCRIPTION = ROOT / "modelDescription.xml"
FMI_VERSIONS = tuple(FMU_FILES)
# FMI version -> the FMU a checkout builds and runs when none is named.
CHECKOUT_FMUS = {version: ROOT / "dist" / name for version, name in FMU_FILES.items()}
DEFAULT_FMU = CHECKOUT_FMUS[2]
CHECKOUT_CONTROLLER = ROOT / "dist" / CONTROLLER_FMU_FILE
MODEL_FILES = ("config.h", "model.c")
# The FMI standard's own headers, kept in the repository as the Reference FMUs keep them.
FMI_HEADERS = HEADERS_DIR / "fmi"


@dataclass(frozen=True)
class Model:
    """A model built over the FMI plumbing."""

    folder: Path  # its config.h and model.c
    description: Path  # its FMI 2.0 modelDescription.xml


# The build's one table of models. The pendulum's description is the project's top-level
# modelDescription.xml, the single source of truth for its variables.
MODELS = {
    "pendulum": Model(SOURCE_DIR / "pendulum", MODEL_DESCRIPTION),
    "pid_controller": Model(SOURCE_DIR / "pid_controller", SOURCE_DIR / "pid_controller" / "modelDescription.xml"),
}
PENDULUM_DIR = MODELS["pendulum"].folder
PID_CONTROLLER_DIR = MODELS["pid_controller"].folder
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


def _check_sources_present() -> None:
    if not is_source_checkout():
        raise BuildError(
            f"the FMU's sources (fmu_src/, modelDescription.xml, CMakeLists.txt) are not beside "
            f"{Path(__file__).parent}: to build, run python build_fmu.py in a clone or the unpacked "
            "sdist; an installed package uses its packaged FMU (pendulum_fmu.default_fmu())"
        )


def _generate_variables(xml: Path, out_dir: Path) -> None:
    """model_variables.h/.c, as CMake generates them too; BuildError for a description the C code
    cannot take.
    """
    try:
        generate_variables(xml, out_dir)
    except ModelDescriptionError as error:
        raise BuildError(str(error)) from None


def _check_source_files(model_description, xml: Path, sources: Path, fmi_version: int = 2) -> None:
    for configuration in model_description.buildConfigurations:
        listed = set(configuration.sourceFileSets[0].sourceFiles)
        listed = set(fmi3.with_adapter(listed, fmi_version))
        present = {p.name for p in sources.glob("*.c")}
        if listed != present:
            raise BuildError(
                f"<SourceFiles> in {xml} lists {sorted(listed)} but the sources are "
                f"{sorted(present)}: fmpy compile needs them to agree"
            )


def assemble_sources(
    sources: Path,
    model_dir: Path = PENDULUM_DIR,
    model_description_file: Path = MODEL_DESCRIPTION,
    fmi_version: int = 2,
) -> Path:
    """Everything that compiles into the FMU, in one flat folder: what the FMU's sources/ holds,
    which fmpy compile builds, and what the tests' C driver and fuzzers link.
    """
    _check_sources_present()
    sources = Path(sources)
    sources.mkdir()
    _generate_variables(model_description_file, sources)
    _copy_sources(Path(model_dir), sources, fmi_version)
    return sources


def _copy_sources(model_dir: Path, sources: Path, fmi_version: int) -> None:
    """The plumbing (with the entry points of one FMI version) and the model, into sources."""
    left_out = fmi3.adapter_left_out(fmi_version)
    for path in [
        *sorted(HEADERS_DIR.glob("*.h")),
        *sorted(PLUMBING_DIR.glob("*.c")),
        *(model_dir / name for name in MODEL_FILES),
    ]:
        if path.name != left_out:
            shutil.copy2(path, sources)


def find_zig() -> str | None:
    """Zig from the ziglang package (pip install ziglang), else from PATH."""
    try:
        import ziglang
    except ImportError:
        return shutil.which(ZIG)
    bundled = Path(ziglang.__file__).parent / ("zig.exe" if os.name == "nt" else "zig")
    return str(bundled) if bundled.is_file() else shutil.which(ZIG)


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


def _merged(slices: list[Path], out_file: Path) -> Path:
    """One binary of the slices: the slice itself, or a universal Mach-O (fmu_build/macho.py)."""
    if len(slices) == 1:
        return slices[0]
    try:
        return merge_universal(slices, out_file)
    except MachOError as error:
        raise BuildError(f"the universal {out_file.name}: {error}") from None


def compile_native_loop(platform: str, out_dir: str | os.PathLike, linux_glibc: str | None = None) -> Path:
    """Build the native co-simulation loop (pendulum_fmu/_cs_loop.c) for a platform of PLATFORMS
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
    _check_sources_present()
    check_platforms([platform])
    check_toolchain(PLATFORMS[platform], linux_glibc=linux_glibc)
    with tempfile.TemporaryDirectory(prefix="pendulum_fmu_native_loop_") as tmp:
        slices = [
            cmake_build(target, Path(tmp, target.name), "_cs_loop", {"MODEL_DIR": ""}, linux_glibc=linux_glibc)
            for target in PLATFORMS[platform].targets
        ]
        built = _merged(slices, Path(tmp, slices[0].name))
        out_file = Path(out_dir, built.name)
        with replacing_path(out_file) as partial:
            shutil.copyfile(built, partial)
    return out_file


def documentation_html(model_description, fmi_version: int = 2) -> str:
    """documentation/index.html: what the model is and every variable with its unit and meaning."""
    rows = "\n".join(
        "<tr>"
        + "".join(
            f"<td>{html.escape(str(cell))}</td>"
            for cell in (
                v.name,
                v.valueReference,
                v.causality,
                v.variability,
                v.unit or "",
                "" if v.start is None else v.start,
                v.description or "",
            )
        )
        + "</tr>"
        for v in model_description.modelVariables
    )
    interfaces = " and ".join(
        name
        for name, present in (
            ("Model Exchange", model_description.modelExchange),
            ("Co-Simulation", model_description.coSimulation),
        )
        if present
    )
    name = html.escape(model_description.modelName)
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{name} FMU</title>
<style>body{{font-family:sans-serif;max-width:60em;margin:2em auto}}
table{{border-collapse:collapse}}td,th{{border:1px solid #999;padding:.2em .5em}}</style></head>
<body>
<h1>{name}</h1>
<p>{html.escape(model_description.description or "")}</p>
<p>FMI {fmi_version}.0 {interfaces}, model identifier <code>{name}</code>.</p>
<h2>Inside a communication step</h2>
<p>Each <code>fmi{fmi_version}DoStep(t, h)</code> integrates exactly [t, t+h] with an error-controlled
Taylor series method of order 6 (Dormand-Prince 5(4) where the model has no series or the
method gives up): internal steps end on t+h and never cross it, and the internal step size
carries over between calls. Inputs are held over the step (zero-order
hold) or, after <code>fmi2SetRealInputDerivatives</code> (orders 1 and 2; higher orders are
ignored), follow their Taylor polynomial from their values at t until the derivatives are set
again. FMI 3.0 has no input derivatives: there inputs are always held. The relative tolerance is
<code>fmi2SetupExperiment</code>'s when defined, else 1e-10; the absolute tolerance equals it.
A step that needs more than 100000 internal steps returns fmi2Discard and leaves the instance
where it was.</p>
<h2>Variables</h2>
<table><tr><th>name</th><th>value reference</th><th>causality</th><th>variability</th>
<th>unit</th><th>start</th><th>description</th></tr>
{rows}
</table>
</body></html>
"""


def check_platforms(names) -> None:
    """BuildError unless names are one or more of PLATFORMS."""
    unknown = [name for name in names if name not in PLATFORMS]
    if unknown or not names:
        raise BuildError(
            f"unknown platform(s) {', '.join(unknown) or '(none given)'}: choose among {', '.join(PLATFORMS)}"
        )


def available_platforms(fmi_version: int = 2, linux_glibc: str | None = None) -> tuple[str, ...]:
    """Every platform whose tools are present (zig for the Linux ones with linux_glibc); for each
    missing one, a PlatformSkipped warning naming the package that installs it. The machine's
    own platform is never skipped.
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
    return tuple(present)


def _stamped_model_description(xml: Path, fmi_version: int = 2) -> str:
    """The model description as the FMU carries it (for FMI 3.0 generated from the FMI 2.0 one):
    generationTool names this package's version.
    """
    text = xml.read_text(encoding="utf-8") if fmi_version == 2 else fmi3.model_description(xml)
    text, count = re.subn(r'generationTool="[^"]*"', f'generationTool="pendulum_fmu {__version__}"', text, count=1)
    if count != 1:
        raise BuildError(f"{xml}: no generationTool attribute to stamp the version into")
    return text


def build_fmu(
    out_file: str | os.PathLike = DEFAULT_FMU,
    *,
    model_dir: Path = PENDULUM_DIR,
    model_description_file: Path = MODEL_DESCRIPTION,
    platforms: tuple[str, ...] | None = None,
    fmi_version: int = 2,
    linux_glibc: str | None = None,
) -> Path:
    """Build an FMU (binaries/, sources/, documentation/) of a model over the FMI plumbing.

    Everything is compiled in a private temporary folder and the zip is renamed into place
    whole, so builds into the same path at the same time all succeed.

    Parameters
    ----------
    out_file : str or os.PathLike
        Where to write the FMU.
    model_dir : Path
        The model's folder (config.h, model.c); see MODELS.
    model_description_file : Path
        The model's FMI 2.0 modelDescription.xml, the source of its variables.
    platforms : tuple of str, optional
        FMI 2.0 platform folder names (keys of PLATFORMS). None builds every platform whose
        tools are present and warns (PlatformSkipped) about each other one; a platform named
        here must build.
    fmi_version : int
        2, or 3 for the FMI 3.0 FMU from the same sources: its model description and
        sources/buildDescription.xml are generated from the FMI 2.0 one (fmi3.py), its binaries
        go into the FMI 3.0 platform folders (darwin64's two slices into x86_64-darwin and
        aarch64-darwin) and export only fmi3* functions.
    linux_glibc : str, optional
        The oldest glibc the Linux binaries are to load on, such as "2.17" (manylinux2014's):
        zig's C compiler builds them against that glibc's symbol versions (cmake/linux.cmake).
        None: gcc (or $CC) and the cross gcc, against the build machine's glibc and the cross
        libc.

    Returns
    -------
    Path
        out_file.

    Raises
    ------
    BuildError
        When the sources are not beside the package, a platform or FMI version is unknown, a
        named platform's tools are missing, linux_glibc is not a glibc version, or a compiler
        fails.
    CannotWrite
        out_file cannot be written.
    """
    _check_sources_present()
    if fmi_version not in FMI_VERSIONS:
        raise BuildError(f"FMI version {fmi_version}: choose among {', '.join(map(str, FMI_VERSIONS))}")
    if platforms is None:
        platforms = available_platforms(fmi_version, linux_glibc)
    check_platforms(platforms)
    check_writable(out_file)  # before the compilers run
    for name in platforms:
        check_toolchain(PLATFORMS[name], fmi_version, linux_glibc)
    model_dir = Path(model_dir)
    model_description = read_model_description(str(model_description_file))
    identifier = model_description.coSimulation.modelIdentifier
    with tempfile.TemporaryDirectory(prefix="pendulum_fmu_build_") as tmp:
        tmp = Path(tmp)
        sources = tmp / "sources"
        sources.mkdir()
        _copy_sources(model_dir, sources, fmi_version)
        _generate_variables(model_description_file, sources)  # as CMake generates them for the binaries
        _check_source_files(model_description, model_description_file, sources, fmi_version)
        if fmi_version == 3:
            (sources / "buildDescription.xml").write_text(fmi3.build_description(model_description_file))
        definitions = {
            "MODEL_DIR": model_dir.resolve(),
            "MODEL_DESCRIPTION": Path(model_description_file).resolve(),
            "FMI_VERSION": fmi_version,
        }
        binaries = {}
        for name in platforms:
            platform = PLATFORMS[name]
            slices = {
                target.name: cmake_build(target, tmp / name / target.name, "fmu", definitions, linux_glibc=linux_glibc)
                for target in platform.targets
            }
            if fmi_version == 3:
                binaries.update({f"binaries/{folder}/{binary.name}": binary for folder, binary in slices.items()})
            else:
                binary = _merged(list(slices.values()), tmp / name / f"{identifier}{platform.suffix}")
                binaries[f"binaries/{name}/{binary.name}"] = binary
        with replacing_path(out_file) as partial, zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as fmu:
            fmu.writestr("modelDescription.xml", _stamped_model_description(Path(model_description_file), fmi_version))
            for name, binary in binaries.items():
                fmu.write(binary, name)
            for source in sorted(sources.iterdir()):
                fmu.write(source, f"sources/{source.name}")
            fmu.writestr("documentation/index.html", documentation_html(model_description, fmi_version))
    return Path(out_file)


def build_pid_controller(out_file: str | os.PathLike = CHECKOUT_CONTROLLER, **options) -> Path:
    """The PID controller FMU that closes the loop around the pendulum in co-simulation.

    options are build_fmu's platforms and linux_glibc: the wheel builds it as it builds the
    pendulum's FMI 2.0 FMU, for the same platforms.
    """
    model = MODELS["pid_controller"]
    return build_fmu(out_file, model_dir=model.folder, model_description_file=model.description, **options)


def build_inputs() -> list[Path]:
    """Every file a checkout's FMU is built from: when one is newer than the FMU, it is stale."""
    return [
        MODEL_DESCRIPTION,
        CMAKE_LISTS,
        ROOT / "pendulum_fmu" / "__init__.py",
        *Path(__file__).parent.glob("*.py"),
        *TOOLCHAINS.glob("*.cmake"),
        *(p for p in SOURCE_DIR.rglob("*") if p.is_file()),
    ]


def fmu_is_stale(fmu: Path = DEFAULT_FMU) -> bool:
    """True when fmu is missing or older than any of its sources."""
    if not fmu.exists():
        return True
    built = fmu.stat().st_mtime
    return any(p.stat().st_mtime > built for p in build_inputs())


def is_source_checkout() -> bool:
    """Whether this package sits beside the FMU's sources (a clone, an editable install, the
    sdist being built), rather than installed from a wheel.
    """
    return SOURCE_DIR.is_dir() and MODEL_DESCRIPTION.is_file() and CMAKE_LISTS.is_file()
