"""What a Gymnasium environment over the FMU is made with: the make keywords checked, and the batch
of FMU instances they start.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .._errors import InvalidInput, WrongType
from ..fmu._batch import FmuBatch
from ..fmu._model import FmuModel, fmu_model
from ..fmu._parameters import merged_with
from ._conventions import PENDULUM_V1_PARAMETERS, fmu_angle

# The most environments one vector environment holds: each is an FMU instance of a few kB and a
# row of every buffer; past this a typo (an extra zero or three) would take the machine's memory.
MAX_ENVS = 1_000_000
# The most threads one vector environment starts.
MAX_THREADS = 1024


@dataclass(frozen=True)
class Settings:
    """An environment's make keywords, checked: the FMU and its parameters, the torque limit (N.m),
    the communication step (s), the episode length (steps; None where Gymnasium's TimeLimit
    counts them) and the FMU's relative tolerance.
    """

    model: FmuModel
    parameters: dict[str, float]
    max_torque: float
    dt: float
    max_episode_steps: int | None
    tolerance: float | None

    def batch(self, size: int, threads: int = 1) -> FmuBatch:
        """A batch of size FMU instances at this setting, each restarted at rest upright, so that the FMU has
        checked the parameters and tolerance before an episode starts.

        Raises
        ------
        FmuError
            The FMU refused the parameters or the tolerance (its message).
        """
        batch = FmuBatch(
            self.model,
            size,
            start_names=(*self.parameters, "theta", "omega"),
            input_names=("torque",),
            output_names=("theta", "omega"),
            step_size=self.dt,
            tolerance=self.tolerance,
            threads=threads,
        )
        try:
            batch.start_values[:, : len(self.parameters)] = list(self.parameters.values())
            batch.start_values[:, -2:] = (fmu_angle(0.0), 0.0)
            batch.advance()
        except BaseException:
            batch.close()
            raise
        return batch


def settings(
    *,
    fmu: str | Path | FmuModel | None,
    max_torque: Any,
    dt: Any,
    max_episode_steps: Any,
    tolerance: Any,
    parameters: dict[str, Any],
) -> Settings:
    """The Settings of make keywords; InvalidInput (one line) for any the environment refuses."""
    model = fmu_model(fmu)
    if model.fmi_version != 2:
        raise InvalidInput(f"fmu {model.path} is an FMI {model.fmi_version} FMU: the environment runs FMI 2.0 FMUs")
    unknown = sorted(set(parameters) - set(model.default_parameters))
    if unknown:
        raise InvalidInput(
            f"unknown keyword {unknown[0]!r}: the keywords are the FMU's parameters "
            f"({', '.join(model.default_parameters)}), max_torque, dt, max_episode_steps, tolerance, fmu"
        )
    defaults = {name: PENDULUM_V1_PARAMETERS.get(name, value) for name, value in model.default_parameters.items()}
    return Settings(
        model=model,
        parameters=merged_with(defaults, parameters),
        max_torque=positive("max_torque", max_torque, "N.m"),
        dt=positive("dt", dt, "s"),
        max_episode_steps=None if max_episode_steps is None else count("max_episode_steps", max_episode_steps, 2**62),
        tolerance=None if tolerance is None else positive("tolerance", tolerance, ""),
    )


def positive(name: str, value: Any, unit: str) -> float:
    """The value as a float; InvalidInput unless it is a positive finite number."""
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        raise WrongType(f"{name} = {value!r} is not a number")
    if not (math.isfinite(value) and value > 0):
        raise InvalidInput(f"{name} = {value}{' ' + unit if unit else ''} must be positive and finite")
    return float(value)


def count(name: str, value: Any, most: int) -> int:
    """The value as an int; InvalidInput unless it is a whole number from 1 to most."""
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise WrongType(f"{name} = {value!r} is not a whole number")
    if not 1 <= value <= most:
        raise InvalidInput(f"{name} = {value} must be from 1 to {most:,}")
    return int(value)
