"""An FMU file: a model's binaries for each platform, its sources and its documentation, zipped.

Everything is compiled in a private temporary folder and the zip is renamed into place whole, so
builds into the same path at the same time all succeed. The FMI 3.0 FMU is built from the same
sources, its model description generated from the FMI 2.0 one (fmi3.py).
"""

from __future__ import annotations

import os
import re
import tempfile
from pathlib import Path

from fmpy import read_model_description

from pendulum_fmu import __version__
from pendulum_fmu._atomic_files import check_writable, replacing_path
from pendulum_fmu._errors import BuildError
from pendulum_fmu.fmu._build_record import RECORD_FORMAT, with_record, write_archive

from . import fmi3
from .binaries import cmake_build, merged_binary
from .build_record import source_commit, source_date_epoch, toolchain
from .documentation import documentation_html
from .platforms import PLATFORMS, WASM, available_platforms, check_platforms, check_toolchain, check_wasm_toolchain
from .sources import (
    CHECKOUT_CONTROLLER,
    DEFAULT_FMU,
    FMI_VERSIONS,
    MODEL_DESCRIPTION,
    MODELS,
    PENDULUM_DIR,
    check_source_files,
    check_sources_present,
    copy_sources,
    write_variables,
)
from .wasm_component import MANIFEST, MANIFEST_ENTRY, wasm_component


def _stamped_model_description(xml: Path, fmi_version: int = 2) -> str:
    """The model description as the FMU carries it (for FMI 3.0 generated from the FMI 2.0 one):
    generationTool names this package's version.
    """
    text = xml.read_text(encoding="utf-8") if fmi_version == 2 else fmi3.model_description(xml)
    text, count = re.subn(r'generationTool="[^"]*"', f'generationTool="pendulum_fmu {__version__}"', text, count=1)
    if count != 1:
        raise BuildError(f"{xml}: no generationTool attribute to stamp the version into")
    return text


def _check_toolchains(platforms: tuple[str, ...], fmi_version: int, linux_glibc: str | None) -> None:
    """BuildError naming what to install unless every platform's tools are here."""
    for name in platforms:
        if name == WASM:
            check_wasm_toolchain(fmi_version)
        else:
            check_toolchain(PLATFORMS[name], fmi_version, linux_glibc)


def _binaries(
    platforms: tuple[str, ...], tmp: Path, definitions: dict, identifier: str, fmi_version: int, linux_glibc
) -> tuple[dict[str, Path], dict[str, list]]:
    """Each platform's binary built in tmp, by its entry name in the FMU (FMI 3.0: one per slice,
    FMI 2.0: macOS's slices merged), and the toolchain each was made with (for its build record).
    """
    binaries: dict[str, Path] = {}
    toolchains: dict[str, list] = {}
    for name in platforms:
        if name == WASM:
            component, made_component = wasm_component(tmp / name, definitions)
            binaries[f"binaries/{WASM}/{component.name}"] = component
            toolchains[f"binaries/{WASM}/{component.name}"] = [made_component]
            continue
        platform = PLATFORMS[name]
        slices = {
            target.name: cmake_build(target, tmp / name / target.name, "fmu", definitions, linux_glibc=linux_glibc)
            for target in platform.targets
        }
        made = {
            folder: {"target": folder, **toolchain(binary.parent.parent / "build", "fmu")}
            for folder, binary in slices.items()
        }
        if fmi_version == 3:
            for folder, binary in slices.items():
                binaries[f"binaries/{folder}/{binary.name}"] = binary
                toolchains[f"binaries/{folder}/{binary.name}"] = [made[folder]]
        else:
            binary = merged_binary(list(slices.values()), tmp / name / f"{identifier}{platform.suffix}")
            binaries[f"binaries/{name}/{binary.name}"] = binary
            toolchains[f"binaries/{name}/{binary.name}"] = list(made.values())
    return binaries, toolchains


