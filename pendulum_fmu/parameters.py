"""The FMU's variables, parameters and their defaults, read from that FMU's modelDescription.xml.

Every function takes the FMU it is about (default: pendulum_fmu.default_fmu()), so another build
of the pendulum brings its own parameters. Each FMU file is parsed once per modification time,
and this is where every FMU a user names is first opened: a file that is no FMI 2.0 or 3.0 FMU
is refused here with FmuFileError, and one that is not a pendulum wherever the pendulum's
variables are asked for.
"""

from __future__ import annotations

import math
import numbers
import os
import zipfile
from collections.abc import Mapping
from functools import lru_cache
from pathlib import Path

import fmpy
from fmpy import read_model_description

from .errors import InvalidInput, MissingFile, WrongType

# The start values a user gives, and the FMU's variables they start.
START_VALUES = {"theta0": "theta", "omega0": "omega"}
# What every tool reads from or writes to a pendulum FMU.
PENDULUM_VARIABLES = ("torque", "theta", "omega", "alpha")
FMI_VERSIONS = ("2.0", "3.0")


class FmuFileError(InvalidInput):
    """The file given as an FMU is none this package can run: not a zip, no modelDescription.xml,
    not FMI 2.0 or 3.0, or not a pendulum; the message names the file and what to do."""


def file_version(path: str | os.PathLike) -> tuple[int, int, int, int]:
    """(device, inode, size, modification time in ns) of a file: a file rebuilt, rewritten or
    replaced has another. MissingFile (with the path) when it is not there."""
    try:
        status = os.stat(path)
    except OSError as error:
        raise MissingFile(f"FMU {path}: {error.strerror}") from None
    return status.st_dev, status.st_ino, status.st_size, status.st_mtime_ns


@lru_cache(maxsize=32)
def _read(path: str, modified_ns: int, shown: str):
    """(model description, {name: variable}, the archive's file names) of the FMU at path; shown
    is the path as the user gave it, for the messages."""
    try:
        with zipfile.ZipFile(path) as archive:
            names = frozenset(archive.namelist())
    except (zipfile.BadZipFile, OSError):
        raise FmuFileError(f"{shown} is not an FMU (an FMU is a zip archive with a "
                           "modelDescription.xml): check the path") from None
    if "modelDescription.xml" not in names:
        raise FmuFileError(f"{shown} is not an FMU: the zip archive has no modelDescription.xml"
                           + ("" if names else " (it is empty)"))
    try:
        description = read_model_description(path)
    except Exception as error:  # lxml's and fmpy's own: the XML is broken or invalid
        # fmpy lists its validation problems one per line: one line here.
        problems = "; ".join(line.strip(" -") for line in str(error).splitlines() if line.strip(" -"))
        raise FmuFileError(f"{shown}: its modelDescription.xml cannot be read: {problems}") from None
    if description.fmiVersion not in FMI_VERSIONS:
        raise FmuFileError(f"{shown} is an FMI {description.fmiVersion} FMU; this package runs "
                           "FMI 2.0 and 3.0 FMUs: export the model as one of those")
    return description, {v.name: v for v in description.modelVariables}, names


def _described(fmu_path: str | Path | None):
    path = fmu_file(fmu_path)
    try:
        modified_ns = path.stat().st_mtime_ns
    except OSError as error:
        raise MissingFile(f"FMU {path}: {error.strerror}") from None
    return _read(str(path.resolve()), modified_ns, str(path))


def pendulum_variables(fmu_path: str | Path | None = None) -> dict:
    """variables() of a pendulum FMU this machine can run; raises as default_parameters."""
    description, found, names = _described(fmu_path)
    path = fmu_file(fmu_path)
    missing = [name for name in PENDULUM_VARIABLES if name not in found]
    if missing:
        raise FmuFileError(f"{path} is not a pendulum FMU: it has no variable {', '.join(missing)} "
                           f"(it is the model {description.modelName!r}); give the pendulum's FMU, "
                           "or compare another model with compare --tools LABEL=path --map")
    if description.coSimulation is None:
        raise FmuFileError(f"{path} has no Co-Simulation interface, which this package runs: "
                           "export it for Co-Simulation")
    folder = fmpy.platform_tuple if description.fmiVersion == "3.0" else fmpy.platform
    binary = f"binaries/{folder}/{description.coSimulation.modelIdentifier}{fmpy.sharedLibraryExtension}"
    if binary not in names:
        raise FmuFileError(f"{path} has no binary for this platform ({binary}): build it here with "
                           "pendulum-fmu build, or give an FMU built for this platform")
    return found


