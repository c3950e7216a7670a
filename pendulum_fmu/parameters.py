"""The FMU's variables, parameters and their defaults, read from that FMU's modelDescription.xml.

Every function takes the FMU it is about (default: pendulum_fmu.default_fmu()), so another build
of the pendulum brings its own parameters. Each FMU file is parsed once per version (file_version).
"""

from __future__ import annotations

import math
import os
from functools import lru_cache
from pathlib import Path

from fmpy import read_model_description

# The start values a user gives, and the FMU's variables they start.
START_VALUES = {"theta0": "theta", "omega0": "omega"}


def file_version(path: str | os.PathLike) -> tuple[int, int, int, int]:
    """(device, inode, size, modification time in ns) of a file: a file rebuilt, rewritten or
    replaced has another. FileNotFoundError (with the path) when it is not there."""
    try:
        status = os.stat(path)
    except OSError as error:
        raise FileNotFoundError(f"FMU {path}: {error.strerror}") from None
    return status.st_dev, status.st_ino, status.st_size, status.st_mtime_ns


@lru_cache(maxsize=32)
def _read(path: str, version: tuple):
    description = read_model_description(path)
    return description, {v.name: v for v in description.modelVariables}


def _described(fmu_path: str | Path | None):
    path = _fmu_file(fmu_path)
    return _read(str(path.resolve()), file_version(path))


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
    What the FMU itself refuses is left to it: see resolve_parameters."""
    return merged_with(default_parameters(fmu_path), overrides)


def merged_with(defaults: dict[str, float], overrides: dict[str, float] | None) -> dict[str, float]:
    """merged_parameters over given defaults (an FMU's default_parameters)."""
    parameters = dict(defaults)
    for name, value in (overrides or {}).items():
        if name not in parameters:
            raise ValueError(f"unknown parameter {name!r}: the parameters are {', '.join(parameters)}")
        value = float(value)
        if not math.isfinite(value):
            raise ValueError(f"parameter {name} = {value} must be finite")
        parameters[name] = value
    return parameters


def resolve_parameters(overrides: dict[str, float] | None = None,
                       fmu_path: str | Path | None = None) -> dict[str, float]:
    """merged_parameters, and a set the FMU accepts.

    The physical checks (mass > 0, an inertia about the pivot > 0, ...) live in one place, the
    FMU's model.c, and every tool goes through them here: the FMU, the scipy reference, OpenSim,
    the engines. Each refuses a bad set with the FMU's own message, word for word.
    """
    parameters = merged_parameters(overrides, fmu_path)
    path = _fmu_file(fmu_path)
    refusal = _refusal(str(path.resolve()), file_version(path), tuple(parameters.items()))
    if refusal:
        raise ValueError(refusal)
    return parameters


def _fmu_file(fmu_path: str | Path | None) -> Path:
    if fmu_path is None:
        from . import default_fmu
        return default_fmu()
    return Path(fmu_path)


@lru_cache(maxsize=256)
def _refusal(fmu: str, version: tuple, items: tuple) -> str | None:
    """What the FMU says when it refuses these parameters at initialization, or None."""
    from .simulate import FmuError, open_fmu

    try:
        slave = open_fmu(fmu, parameters=dict(items))
    except FmuError as error:
        # "initialization failed: [ERROR] fmi2ExitInitializationMode: mass must be > 0"
        return f"the FMU refuses the parameters: {str(error).rsplit(': ', 1)[-1]}"
    slave.terminate()
    slave.freeInstance()
    return None


def total_inertia(parameters: dict[str, float]) -> float:
    """Moment of inertia about the pivot: the head's own plus mass*length^2 (parallel axes)."""
    return parameters["inertia"] + parameters["mass"] * parameters["length"] ** 2
