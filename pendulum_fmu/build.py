"""Build Pendulum.fmu from fmu_src/ and modelDescription.xml.

The C code takes its value references, names and start values from modelDescription.xml: this
module generates them (model_variables.h/.c), so the XML stays the single source of truth.
fmu_src/ holds the FMI plumbing, which knows nothing of pendulums, and the pendulum's model.h and
model.c; another model (fmu_src/pid_controller/) is built over the same plumbing by naming its
folder and modelDescription.xml.
"""

from __future__ import annotations

import html
import os
import shutil
import subprocess
import tempfile
import warnings
import zipfile
from pathlib import Path

import fmpy
from fmpy import read_model_description

from . import fmi3

ROOT = Path(__file__).resolve().parent.parent
SOURCE_DIR = ROOT / "fmu_src"
MODEL_DESCRIPTION = ROOT / "modelDescription.xml"
DEFAULT_FMU = ROOT / "dist" / "Pendulum.fmu"
DEFAULT_FMU3 = ROOT / "dist" / "Pendulum-fmi3.fmu"
GENERATED_SOURCES = ("model_variables.h", "model_variables.c")
MODEL_FILES = ("config.h", "model.c")
PID_CONTROLLER_DIR = SOURCE_DIR / "pid_controller"
# The FMI 2.0 headers fmpy ships, rather than a vendored copy.
FMI_HEADERS = Path(fmpy.__file__).parent / "c-code"
# Debian's gcc-mingw-w64-x86-64 cross-compiles the Windows binary.
MINGW_COMPILER = "x86_64-w64-mingw32-gcc"
PLATFORMS = ("linux64", "win64")


class BuildError(RuntimeError):
    """The FMU could not be built; the message says why."""


def _check_sources_present() -> None:
    if not SOURCE_DIR.is_dir() or not MODEL_DESCRIPTION.is_file():
        raise BuildError(
            f"FMU sources not found at {ROOT} (fmu_src/ and modelDescription.xml): build from a "
            "clone of the repository, installed with pip install -e ."
        )


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
        if fmi_version == 3:
            listed = listed - {fmi3.FMI2_ADAPTER} | {fmi3.FMI3_ADAPTER}
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


def _compile(command: list[str], what: str) -> None:
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        raise BuildError(f"compiling {what} failed:\n{' '.join(command)}\n{result.stderr}")


def compile_linux64(source_dir: Path, out_file: Path, compiler: str | None = None,
                    exported_prefix: str = "fmi2") -> Path:
    """Compile every C file in source_dir into a shared library exporting only the
    exported_prefix* symbols."""
    compiler = compiler or os.environ.get("CC", "gcc")
    if shutil.which(compiler) is None:
        raise BuildError(f"C compiler {compiler!r} not found: install gcc (apt-get install gcc)")
    version_script = out_file.parent / "exports.map"
    version_script.write_text(f"{{ global: {exported_prefix}*; local: *; }};\n")
    _compile([
        # -flto lets the integrator inline the model's right-hand side across files.
        compiler, "-std=c99", "-O2", "-flto", "-fPIC", "-shared", "-fvisibility=hidden",
        "-Wall", "-Wextra", "-Werror",
        f"-I{source_dir}", f"-I{FMI_HEADERS}",
        *sorted(str(p) for p in source_dir.glob("*.c")),
        f"-Wl,--version-script={version_script}", "-lm",
        "-o", str(out_file),
    ], out_file.name)
    return out_file


