"""A torque-driven pendulum as an FMI 2.0 Co-Simulation FMU, and the tools to compare it.

The API is this package's names; each is imported from its module on first use, so that
``import pendulum_fmu`` loads neither numpy, fmpy, scipy, matplotlib nor dask::

    from pendulum_fmu import compare, default_fmu, judge, reference, run_sweep, simulate, Study

Four of the names are also the names of the modules that hold them (simulate, reference, compare,
judge): ``pendulum_fmu.simulate`` is the function; the module is ``import_module("pendulum_fmu.simulate")``,
and ``from pendulum_fmu.simulate import ...`` works as ever.
"""

import sys
import types

# The package version's one source: pyproject.toml reads it, the FMU's generationTool carries it.
__version__ = "0.1.0"

# Nothing else is imported here at import time, not even the standard library's
# importlib.resources: the program (pendulum_fmu.entry) sets its signal handlers as soon as this
# package is loaded, before anything that takes a noticeable time.

# The public name -> the module that holds it, imported on first use (__getattr__ below).
_LAZY = {
    "simulate": "simulate",
    "reference": "reference",
    "compare": "compare",
    "Comparison": "compare",
    "judge": "judge",
    "judge_kit": "judge",
    "Judgement": "judge",
    "run_sweep": "sweep",
    "sweep_grid": "sweep",
    "Study": "sweep",
    "SweepResult": "sweep",
    "write_scenarios": "scenarios",
    "PendulumFmuError": "errors",
}
__all__ = ["FMU_FILES", "__version__", "default_fmu", *_LAZY]


def __getattr__(name: str):
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    from importlib import import_module

    value = getattr(import_module(f"{__name__}.{module}"), name)
    globals()[name] = value  # found here from now on, without this function
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})


class _Package(types.ModuleType):
    """The package's module type, which keeps its functions from being hidden by their modules.

    The import system sets every submodule it loads as an attribute of its package: for the modules
    named like the function they hold, ``pendulum_fmu.simulate`` would be the module after any
    ``import pendulum_fmu.simulate``.
    """

    def __setattr__(self, name: str, value) -> None:
        if name in _LAZY and isinstance(value, types.ModuleType):
            return
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package

# FMI version -> the FMU's file name, in a checkout's dist/ and in the installed package's data/:
# the one list of the FMI versions this package builds.
FMU_FILES = {2: "Pendulum.fmu", 3: "Pendulum-fmi3.fmu"}
# Holds open the real files of packaged FMUs that importlib.resources had to extract (a zipped
# install); a plain install hands out the files themselves. Made on first use.
_extracted = None


def default_fmu(fmi_version: int = 2):
    """The FMU this package runs when none is named.

    In a source checkout (a clone or an editable install): dist/Pendulum.fmu, rebuilt first when
    any of its sources is newer, by the repository's build tool (fmu_build/, found beside the
    package). In an installed package: the FMU packaged with it. Nothing is
    ever written into site-packages.

    Parameters
    ----------
    fmi_version : {2, 3}, optional
        The FMI standard of the FMU.

    Returns
    -------
    Path
        The FMU file.

    Raises
    ------
    InvalidInput
        An FMI version the package does not build.
    MissingFile
        An installed package without its packaged FMU.
    BuildError
        A checkout whose FMU is stale and cannot be rebuilt here.

    Examples
    --------
    >>> from pendulum_fmu import default_fmu
    >>> default_fmu().name
    'Pendulum.fmu'
    """
    global _extracted
    import atexit
    import contextlib
    from importlib import resources
    from pathlib import Path

    from ._checkout import build_tool, is_source_checkout
    from .errors import InvalidInput, MissingFile

    if fmi_version not in FMU_FILES:
        raise InvalidInput(f"no FMI {fmi_version} FMU: the FMI versions are {', '.join(map(str, FMU_FILES))}")
    packaged_name = FMU_FILES[fmi_version]
    if is_source_checkout():
        build = build_tool()
        checkout_fmu = build.CHECKOUT_FMUS[fmi_version]
        if build.fmu_is_stale(checkout_fmu):
            build.build_fmu(checkout_fmu, fmi_version=fmi_version)
        return checkout_fmu
    packaged = resources.files(__name__) / "data" / packaged_name
    if not packaged.is_file():
        raise MissingFile(
            f"pendulum_fmu {__version__} at {Path(__file__).parent} has neither its packaged "
            f"data/{packaged_name} nor the FMU's sources beside it: reinstall it from its wheel or "
            "sdist, or pass the FMU's path"
        )
    if _extracted is None:
        _extracted = contextlib.ExitStack()
        atexit.register(_extracted.close)
    return _extracted.enter_context(resources.as_file(packaged))
