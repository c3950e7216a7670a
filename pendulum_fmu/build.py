"""Build Pendulum.fmu from fmu_src/ and modelDescription.xml, for every platform we can compile for.

The C code takes its value references, names and start values from modelDescription.xml: this
module generates them (model_variables.h/.c), so the XML stays the single source of truth.
fmu_src/ holds the FMI plumbing, which knows nothing of pendulums, and the pendulum's model.h and
model.c; another model (fmu_src/pid_controller/) is built over the same plumbing by naming its
folder and modelDescription.xml.

Builds only ever run from a source tree (a clone or the sdist): an installed package carries the
built FMU as package data instead (see pendulum_fmu.default_fmu).
"""

from __future__ import annotations

import functools
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

import fmpy
from fmpy import read_model_description

from . import FMU_FILES, __version__, fmi3
from .files import replacing_path

ROOT = Path(__file__).resolve().parent.parent
SOURCE_DIR = ROOT / "fmu_src"
MODEL_DESCRIPTION = ROOT / "modelDescription.xml"
FMI_VERSIONS = tuple(FMU_FILES)
# FMI version -> the FMU a checkout builds and runs when none is named.
CHECKOUT_FMUS = {version: ROOT / "dist" / name for version, name in FMU_FILES.items()}
DEFAULT_FMU = CHECKOUT_FMUS[2]
GENERATED_SOURCES = ("model_variables.h", "model_variables.c")
MODEL_FILES = ("config.h", "model.c")
PID_CONTROLLER_DIR = SOURCE_DIR / "pid_controller"
# The FMI headers fmpy ships, rather than a vendored copy.
FMI_HEADERS = Path(fmpy.__file__).parent / "c-code"


@dataclass(frozen=True)
class Platform:
    """A platform an FMU can carry a binary for."""

    fmi2_folder: str      # binaries/<folder> in an FMI 2.0 FMU
    fmi3_folder: str      # binaries/<folder> in an FMI 3.0 FMU
    cross_compiler: str   # the compiler when this is not the machine we build on
    package: str          # the Debian package that installs cross_compiler
    machine: str          # platform.machine() of a Linux host that builds it natively
    suffix: str           # of the shared library

    @property
    def windows(self) -> bool:
        return self.suffix == ".dll"

    @property
    def native(self) -> bool:
        return not self.windows and sys.platform.startswith("linux") and host.machine() == self.machine

    def compiler(self) -> list[str]:
        """The compiler command: $CC (split as a shell would, so CC="ccache gcc" works) or gcc on
        the machine we build on, the cross-compiler elsewhere."""
        if self.native:
            return shlex.split(os.environ.get("CC") or "gcc")
        return [self.cross_compiler]

    def install_hint(self) -> str:
        return f"apt-get install {'gcc' if self.native else self.package}"


PLATFORMS = {platform.fmi2_folder: platform for platform in (
    Platform("linux64", "x86_64-linux", "x86_64-linux-gnu-gcc", "gcc-x86-64-linux-gnu", "x86_64", ".so"),
    Platform("win64", "x86_64-windows", "x86_64-w64-mingw32-gcc", "gcc-mingw-w64-x86-64", "", ".dll"),
    # The folder name fmpy and the Reference FMUs use for Linux on ARM64.
    Platform("aarch64-linux", "aarch64-linux", "aarch64-linux-gnu-gcc", "gcc-aarch64-linux-gnu", "aarch64", ".so"),
)}


class BuildError(RuntimeError):
    """The FMU could not be built; the message says why."""


def _check_sources_present() -> None:
    if not is_source_checkout():
        raise BuildError(
            f"the FMU's sources (fmu_src/, modelDescription.xml) are not beside {Path(__file__).parent}: "
            "to build, run python build_fmu.py in a clone or the unpacked sdist; an installed "
            "package uses its packaged FMU (pendulum_fmu.default_fmu())")