def _write_fmu(
    out_file,
    model_description_file: Path,
    model_description,
    fmi_version: int,
    binaries: dict,
    toolchains: dict,
    sources: Path,
) -> None:
    """Zip the FMU's entries and its build record into out_file, whole or not at all."""
    entries = {
        "modelDescription.xml": _stamped_model_description(model_description_file, fmi_version).encode(),
        **{name: binary.read_bytes() for name, binary in binaries.items()},
        **{f"sources/{source.name}": source.read_bytes() for source in sorted(sources.iterdir())},
        "documentation/index.html": documentation_html(model_description, fmi_version).encode(),
    }
    if any(name.startswith(f"binaries/{WASM}/") for name in binaries):
        entries[MANIFEST_ENTRY] = MANIFEST.encode()
    epoch = source_date_epoch()
    record = {
        "format": RECORD_FORMAT,
        "generator": f"pendulum_fmu {__version__}",
        **source_commit(),
        "source_date_epoch": epoch,
        "fmi_version": fmi_version,
        "binaries": toolchains,
    }
    with replacing_path(out_file) as partial:
        write_archive(partial, with_record(entries, record).items(), epoch)


def build_fmu(
    out_file: str | os.PathLike = DEFAULT_FMU,
    *,
    model_dir: Path = PENDULUM_DIR,
    model_description_file: Path = MODEL_DESCRIPTION,
    platforms: tuple[str, ...] | None = None,
    fmi_version: int = 2,
    linux_glibc: str | None = None,
) -> Path:
    """Build an FMU (binaries/, sources/, documentation/) of a model over the FMI plumbing, as
    the module's docstring says: in a private folder, renamed into place whole.

    Parameters
    ----------
    out_file : str or os.PathLike
        Where to write the FMU.
    model_dir : Path
        The model's folder (config.h, model.c); see MODELS.
    model_description_file : Path
        The model's FMI 2.0 modelDescription.xml, the source of its variables.
    platforms : tuple of str, optional
        FMI 2.0 platform folder names (keys of PLATFORMS), and for FMI 3.0 WASM
        ("wasm32-wasip2": the WebAssembly component and FMI-LS-WASM's manifest). None builds
        every platform whose tools are present and warns (PlatformSkipped) about each other one;
        a platform named here must build.
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
    check_sources_present()
    if fmi_version not in FMI_VERSIONS:
        raise BuildError(f"FMI version {fmi_version}: choose among {', '.join(map(str, FMI_VERSIONS))}")
    if platforms is None:
        platforms = available_platforms(fmi_version, linux_glibc)
    check_platforms(platforms)
    check_writable(out_file)  # before the compilers run
    _check_toolchains(platforms, fmi_version, linux_glibc)
    model_dir = Path(model_dir)
    model_description = read_model_description(str(model_description_file))
    identifier = model_description.coSimulation.modelIdentifier
    with tempfile.TemporaryDirectory(prefix="pendulum_fmu_build_") as tmp:
        tmp = Path(tmp)
        sources = tmp / "sources"
        sources.mkdir()
        copy_sources(model_dir, sources, fmi_version)
        write_variables(model_description_file, sources)  # as CMake generates them for the binaries
        check_source_files(model_description, model_description_file, sources, fmi_version)
        if fmi_version == 3:
            (sources / "buildDescription.xml").write_text(fmi3.build_description(model_description_file))
        definitions = {
            "MODEL_DIR": model_dir.resolve(),
            "MODEL_DESCRIPTION": Path(model_description_file).resolve(),
            "FMI_VERSION": fmi_version,
        }
        binaries, toolchains = _binaries(platforms, tmp, definitions, identifier, fmi_version, linux_glibc)
        _write_fmu(
            out_file, Path(model_description_file), model_description, fmi_version, binaries, toolchains, sources
        )
    return Path(out_file)


def build_pid_controller(out_file: str | os.PathLike = CHECKOUT_CONTROLLER, **options) -> Path:
    """The PID controller FMU that closes the loop around the pendulum in co-simulation.

    options are build_fmu's platforms and linux_glibc: the wheel builds it as it builds the
    pendulum's FMI 2.0 FMU, for the same platforms.
    """
    model = MODELS["pid_controller"]
    return build_fmu(out_file, model_dir=model.folder, model_description_file=model.description, **options)