def compile_win64(source_dir: Path, out_file: Path) -> Path:
    """Cross-compile the Windows DLL with mingw-w64. fmi2Functions.h (fmi3Functions.h) marks the
    fmi2 (fmi3) functions __declspec(dllexport) on Windows, so they are all the DLL exports."""
    if shutil.which(MINGW_COMPILER) is None:
        raise BuildError(f"{MINGW_COMPILER} not found: install Debian's gcc-mingw-w64-x86-64")
    _compile([
        MINGW_COMPILER, "-std=c99", "-O2", "-flto", "-shared", "-Wall", "-Wextra", "-Werror",
        # No dependency on the mingw runtime DLLs: the FMU must load on any Windows machine.
        "-static-libgcc", "-s", f"-I{source_dir}", f"-I{FMI_HEADERS}",
        *sorted(str(p) for p in source_dir.glob("*.c")), "-o", str(out_file),
    ], out_file.name)
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
<p>Each <code>fmi2DoStep(t, h)</code> integrates exactly [t, t+h] with an error-controlled
Dormand-Prince 5(4) Runge-Kutta method: internal steps end on t+h and never cross it, and the
internal step size carries over between calls. Inputs are held over the step (zero-order
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


def build_fmu(out_file: str | os.PathLike = DEFAULT_FMU, compiler: str | None = None, *,
              model_dir: Path = SOURCE_DIR, model_description_file: Path = MODEL_DESCRIPTION,
              platforms: tuple[str, ...] = ("linux64",), fmi_version: int = 2) -> Path:
    """Build an FMU (binaries/, sources/, documentation/) and return its path.

    By default the pendulum for linux64; model_dir and model_description_file name another
    model's config.h/model.c and XML to build over the same plumbing. A platform other than
    linux64 whose cross-compiler is missing is left out with a warning. fmi_version 3 builds the
    FMI 3.0 FMU from the same sources, its model description generated by fmi3.py.
    """
    if fmi_version not in (2, 3):
        raise BuildError(f"fmi_version must be 2 or 3, got {fmi_version}")
    unknown = set(platforms) - set(PLATFORMS)
    if unknown or "linux64" not in platforms:
        raise BuildError(f"platforms must include linux64 and be among {', '.join(PLATFORMS)}; "
                         f"got {', '.join(platforms)}")
    _check_sources_present()
    model_description = read_model_description(str(model_description_file))
    identifier = model_description.coSimulation.modelIdentifier
    out_file = Path(out_file)
    out_file.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        sources = tmp / "sources"
        _assemble_sources(Path(model_dir), model_description, sources, fmi_version)
        _check_source_files(model_description, model_description_file, sources, fmi_version)
        if fmi_version == 3:
            (sources / "buildDescription.xml").write_text(fmi3.build_description(model_description_file))
        folder = {p: fmi3.platform_folder(p, fmi_version) for p in PLATFORMS}
        binaries = {f"binaries/{folder['linux64']}/{identifier}.so":
                    compile_linux64(sources, tmp / f"{identifier}.so", compiler, f"fmi{fmi_version}")}
        if "win64" in platforms:
            try:
                binaries[f"binaries/{folder['win64']}/{identifier}.dll"] = compile_win64(
                    sources, tmp / f"{identifier}.dll")
            except BuildError as error:
                warnings.warn(f"win64 left out: {error}", stacklevel=2)
        # Write to a temporary name first so a failed build never leaves half an FMU behind.
        partial = out_file.with_suffix(".fmu.partial")
        with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as fmu:
            if fmi_version == 3:
                fmu.writestr("modelDescription.xml", fmi3.model_description(model_description_file))
            else:
                fmu.write(model_description_file, "modelDescription.xml")
            for name, binary in binaries.items():
                fmu.write(binary, name)
            for source in sorted(sources.iterdir()):
                fmu.write(source, f"sources/{source.name}")
            fmu.writestr("documentation/index.html", documentation_html(model_description, fmi_version))
        partial.replace(out_file)
    return out_file


def build_pid_controller(out_file: str | os.PathLike, compiler: str | None = None) -> Path:
    """The PID controller FMU that closes the loop around the pendulum in co-simulation."""
    return build_fmu(out_file, compiler, model_dir=PID_CONTROLLER_DIR,
                     model_description_file=PID_CONTROLLER_DIR / "modelDescription.xml")


def fmu_is_stale(fmu: Path = DEFAULT_FMU) -> bool:
    """True when fmu is missing or older than any of its sources."""
    if not fmu.exists():
        return True
    built = fmu.stat().st_mtime
    inputs = [MODEL_DESCRIPTION, Path(__file__), Path(fmi3.__file__),
              *(p for p in SOURCE_DIR.iterdir() if p.is_file())]
    return any(p.stat().st_mtime > built for p in inputs)


def default_fmu(fmi_version: int = 2) -> Path:
    """The FMU built from this checkout, rebuilt first when its sources changed."""
    _check_sources_present()
    path = DEFAULT_FMU3 if fmi_version == 3 else DEFAULT_FMU
    if fmu_is_stale(path):
        build_fmu(path, fmi_version=fmi_version)
    return path
