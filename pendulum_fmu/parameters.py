"""The FMU's parameters and their defaults, read from modelDescription.xml."""

from __future__ import annotations

import math
from functools import lru_cache

from fmpy import read_model_description

from .build import MODEL_DESCRIPTION


@lru_cache(maxsize=1)
def _variables():
    return {v.name: v for v in read_model_description(str(MODEL_DESCRIPTION)).modelVariables}


def value_reference(name: str) -> int:
    return _variables()[name].valueReference


def default_parameters() -> dict[str, float]:
    """{name: start value} of every parameter (mass, length, inertia, gravity, damping)."""
    return {name: float(v.start) for name, v in _variables().items() if v.causality == "parameter"}


def resolve_parameters(overrides: dict[str, float] | None = None) -> dict[str, float]:
    """The defaults with overrides applied; unknown names and non-finite values are refused."""
    parameters = default_parameters()
    for name, value in (overrides or {}).items():
        if name not in parameters:
            raise ValueError(f"unknown parameter {name!r}: the parameters are {', '.join(parameters)}")
        value = float(value)
        if not math.isfinite(value):
            raise ValueError(f"parameter {name} = {value} must be finite")
        parameters[name] = value
    return parameters


def total_inertia(parameters: dict[str, float]) -> float:
    """Moment of inertia about the pivot: the head's own plus mass*length^2 (parallel axes)."""
    return parameters["inertia"] + parameters["mass"] * parameters["length"] ** 2
