"""The FMU's variables, parameters and their defaults, read from that FMU's modelDescription.xml.

Every function takes the FMU it is about (default: pendulum_fmu.default_fmu()), so another build
of the pendulum brings its own parameters. Each FMU file is parsed once per modification time.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from functools import lru_cache
from pathlib import Path

from fmpy import read_model_description

from .errors import InvalidInput, MissingFile, WrongType

# The start values a user gives, and the FMU's variables they start.
START_VALUES = {"theta0": "theta", "omega0": "omega"}


@lru_cache(maxsize=32)
def _read(path: str, modified_ns: int):
    description = read_model_description(path)
    return description, {v.name: v for v in description.modelVariables}


def _described(fmu_path: str | Path | None):
    path = fmu_file(fmu_path)
    try:
        modified_ns = path.stat().st_mtime_ns
    except OSError as error:
        raise MissingFile(f"FMU {path}: {error.strerror}") from None
    try:
        return _read(str(path.resolve()), modified_ns)
    except Exception as error:  # fmpy's, whatever the file is instead: no zip, no or bad XML
        raise InvalidInput(f"FMU {path} cannot be read: {error}; pass an FMI 2.0 or 3.0 FMU "
                           "file") from None


def model_description(fmu_path: str | Path | None = None):
    """fmpy's ModelDescription of the FMU."""
    return _described(fmu_path)[0]


def variables(fmu_path: str | Path | None = None) -> dict:
    """{name: fmpy ModelVariable} of the FMU (shared: do not modify)."""
    return _described(fmu_path)[1]


def value_reference(name: str, fmu_path: str | Path | None = None) -> int:
    return variables(fmu_path)[name].valueReference


def default_parameters(fmu_path: str | Path | None = None) -> dict[str, float]:
    """{name: start value} of every parameter (mass, length, inertia, gravity, damping)."""
    return {name: float(v.start) for name, v in variables(fmu_path).items() if v.causality == "parameter"}


def merged_parameters(overrides: dict[str, float] | None = None,
                      fmu_path: str | Path | None = None) -> dict[str, float]:
    """The FMU's defaults with overrides applied; unknown names and non-finite values are refused.
    What the FMU itself refuses is left to it: see simulate.resolve_parameters."""
    parameters = default_parameters(fmu_path)
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
    return Path(fmu_path)


def total_inertia(parameters: dict[str, float]) -> float:
    """Moment of inertia about the pivot: the head's own plus mass*length^2 (parallel axes)."""
    return parameters["inertia"] + parameters["mass"] * parameters["length"] ** 2
