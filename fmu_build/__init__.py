"""The repository's build of Pendulum.fmu from fmu_src/ and modelDescription.xml, for every platform
we can compile for: `python build_fmu.py`, the wheel build (setup.py, build_wheels.py), and a
checkout's pendulum_fmu.default_fmu() when a source is newer than dist/Pendulum.fmu.
It is a tool of the repository, not part of the installed package.

This module is its face: the names the build's users import, from the modules that do the work,
each of which imports only those listed before it:

- sources.py: where the build's inputs are in the checkout, the table of models (MODELS), the
  sources an FMU carries, and whether a checkout's FMU is stale;
- platforms.py: the platforms an FMU carries a binary for (PLATFORMS), their compilers (the
  cross gcc, zig) and whether they are here;
- binaries.py: one binary through CMake (CMakeLists.txt, cmake/): the FMU's library, the native
  loop; macho.py merges the two macOS slices into one universal binary;
- documentation.py: the FMU's documentation/index.html;
- wasm_component.py: the FMI 3.0 FMU's WebAssembly component and FMI-LS-WASM's manifest;
- fmu_file.py: an FMU file, its binaries, sources and documentation zipped (build_fmu,
  build_pid_controller).
- release_files.py: the sdist's tar.gz and the wheel's files, the same bytes from one commit
  (setup.py, build_wheels.py; the commit and its time from build_record.py).

model_variables.py writes the C code's value references, names and start values from the
model's modelDescription.xml, so the XML stays the single source of truth; fmi3.py generates the
FMI 3.0 description from the FMI 2.0 one; wasm_glue.py the WebAssembly component's canonical-ABI
glue from its WIT world (both run by CMake, standard library only).

Each name is imported from its module on first use (__getattr__ below): what a checkout's
package asks on every start (its FMU's path and whether it is stale, the build command's help)
loads sources.py and platforms.py, not fmpy and the zipping of fmu_file.py (start-up time).

Builds only ever run from a source tree (a clone or the sdist): an installed package carries the
built FMU as package data instead (see pendulum_fmu.default_fmu).
"""

from pendulum_fmu import _imported_on_first_use
from pendulum_fmu._errors import BuildError, PlatformSkipped

# The public name -> the module that holds it, imported on first use (__getattr__ below).
_LAZY = {
    "cmake_build": "binaries",
    "compile_native_loop": "binaries",
    "run_tool": "binaries",
    "documentation_html": "documentation",
    "build_fmu": "fmu_file",
    "build_pid_controller": "fmu_file",
    "MachOError": "macho",
    "merge_universal": "macho",
    "ModelDescriptionError": "model_variables",
    "generate_variables": "model_variables",
    "PLATFORMS": "platforms",
    "WASM": "platforms",
    "WASM_TARGET": "platforms",
    "ZIG": "platforms",
    "ZIG_GLIBC": "platforms",
    "ZIG_PACKAGE": "platforms",
    "Platform": "platforms",
    "Target": "platforms",
    "available_platforms": "platforms",
    "check_platforms": "platforms",
    "check_toolchain": "platforms",
    "check_wasm_toolchain": "platforms",
    "find_wasm_tools": "platforms",
    "find_zig": "platforms",
    "CHECKOUT_CONTROLLER": "sources",
    "CHECKOUT_FMUS": "sources",
    "CMAKE_LISTS": "sources",
    "DEFAULT_FMU": "sources",
    "FMI_HEADERS": "sources",
    "FMI_VERSIONS": "sources",
    "HEADERS_DIR": "sources",
    "MODEL_DESCRIPTION": "sources",
    "MODEL_FILES": "sources",
    "MODELS": "sources",
    "PENDULUM_DIR": "sources",
    "PID_CONTROLLER_DIR": "sources",
    "PLUMBING_DIR": "sources",
    "ROOT": "sources",
    "SOURCE_DIR": "sources",
    "TOOLCHAINS": "sources",
    "Model": "sources",
    "assemble_sources": "sources",
    "build_inputs": "sources",
    "fmu_is_stale": "sources",
    "is_source_checkout": "sources",
}

__all__ = ["BuildError", "PlatformSkipped", *_LAZY]


def __getattr__(name: str):
    return _imported_on_first_use(globals(), _LAZY, name)


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
