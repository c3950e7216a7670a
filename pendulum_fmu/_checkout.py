"""The checkout this package may sit in, and the repository's build tool there.

The build of the FMU is a tool of the repository (fmu_build/ beside this package, run as
`python build_fmu.py`), not part of the installed package. In a clone, an editable install or the
unpacked sdist the package still rebuilds a stale dist/Pendulum.fmu and builds the PID controller
through that tool: it loads fmu_build/ from the folder above the package by its file location,
because that folder need not be on sys.path (an editable install maps only the package).
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

from . import FMU_FILES

ROOT = Path(__file__).resolve().parent.parent
BUILD_TOOL = ROOT / "fmu_build" / "__init__.py"
# FMI version -> the FMU a checkout builds and runs when none is named (the build tool's too):
# here, so that the build command's help names them without importing the build tool's sources.
CHECKOUT_FMUS = {version: ROOT / "dist" / name for version, name in FMU_FILES.items()}
# What a checkout has beside the package and an installed package has not.
CHECKOUT_MARKERS = (BUILD_TOOL, ROOT / "modelDescription.xml", ROOT / "CMakeLists.txt", ROOT / "fmu_src")


def is_source_checkout() -> bool:
    """Whether this package sits in a checkout with the FMU's sources and build tool.

    A clone, an editable install or the sdist being built is one; a package installed from a wheel
    is not.
    """
    return all(path.exists() for path in CHECKOUT_MARKERS)


def build_tool():
    """The checkout's build tool, the module fmu_build, imported once.

    Returns
    -------
    module
        fmu_build of this checkout (the one already imported when it is this checkout's).

    Raises
    ------
    BuildError
        When this package is not in a checkout.
    """
    loaded = sys.modules.get("fmu_build")
    if loaded is not None and loaded.__file__ and Path(loaded.__file__).resolve() == BUILD_TOOL:
        return loaded
    if not is_source_checkout():
        from ._errors import BuildError

        raise BuildError(
            f"pendulum_fmu at {ROOT / 'pendulum_fmu'} is installed, not in a checkout: building "
            "needs the repository (python build_fmu.py in a clone or the unpacked sdist)"
        )
    spec = importlib.util.spec_from_file_location(
        "fmu_build", BUILD_TOOL, submodule_search_locations=[str(BUILD_TOOL.parent)]
    )
    assert spec is not None and spec.loader is not None  # a .py file always has both
    module = importlib.util.module_from_spec(spec)
    sys.modules["fmu_build"] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules["fmu_build"]
        raise
    return module
