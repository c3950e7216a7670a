"""The FMU's variables, parameters and their defaults, read from that FMU's modelDescription.xml.

Every function takes the FMU it is about (a path, a model.FmuModel, or None for
pendulum_fmu.default_fmu()), so another build of the pendulum brings its own parameters; the
model object (_model.py) parses each file once, and a caller that holds one passes it on.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from pathlib import Path

from .._errors import InvalidInput, WrongType
from ._model import FmuModel, fmu_model

Fmu = str | Path | FmuModel | None


def pendulum_variables(fmu_path: Fmu = None) -> dict:
    """variables() of a pendulum FMU this machine can run; raises as default_parameters."""
    return fmu_model(fmu_path).pendulum_variables


def model_description(fmu_path: Fmu = None):
    """Fmpy's ModelDescription of the FMU.

    Raises
    ------
    MissingFile
        No file at fmu_path.
    FmuFileError
        The file is no FMI 2.0 or 3.0 FMU.
    """
    return fmu_model(fmu_path).description


def variables(fmu_path: Fmu = None) -> dict:
    """{name: fmpy ModelVariable} of any FMI 2.0 or 3.0 FMU (shared: do not modify); raises as
    model_description.
    """
    return fmu_model(fmu_path).variables


def value_reference(name: str, fmu_path: Fmu = None) -> int:
    """The value reference of a variable of a pendulum FMU; raises as default_parameters."""
    return fmu_model(fmu_path).value_reference(name)


def unit(name: str, fmu_path: Fmu = None) -> str:
    """The unit the pendulum FMU declares for a variable, a parameter or a start value (theta0:
    theta's), '' where it declares none; raises as default_parameters, KeyError for a name it
    does not have.
    """
    return fmu_model(fmu_path).unit(name)


def default_parameters(fmu_path: Fmu = None) -> dict[str, float]:
    """{name: start value} of every parameter (mass, length, inertia, gravity, damping).

    Raises
    ------
    MissingFile
        No file at fmu_path.
    FmuFileError
        The file is no FMI 2.0 or 3.0 FMU, or not a pendulum (no torque, theta, omega or alpha),
        or has no Co-Simulation binary for this platform.
    """
    return dict(fmu_model(fmu_path).default_parameters)


def merged_parameters(overrides: dict[str, float] | None = None, fmu_path: Fmu = None) -> dict[str, float]:
    """The FMU's defaults with overrides applied; unknown names and non-finite values are refused.
    What the FMU itself refuses is left to it: see simulate.resolve_parameters.
    """
    return merged_with(default_parameters(fmu_path), overrides)


def merged_with(defaults: dict[str, float], overrides: dict[str, float] | None) -> dict[str, float]:
    """merged_parameters over given defaults (an FMU's default_parameters)."""
    parameters = dict(defaults)
    if not isinstance(overrides, Mapping | None):
        raise WrongType(
            f"parameters is a dict {{name: value}}, e.g. {{'gravity': 0}}; got a {type(overrides).__name__}"
        )
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


def total_inertia(parameters: dict[str, float]) -> float:
    """Moment of inertia about the pivot: the head's own plus mass*length^2 (parallel axes).

    Parameters
    ----------
    parameters : dict of str to float
        The pendulum's parameters, with inertia (kg.m^2), mass (kg) and length (m) among them.

    Returns
    -------
    float
        inertia + mass * length**2, in kg.m^2.

    Raises
    ------
    KeyError
        parameters lacks inertia, mass or length.

    Examples
    --------
    The default FMU's pendulum: 20 + 40 * 0.5**2.

    >>> from pendulum_fmu import fmu_model, total_inertia
    >>> total_inertia(fmu_model().default_parameters)
    30.0
    """
    return parameters["inertia"] + parameters["mass"] * parameters["length"] ** 2
