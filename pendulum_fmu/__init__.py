"""A torque-driven pendulum as an FMI 2.0 Co-Simulation FMU, and the tools to compare it.

The API is this package's names. Its folders are its jobs, bottom up: signals/, fmu/, oracle/,
engines/, figures/, sweep/, comparing/, scenarios/, judging/, ssp/, cli/ (each one's docstring
says what it may import; docs/layout.md draws them); the modules in them are private. Each
name is imported from its module on first use, so that ``import pendulum_fmu`` loads neither
numpy, fmpy, matplotlib nor dask::

    from pendulum_fmu import compare, default_fmu, judge, reference, run_sweep, simulate, Study
"""

# The package version's one source: pyproject.toml reads it, the FMU's generationTool carries it.
__version__ = "0.1.0"

# Nothing else is imported here at import time, not even the standard library's
# importlib.resources: the program (pendulum_fmu._entry) sets its signal handlers as soon as this
# package is loaded, before anything that takes a noticeable time.

# The public name -> the private module that holds it, imported on first use (__getattr__ below).
_LAZY = {
    # running the FMU
    "simulate": "fmu._simulate",
    "open_fmu": "fmu._instance",
    "FmuError": "fmu._instance",
    "fmu_model": "fmu._model",
    "FmuModel": "fmu._model",
    "FmuInstance": "fmu._instance",
    "FmuFileError": "fmu._model",
    "total_inertia": "fmu._parameters",
    # control: the FMU linearised from its own directional derivatives
    "linearize": "fmu._linearize",
    "Linearization": "fmu._linearize",
    # torque signals
    "schedule": "signals._torque_schedule",
    "TorqueSchedule": "signals._torque_schedule",
    "write_torque_csv": "signals._schedule_csv",
    "TorqueFileError": "signals._torque_csv",
    # references and comparisons
    "reference": "oracle._reference",
    "reference_schedule": "oracle._reference",
    "compare": "comparing._compare",
    "Comparison": "comparing._compare",
    "format_table": "comparing._compare",
    "list_tools": "comparing._compare_tools",
    "plot_overlay": "figures._plot",
    # judging a master's result, and the kit of scenarios to judge
    "judge": "judging._judge",
    "judge_kit": "judging._judge",
    "judge_results": "judging._judge",
    "Judgement": "judging._judgement",
    "ResultFileError": "judging._result_file",
    "write_scenarios": "scenarios._scenarios",
    "read_settings": "scenarios._scenario_settings",
    # sweeps
    "run_sweep": "sweep",
    "sweep_grid": "sweep",
    "Study": "sweep",
    "SweepResult": "sweep",
    "tls_files": "sweep",
    "close_kept_clusters": "sweep",
    # what a user hands on: the FMU, the closed loop, the SSP
    "export_fmu": "fmu._export",
    "create_closed_loop_fmu": "ssp._closed_loop",
    "export_ssp": "ssp._ssp",
    # errors and warnings
    "PendulumFmuError": "_errors",
    "InvalidInput": "_errors",
    "WrongType": "_errors",
    "MissingFile": "_errors",
    "CannotWrite": "_errors",
    "MissingDependency": "_errors",
    "BuildError": "_errors",
    "PlatformSkipped": "_errors",
    "NotComputed": "_errors",
    "Clipped": "_errors",
    "Skipped": "_errors",
    "UnencryptedScheduler": "_errors",
}
__all__ = ["FMU_FILES", "__version__", "default_fmu", *_LAZY]


def _imported_on_first_use(namespace: dict, lazy: dict[str, str], name: str):
    """The value of name in a package whose names are imported on first use (this one, the
    repository's fmu_build): namespace is the package's globals, lazy its name -> module table
    (the module relative to the package). Kept in namespace, found there from then on.
    """
    module = lazy.get(name)
    if module is None:
        raise AttributeError(f"module {namespace['__name__']!r} has no attribute {name!r}")
    from importlib import import_module

    value = getattr(import_module(f"{namespace['__name__']}.{module}"), name)
    namespace[name] = value  # found there from now on, without the package's __getattr__
    return value


def __getattr__(name: str):
    return _imported_on_first_use(globals(), _LAZY, name)


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})


# FMI version -> the FMU's file name, in a checkout's dist/ and in the installed package's data/:
# the one list of the FMI versions this package builds.
FMU_FILES = {2: "Pendulum.fmu", 3: "Pendulum-fmi3.fmu"}
# The PID controller FMU that closes the loop around the pendulum (FMI 2.0), beside them: what
# export-ssp and the closed loop's tools hand a master.
CONTROLLER_FMU_FILE = "PIDController.fmu"
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
    from ._checkout import build_tool, is_source_checkout
    from ._errors import InvalidInput

    if fmi_version not in FMU_FILES:
        raise InvalidInput(f"no FMI {fmi_version} FMU: the FMI versions are {', '.join(map(str, FMU_FILES))}")
    if is_source_checkout():
        build = build_tool()
        checkout_fmu = build.CHECKOUT_FMUS[fmi_version]
        if build.fmu_is_stale(checkout_fmu):
            build.build_fmu(checkout_fmu, fmi_version=fmi_version)
        return checkout_fmu
    return _packaged_file(FMU_FILES[fmi_version])


def _packaged_file(name: str):
    """The real file of data/NAME packaged with an installed package; MissingFile when it is not there."""
    global _extracted
    import atexit
    import contextlib
    from importlib import resources
    from pathlib import Path

    from ._errors import MissingFile

    packaged = resources.files(__name__) / "data" / name
    if not packaged.is_file():
        raise MissingFile(
            f"pendulum_fmu {__version__} at {Path(__file__).parent} has neither its packaged "
            f"data/{name} nor the FMU's sources beside it: reinstall it from its wheel or "
            "sdist, or pass the FMU's path"
        )
    if _extracted is None:
        _extracted = contextlib.ExitStack()
        atexit.register(_extracted.close)
    return _extracted.enter_context(resources.as_file(packaged))
