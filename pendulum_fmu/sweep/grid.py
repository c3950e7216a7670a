"""The cases of a study: a grid of every combination of some values, or a list of dicts.

A case is {'torque': .., <parameter or start value>: ..}. A grid is computed when asked, so a
million cases cost only their axes; a list is checked case by case.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping, Sequence

import numpy as np

from .._errors import InvalidInput, WrongType
from ..fmu._model import START_VALUES
from ..fmu._parameters import default_parameters


def sweepable(fmu_path=None) -> list[str]:
    """The names a case may set: the torque, the FMU's parameters and the start values."""
    return ["torque", *default_parameters(fmu_path), *START_VALUES]


def _extra_names() -> list[str]:
    return [name for name in sweepable() if name not in ("torque", "gravity")]


def _values(name: str, values) -> np.ndarray:
    try:
        array = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise InvalidInput(f"{name} values must be numbers, got {values!r}") from None
    if array.ndim != 1:
        raise InvalidInput(f"{name} values must be a flat list of numbers, got {values!r}")
    if array.size == 0:
        raise InvalidInput(f"no values given for {name}")
    if not np.all(np.isfinite(array)):
        raise InvalidInput(f"{name} values must be finite, got {array[~np.isfinite(array)][0]}")
    if len(np.unique(array)) < array.size:
        raise InvalidInput(f"{name} values repeat: {values!r}")
    return array


class Grid(Sequence):
    """Every combination of the axes' values as a sequence of cases ({name: value} dicts), in
    itertools.product order, computed when asked: a grid of a million cases costs its axes.
    """

    def __init__(self, axes: dict[str, np.ndarray]):
        self.axes = axes
        self._shape = tuple(len(values) for values in axes.values())

    def __len__(self) -> int:
        return math.prod(self._shape)

    def __getitem__(self, index):
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(len(self)))]
        number = index + len(self) if index < 0 else index
        if not 0 <= number < len(self):
            raise IndexError(f"case {index} of a grid of {len(self)}")
        return {name: float(column[0]) for name, column in self.columns(number, number + 1).items()}

    def columns(self, start: int, stop: int) -> dict[str, np.ndarray]:
        """The values of cases start..stop-1, one array per name."""
        positions = np.unravel_index(np.arange(start, stop), self._shape)
        return {name: values[p] for (name, values), p in zip(self.axes.items(), positions, strict=False)}


def sweep_grid(torques, gravities=(9.81,), extra: dict | None = None) -> Grid:
    """Every combination of the torques, gravities and extra values, as a sequence of cases.

    Parameters
    ----------
    torques : sequence of float
        The torques in N.m.
    gravities : sequence of float, optional
        The gravities in m/s2 (default: 9.81 alone).
    extra : dict, optional
        {name: [values, ...]} for the parameters mass, length, inertia, damping and the start
        values theta0, omega0.

    Returns
    -------
    Grid
        The cases, each a dict {'torque': .., 'gravity': .., <extra names>: ..}, in
        itertools.product order.

    Raises
    ------
    InvalidInput
        A name that cannot be swept, or values that are no flat list of distinct finite numbers.

    Examples
    --------
    >>> from pendulum_fmu import sweep_grid
    >>> grid = sweep_grid([5, 10], [0, 9.81], {"damping": [0.0, 0.5]})
    >>> len(grid), grid[0]
    (8, {'torque': 5.0, 'gravity': 0.0, 'damping': 0.0})
    """
    if not isinstance(extra, Mapping | None):
        raise WrongType(
            f"extra is a dict {{name: [values, ...]}}, e.g. {{'damping': [0, 0.5]}}; got a {type(extra).__name__}"
        )
    extra = dict(extra or {})
    # Looked up only for extra values to check: a grid of torques and gravities alone leaves the
    # default FMU alone (in a checkout its staleness check and its reading, ~15 ms of the start of
    # a study given an FMU of its own).
    extra_names = _extra_names() if extra else []
    for name in extra:
        if name in ("torque", "gravity"):
            argument = {"torque": "torques", "gravity": "gravities"}[name]
            raise InvalidInput(f"give {name} values as the {argument} argument, not in extra")
        if name not in extra_names:
            raise InvalidInput(f"cannot sweep {name!r}: extra takes {', '.join(extra_names)}")
    axes = {"torque": torques, "gravity": gravities, **extra}
    return Grid({name: _values(name, values) for name, values in axes.items()})


def check_cases(cases, fmu_path=None) -> list[str]:
    """The cases' common keys, which become the cases table's value columns; InvalidInput for
    cases that are not all alike, finite and distinct.
    """
    names_allowed = sweepable(fmu_path)  # refuses a file that is no pendulum FMU, first
    seen: dict[tuple, int] = {}
    if isinstance(cases, Grid):
        return list(cases.axes)  # checked when the grid was made
    if not cases:
        raise InvalidInput("no cases to run")
    if isinstance(cases, str | Mapping) or not isinstance(cases, Sequence):
        raise WrongType(f"cases are sweep_grid(...) or a list of dicts {{'torque': ..}}; got a {type(cases).__name__}")
    for number, case in enumerate(cases):
        if not isinstance(case, Mapping):
            raise WrongType(f"case {number} is {case!r}, not a dict {{'torque': .., <parameter or start value>: ..}}")
    names = list(cases[0])
    if "torque" not in names:
        raise InvalidInput("every case needs a 'torque'")
    for number, case in enumerate(cases):
        if list(case) != names:
            raise InvalidInput(f"case {number} has keys {list(case)}; every case needs {names}")
        for name, value in case.items():
            if name not in names_allowed:
                raise InvalidInput(f"cannot sweep {name!r}: choose from {', '.join(names_allowed)}")
            if not isinstance(value, numbers.Real) or not math.isfinite(value):
                raise InvalidInput(f"case {number}: {name} = {value!r} must be a finite number")
        # A repeat would only cost time, and share the first one's line in the figure.
        first = seen.setdefault(tuple(case.values()), number)
        if first != number:
            raise InvalidInput(f"case {number} repeats case {first}")
    return names


def columns(cases, names: list[str], start: int, stop: int) -> dict[str, np.ndarray]:
    """The values of cases start..stop-1, one array per name."""
    if isinstance(cases, Grid):
        return cases.columns(start, stop)
    return {name: np.array([case[name] for case in cases[start:stop]], float) for name in names}
