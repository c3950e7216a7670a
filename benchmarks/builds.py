"""What the benchmarks run: the pendulum FMU from this checkout, the null FMU, the C master.

Everything is built fresh into a scratch directory, so the figures are always of the sources as
they are, never of a stale dist/Pendulum.fmu.
"""

from __future__ import annotations

import zipfile
from dataclasses import dataclass
from pathlib import Path

from fmpy import extract, read_model_description

from fmu_build import FMI_HEADERS, PLATFORMS, build_fmu, check_toolchain, cmake_build, run_tool

HERE = Path(__file__).resolve().parent
NULL_FMU_SOURCES = HERE / "null_fmu"
# The bare C master of each FMI version; bare_master.h holds what they share.
STEP_MASTER_SOURCES = {2: HERE / "step_master.c", 3: HERE / "fmi3_step_master.c"}


@dataclass(frozen=True)
class BuiltFmu:
    """An FMU, unzipped once, with what a master needs to instantiate it."""

    path: Path
    unzip_dir: Path
    guid: str
    model_identifier: str
    value_references: dict[str, int]

    @property
    def library(self) -> Path:
        return self.unzip_dir / "binaries" / "linux64" / f"{self.model_identifier}.so"


def unzipped(fmu: Path, out_dir: Path) -> BuiltFmu:
    description = read_model_description(str(fmu))
    unzip_dir = Path(extract(str(fmu), str(out_dir / f"{fmu.stem}_unzipped")))
    references = {v.name: v.valueReference for v in description.modelVariables}
    return BuiltFmu(fmu, unzip_dir, description.guid, description.coSimulation.modelIdentifier, references)


def build_pendulum_fmu(out_dir: Path) -> BuiltFmu:
    return unzipped(build_fmu(out_dir / "Pendulum.fmu", platforms=("linux64",)), out_dir)


def build_fmi3_fmu(out_dir: Path) -> Path:
    """The FMI 3.0 FMU as pendulum-fmu build makes it: every binary this machine builds, the
    WebAssembly one among them (the wasm part runs its native and its wasm binary side by side).
    """
    return build_fmu(out_dir / "Pendulum-fmi3.fmu", fmi_version=3)


def build_null_fmu(out_dir: Path) -> BuiltFmu:
    """Build null_fmu/ with the pendulum's compiler flags (its CMakeLists.txt includes
    cmake/flags.cmake) and zip it as NullFmu.fmu.
    """
    work = out_dir / "null_fmu_build"
    work.mkdir(parents=True, exist_ok=True)
    [native] = PLATFORMS["linux64"].targets
    library = cmake_build(native, work, "NullFmu", project=NULL_FMU_SOURCES)
    fmu = out_dir / "NullFmu.fmu"
    with zipfile.ZipFile(fmu, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.write(NULL_FMU_SOURCES / "modelDescription.xml", "modelDescription.xml")
        archive.write(library, "binaries/linux64/NullFmu.so")
        archive.write(NULL_FMU_SOURCES / "null.c", "sources/null.c")
    return unzipped(fmu, out_dir)


def build_step_master(out_dir: Path, platform: str = "linux64", fmi_version: int = 2) -> Path:
    """Compile the bare C master of an FMI version (step_master.c, fmi3_step_master.c) for a
    platform of fmu_build.PLATFORMS with that platform's compiler (the tests run the win64
    one under wine, the aarch64-linux one under qemu-aarch64).
    """
    return build_bare_master(out_dir, STEP_MASTER_SOURCES[fmi_version], platform)


def build_bare_master(out_dir: Path, source: Path, platform: str = "linux64") -> Path:
    """Compile a C program, one file (a step master over bare_master.h, a program of tests/c/),
    for a platform of fmu_build.PLATFORMS with that platform's compiler.
    """
    chosen = PLATFORMS[platform]
    check_toolchain(chosen)
    [target] = chosen.targets  # the masters run here, where no universal binary is needed
    master = out_dir / f"{source.stem}_{platform}{'.exe' if chosen.windows else ''}"
    command = [
        *target.compiler(),
        "-std=c99",
        "-O2",
        "-Wall",
        "-Wextra",
        "-Werror",
        f"-I{FMI_HEADERS}",
        f"-I{HERE}",
        str(source),
        *([] if chosen.windows else ["-ldl"]),
        "-o",
        str(master),
    ]
    run_tool(command, source.name)
    return master
