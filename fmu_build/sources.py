"""Where the build's inputs are in the checkout, the table of models, and the sources an FMU carries.

The pendulum's variables come from the project's top-level modelDescription.xml, the single source
of truth: generate_variables (model_variables.py) writes the C code's value references, names and
start values from it. fmu_src/src/ and fmu_src/include/ hold the FMI plumbing, which knows nothing
of pendulums; each model has its own folder (config.h, model.c), listed in MODELS. A checkout's FMU
is stale when any file it is built from is newer.
"""

from __future__ import annotations

import shutil
from dataclasses import dataclass
from pathlib import Path

from pendulum_fmu import CONTROLLER_FMU_FILE, FMU_FILES
from pendulum_fmu._checkout import CHECKOUT_FMUS  # FMI version -> the FMU a checkout builds and runs
from pendulum_fmu._errors import BuildError

from . import fmi3
from .model_variables import ModelDescriptionError, generate_variables

ROOT = Path(__file__).resolve().parent.parent
CMAKE_LISTS = ROOT / "CMakeLists.txt"
TOOLCHAINS = ROOT / "cmake"
SOURCE_DIR = ROOT / "fmu_src"
PLUMBING_DIR = SOURCE_DIR / "src"
HEADERS_DIR = SOURCE_DIR / "include"
MODEL_DESCRIPTION = ROOT / "modelDescription.xml"
FMI_VERSIONS = tuple(FMU_FILES)
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


def is_source_checkout() -> bool:
    """Whether this package sits beside the FMU's sources (a clone, an editable install, the
    sdist being built), rather than installed from a wheel.
    """
    return SOURCE_DIR.is_dir() and MODEL_DESCRIPTION.is_file() and CMAKE_LISTS.is_file()


def check_sources_present() -> None:
    """BuildError unless the FMU's sources are beside the package (a clone or the unpacked sdist)."""
    if not is_source_checkout():
        raise BuildError(
            f"the FMU's sources (fmu_src/, modelDescription.xml, CMakeLists.txt) are not beside "
            f"{Path(__file__).parent}: to build, run python build_fmu.py in a clone or the unpacked "
            "sdist; an installed package uses its packaged FMU (pendulum_fmu.default_fmu())"
        )


def write_variables(xml: Path, out_dir: Path) -> None:
    """model_variables.h/.c, as CMake generates them too; BuildError for a description the C code
    cannot take.
    """
    try:
        generate_variables(xml, out_dir)
    except ModelDescriptionError as error:
        raise BuildError(str(error)) from None


def check_source_files(model_description, xml: Path, sources: Path, fmi_version: int = 2) -> None:
    """BuildError unless the model description's <SourceFiles> are the C files in sources."""
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
    check_sources_present()
    sources = Path(sources)
    sources.mkdir()
    write_variables(model_description_file, sources)
    copy_sources(Path(model_dir), sources, fmi_version)
    return sources


def copy_sources(model_dir: Path, sources: Path, fmi_version: int) -> None:
    """The plumbing (with the entry points of one FMI version) and the model, into sources."""
    left_out = fmi3.adapter_left_out(fmi_version)
    for path in [
        *sorted(HEADERS_DIR.glob("*.h")),
        *sorted(PLUMBING_DIR.glob("*.c")),
        *(model_dir / name for name in MODEL_FILES),
    ]:
        if path.name != left_out:
            shutil.copy2(path, sources)


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