def generate_variables(model_description, out_dir: Path) -> list[Path]:
    """Write model_variables.h (GUID, value reference enum) and model_variables.c (the table)."""
    variables = model_description.modelVariables
    for index, variable in enumerate(variables):
        if variable.valueReference != index or variable.type != "Real":
            raise BuildError(
                f"{MODEL_DESCRIPTION}: variable {variable.name!r} must be Real with valueReference "
                f"{index}: the C code indexes one array of Reals by value reference"
            )
    enum = ",\n".join(f"    VR_{v.name.upper()} = {v.valueReference}" for v in variables)
    header = f"""/* Generated from modelDescription.xml by pendulum_fmu/build.py: edit the XML, not this. */
#ifndef MODEL_VARIABLES_H
#define MODEL_VARIABLES_H

#include "variable.h"

#define MODEL_GUID "{model_description.guid}"
#define N_VARIABLES {len(variables)}

typedef enum {{
{enum}
}} ValueReference;

extern const VariableInfo model_variables[N_VARIABLES];

#endif
"""
    rows = ",\n".join(
        f'    {{"{v.name}", CAUSALITY_{_enum_name(v.causality)}, VARIABILITY_{v.variability.upper()}, '
        f"INITIAL_{(v.initial or 'none').upper()}, {float(v.start or 0.0)!r}}}"
        for v in variables
    )
    table = f"""/* Generated from modelDescription.xml by pendulum_fmu/build.py: edit the XML, not this. */
#include "model_variables.h"

const VariableInfo model_variables[N_VARIABLES] = {{
{rows}
}};
"""
    out_dir.mkdir(parents=True, exist_ok=True)
    paths = [out_dir / name for name in GENERATED_SOURCES]
    paths[0].write_text(header)
    paths[1].write_text(table)
    return paths


def _enum_name(causality: str) -> str:
    return "CALCULATED_PARAMETER" if causality == "calculatedParameter" else causality.upper()


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


def assemble_sources(sources: Path, model_dir: Path = SOURCE_DIR,
                     model_description_file: Path = MODEL_DESCRIPTION, fmi_version: int = 2) -> Path:
    """Everything that compiles into the FMU, in one folder: what the FMU's sources/ holds, and
    what the tests' C driver and fuzzers link."""
    _check_sources_present()
    _assemble_sources(Path(model_dir), read_model_description(str(model_description_file)), Path(sources),
                      fmi_version)
    return Path(sources)


def _assemble_sources(model_dir: Path, model_description, sources: Path, fmi_version: int = 2) -> None:
    """The plumbing from fmu_src/ (with the entry points of one FMI version), the model from
    model_dir, the generated variables."""
    sources.mkdir()
    left_out = {*MODEL_FILES, fmi3.adapter_left_out(fmi_version)}
    for path in SOURCE_DIR.iterdir():
        if path.is_file() and path.name not in left_out:
            shutil.copy2(path, sources)
    for name in MODEL_FILES:
        shutil.copy2(model_dir / name, sources)
    generate_variables(model_description, sources)


def run_compiler(command: list[str], what: str) -> None:
    """Run a compiler command; BuildError with its output when it fails."""
    try:
        result = subprocess.run(command, capture_output=True, text=True)
    except OSError as error:
        raise BuildError(f"compiling {what} failed: {shlex.join(command[:1])}: {error.strerror}") from None
    if result.returncode != 0:
        raise BuildError(f"compiling {what} failed:\n{shlex.join(command)}\n{result.stderr}")


@functools.lru_cache(maxsize=None)
def supports_lto(compiler: tuple[str, ...], windows: bool = False) -> bool:
    """Whether compiler links a shared library with -flto: a gcc without its LTO plug-in
    (lto-wrapper) accepts the flag and then fails to link, so ask by trying."""
    with tempfile.TemporaryDirectory(prefix="pendulum_fmu_lto_") as probe:
        source = Path(probe) / "probe.c"
        source.write_text("int probe(int x) { return x + 1; }\n")
        command = [*compiler, "-flto", "-O2", "-shared", *([] if windows else ["-fPIC"]),
                   str(source), "-o", str(Path(probe) / "probe.so")]
        try:
            return subprocess.run(command, capture_output=True).returncode == 0
        except OSError:
            return False