def model_description(fmu_path: str | Path | None = None):
    """fmpy's ModelDescription of the FMU.

    Raises
    ------
    MissingFile
        No file at fmu_path.
    FmuFileError
        The file is no FMI 2.0 or 3.0 FMU.
    """
    return _described(fmu_path)[0]


def variables(fmu_path: str | Path | None = None) -> dict:
    """{name: fmpy ModelVariable} of any FMI 2.0 or 3.0 FMU (shared: do not modify); raises as
    model_description."""
    return _described(fmu_path)[1]


def value_reference(name: str, fmu_path: str | Path | None = None) -> int:
    """The value reference of a variable of a pendulum FMU; raises as default_parameters."""
    return pendulum_variables(fmu_path)[name].valueReference


def unit(name: str, fmu_path: str | Path | None = None) -> str:
    """The unit the pendulum FMU declares for a variable, a parameter or a start value (theta0:
    theta's), '' where it declares none; raises as default_parameters, KeyError for a name it
    does not have."""
    return pendulum_variables(fmu_path)[START_VALUES.get(name, name)].unit or ""


def default_parameters(fmu_path: str | Path | None = None) -> dict[str, float]:
    """{name: start value} of every parameter (mass, length, inertia, gravity, damping).

    Raises
    ------
    MissingFile
        No file at fmu_path.
    FmuFileError
        The file is no FMI 2.0 or 3.0 FMU, or not a pendulum (no torque, theta, omega or alpha),
        or has no Co-Simulation binary for this platform.
    """
    return {name: float(v.start) for name, v in pendulum_variables(fmu_path).items() if v.causality == "parameter"}


def merged_parameters(overrides: dict[str, float] | None = None,
                      fmu_path: str | Path | None = None) -> dict[str, float]:
    """The FMU's defaults with overrides applied; unknown names and non-finite values are refused.
    What the FMU itself refuses is left to it: see simulate.resolve_parameters."""
    return merged_with(default_parameters(fmu_path), overrides)


def merged_with(defaults: dict[str, float], overrides: dict[str, float] | None) -> dict[str, float]:
    """merged_parameters over given defaults (an FMU's default_parameters)."""
    parameters = dict(defaults)
    if not isinstance(overrides, Mapping | None):
        raise WrongType(f"parameters is a dict {{name: value}}, e.g. {{'gravity': 0}}; got a "
                        f"{type(overrides).__name__}")
    for name, value in (overrides or {}).items():
        if name not in parameters:
            raise InvalidInput(f"unknown parameter {name!r}: the parameters are {', '.join(parameters)}")
        if not isinstance(value, numbers.Real):
            raise InvalidInput(f"parameter {name} = {value!r} is not a number")
        value = float(value)
        if not math.isfinite(value):
            raise InvalidInput(f"parameter {name} = {value} must be finite")
        parameters[name] = value
    return parameters


def start_value(name: str, value, unit: str) -> float:
    """theta0 or omega0 as a float; InvalidInput unless it is a finite number."""
    if not (isinstance(value, numbers.Real) and math.isfinite(value)):
        raise InvalidInput(f"{name} = {value!r} must be a finite number of {unit}")
    return float(value)


def fmu_file(fmu_path: str | Path | None) -> Path:
    """The FMU file a function here is about: fmu_path, or pendulum_fmu.default_fmu()."""
    if fmu_path is None:
        from . import default_fmu
        return default_fmu()
    # bool and int would pass for a file descriptor, which is no FMU's path.
    if not isinstance(fmu_path, (str, os.PathLike)):
        raise WrongType(f"fmu_path is the FMU file's path (a str or Path), not {fmu_path!r}")
    return Path(fmu_path)


def total_inertia(parameters: dict[str, float]) -> float:
    """Moment of inertia about the pivot: the head's own plus mass*length^2 (parallel axes)."""
    return parameters["inertia"] + parameters["mass"] * parameters["length"] ** 2
