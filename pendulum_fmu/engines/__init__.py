"""Robotics physics engines as compare tools: one module per engine, each with the same runner.

    run(plan, *, parameters, theta0, omega0, mode="accurate", fmu_path=None) -> results array

Every runner builds the pendulum of the FMU (mass, length, inertia of the head about its own
centre, gravity, damping) in its engine, holds plan.torque[k] over step k, and fills the outputs
it computes (theta, omega, alpha) in a results.empty(N+1) array with the convention of _results.py;
an output of the FMU it does not compute stays NaN. fmu_path (a path, a model or None) is the FMU
whose defaults fill the parameters not given. mode "accurate" sets the engine's
best integrator tight; "default" keeps the engine's own integrator and settings, stepping once per
communication step, so a comparison shows the price of the defaults. docs/engines.md says what
each adapter sets and why. The engine modules import their engine, so import them only when used.

Gymnasium's and EnvPool's Pendulum-v1 (gymnasium.py, envpool.py) are tools here too, with one
mode, their own; _pendulum_v1.py maps the FMU's parameters onto their rod and says when their
clips bite.

May import: fmu/, signals/ and the basics. Not the reference: an engine is held to it, in tests.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from .._errors import InvalidInput
from ..fmu import _results as results
from ..fmu._model import FmuModel
from ..fmu._simulate import resolve_parameters
from ..signals._torque_schedule import TorqueSchedule

MODES = ("accurate", "default")


class ToolCannotRamp(InvalidInput):
    """A tool that holds the torque over a step was given a ramped schedule."""


def check_held(plan: TorqueSchedule, tool: str) -> None:
    """Refuse a schedule whose torque ramps within a step: the tool can only hold it."""
    if np.any(plan.torque_rate):
        raise ToolCannotRamp(
            f"{tool} holds the torque over each step and cannot ramp it: compare "
            f"held torques only (no --ramp), or leave {tool} out of --tools"
        )


def check_mode(mode: str, tool: str, modes: tuple[str, ...] = MODES) -> None:
    """InvalidInput unless mode is one of the tool's modes (MODES unless told)."""
    if mode not in modes:
        raise InvalidInput(f"{tool}: unknown mode {mode!r}; choose {' or '.join(modes)}")


def substeps(step_size: np.ndarray, largest: float) -> np.ndarray:
    """For each communication step, the number of equal substeps no longer than largest."""
    return np.maximum(1, np.ceil(step_size / largest * (1 - 1e-12))).astype(int)


def held_results(plan: TorqueSchedule) -> np.ndarray:
    """A result array with the times and held torques of a schedule filled in; the last row
    repeats the last step's torque.
    """
    out = results.empty(len(plan.time))
    out["time"] = plan.time
    out["torque"][:-1] = plan.torque
    out["torque"][-1] = plan.torque[-1]
    return out


def runner(tool: str, simulate: Callable[..., np.ndarray], setups: dict) -> Callable[..., np.ndarray]:
    """The uniform run() of an engine module from its simulate(plan, parameters, theta0, omega0,
    setup) and its setup per mode (its modes: setups' keys).
    """

    def run(
        plan: TorqueSchedule,
        *,
        parameters: dict | None = None,
        theta0: float = 0.0,
        omega0: float = 0.0,
        mode: str = "accurate",
        fmu_path: str | Path | FmuModel | None = None,
    ) -> np.ndarray:
        check_held(plan, tool)
        check_mode(mode, tool, tuple(setups))
        return simulate(plan, resolve_parameters(parameters, fmu_path), theta0, omega0, setups[mode])

    run.__doc__ = f"The schedule through {tool} in mode {' or '.join(setups)}; see docs/engines.md."
    return run