def find_compiler(platform: Platform) -> list[str]:
    """The platform's compiler command, or BuildError naming the package that installs it."""
    compiler = platform.compiler()
    if not compiler or shutil.which(compiler[0]) is None:
        name = shlex.join(compiler) if compiler else "CC (empty)"
        raise BuildError(f"{platform.fmi2_folder}: C compiler {name} not found "
                         f"({platform.install_hint()})")
    return compiler


def compile_library(source_dir: Path, out_file: Path, platform: str = "linux64", *,
                    export_prefix: str = "fmi2") -> Path:
    """Compile every C file in source_dir into the platform's shared library, exporting only the
    functions named export_prefix* (fmi2 or fmi3).

    On Windows the FMI headers mark those functions __declspec(dllexport), so they are all the DLL
    exports; elsewhere a version script hides everything else. $CFLAGS (split as a shell would)
    applies to the native compiler only: a cross-compiler may not take the host's flags.
    """
    target = PLATFORMS[platform]
    compiler = find_compiler(target)
    if target.windows:
        # No dependency on the mingw runtime DLLs: the FMU must load on any Windows machine.
        linking = ["-static-libgcc", "-s"]
    else:
        version_script = out_file.parent / f"{out_file.stem}.exports.map"
        version_script.write_text(f"{{ global: {export_prefix}*; local: *; }};\n")
        linking = ["-fPIC", "-fvisibility=hidden", f"-Wl,--version-script={version_script}", "-lm"]
    # -flto lets the integrator inline the model's series and right-hand side across files, and
    # -O3 unrolls their loops (bounded by the states and the series' order): a 1 ms step takes
    # about 460 instructions instead of 590 at -O2 (benchmarks/own_cost.py).
    lto = ["-flto"] if supports_lto(tuple(compiler), target.windows) else []
    user_flags = shlex.split(os.environ.get("CFLAGS", "")) if target.native else []
    run_compiler([
        *compiler, "-std=c99", "-O3", *lto, "-shared", "-Wall", "-Wextra", "-Werror", *user_flags,
        f"-I{source_dir}", f"-I{FMI_HEADERS}", *sorted(str(p) for p in source_dir.glob("*.c")),
        *linking, "-o", str(out_file),
    ], f"{out_file.name} for {platform}")
    return out_file


def documentation_html(model_description, fmi_version: int = 2) -> str:
    """documentation/index.html: what the model is and every variable with its unit and meaning."""
    rows = "\n".join(
        "<tr>" + "".join(f"<td>{html.escape(str(cell))}</td>" for cell in (
            v.name, v.valueReference, v.causality, v.variability, v.unit or "",
            "" if v.start is None else v.start, v.description or "")) + "</tr>"
        for v in model_description.modelVariables
    )
    interfaces = " and ".join(name for name, present in (
        ("Model Exchange", model_description.modelExchange), ("Co-Simulation", model_description.coSimulation))
        if present)
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
        raise BuildError(f"unknown platform(s) {', '.join(unknown) or '(none given)'}: choose "
                         f"among {', '.join(PLATFORMS)}")


class PlatformSkipped(UserWarning):
    """A platform left out of a default build because its compiler is missing."""


def available_platforms() -> tuple[str, ...]:
    """Every platform whose compiler is present; for each missing one, a PlatformSkipped warning
    naming the package that installs it. The machine's own platform is never skipped."""
    present = []
    for name, platform in PLATFORMS.items():
        try:
            find_compiler(platform)
        except BuildError as error:
            if platform.native:
                raise  # an FMU that cannot run where it was built is no use
            warnings.warn(PlatformSkipped(f"{error}; skipped"), stacklevel=3)
        else:
            present.append(name)
    return tuple(present)


def _stamped_model_description(xml: Path, fmi_version: int = 2) -> str:
    """The model description as the FMU carries it (for FMI 3.0 generated from the FMI 2.0 one):
    generationTool names this package's version."""
    text = xml.read_text(encoding="utf-8") if fmi_version == 2 else fmi3.model_description(xml)
    text, count = re.subn(r'generationTool="[^"]*"', f'generationTool="pendulum_fmu {__version__}"',
                          text, count=1)
    if count != 1:
        raise BuildError(f"{xml}: no generationTool attribute to stamp the version into")
    return text


def build_fmu(out_file: str | os.PathLike = DEFAULT_FMU, *, model_dir: Path = SOURCE_DIR,
              model_description_file: Path = MODEL_DESCRIPTION,
              platforms: tuple[str, ...] | None = None, fmi_version: int = 2) -> Path:
    """Build an FMU (binaries/, sources/, documentation/) and return its path.

    fmi_version 3 builds the FMI 3.0 FMU from the same sources: its model description and
    sources/buildDescription.xml are generated from the FMI 2.0 one by fmi3.py, its binaries go
    into the FMI 3.0 platform folders and export only fmi3* functions.

    platforms: FMI 2.0 folder names (see PLATFORMS); None builds every platform whose compiler is
    present and warns (PlatformSkipped) about the others. A platform named explicitly must build.
    model_dir and model_description_file name another model's config.h/model.c and XML to build
    over the same plumbing. Everything is compiled in a private temporary folder and the zip is
    renamed into place whole, so builds into the same path at the same time all succeed.
    """
    _check_sources_present()
    if fmi_version not in FMI_VERSIONS:
        raise BuildError(f"FMI version {fmi_version}: choose among {', '.join(map(str, FMI_VERSIONS))}")
    if platforms is None:
        platforms = available_platforms()
    check_platforms(platforms)
    model_description = read_model_description(str(model_description_file))
    identifier = model_description.coSimulation.modelIdentifier
    with tempfile.TemporaryDirectory(prefix="pendulum_fmu_build_") as tmp:
        tmp = Path(tmp)
        sources = tmp / "sources"
        _assemble_sources(Path(model_dir), model_description, sources, fmi_version)
        _check_source_files(model_description, model_description_file, sources, fmi_version)
        if fmi_version == 3:
            (sources / "buildDescription.xml").write_text(fmi3.build_description(model_description_file))
        binaries = {}
        for name in platforms:
            folder = tmp / name
            folder.mkdir()
            library = folder / f"{identifier}{PLATFORMS[name].suffix}"
            platform_folder = name if fmi_version == 2 else PLATFORMS[name].fmi3_folder
            binaries[f"binaries/{platform_folder}/{library.name}"] = compile_library(
                sources, library, name, export_prefix=f"fmi{fmi_version}")
        with replacing_path(out_file) as partial, zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as fmu:
            fmu.writestr("modelDescription.xml",
                         _stamped_model_description(Path(model_description_file), fmi_version))
            for name, binary in binaries.items():
                fmu.write(binary, name)
            for source in sorted(sources.iterdir()):
                fmu.write(source, f"sources/{source.name}")
            fmu.writestr("documentation/index.html", documentation_html(model_description, fmi_version))
    return Path(out_file)


def build_pid_controller(out_file: str | os.PathLike) -> Path:
    """The PID controller FMU that closes the loop around the pendulum in co-simulation."""
    return build_fmu(out_file, model_dir=PID_CONTROLLER_DIR,
                     model_description_file=PID_CONTROLLER_DIR / "modelDescription.xml")


def build_inputs() -> list[Path]:
    """Every file a checkout's FMU is built from: when one is newer than the FMU, it is stale."""
    package = Path(__file__).parent
    return [MODEL_DESCRIPTION, Path(__file__), package / "__init__.py", Path(fmi3.__file__),
            *(p for p in SOURCE_DIR.iterdir() if p.is_file())]


def fmu_is_stale(fmu: Path = DEFAULT_FMU) -> bool:
    """True when fmu is missing or older than any of its sources."""
    if not fmu.exists():
        return True
    built = fmu.stat().st_mtime
    return any(p.stat().st_mtime > built for p in build_inputs())


def is_source_checkout() -> bool:
    """Whether this package sits beside the FMU's sources (a clone, an editable install, the
    sdist being built), rather than installed from a wheel."""
    return SOURCE_DIR.is_dir() and MODEL_DESCRIPTION.is_file()

