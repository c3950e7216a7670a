"""PendulumFmuEnv: Gymnasium's Pendulum-v1 with the FMU's exact pendulum in place of its Euler step."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces

from .._errors import InvalidInput
from ..fmu._batch import RESTART
from ..fmu._model import FmuModel
from ._conventions import DT, MAX_TORQUE, checked_torque, draw_state, fmu_angle, observation, reset_bounds, rewards
from ._settings import settings


def observation_space() -> spaces.Box:
    """[cos theta, sin theta, omega]: float64, omega unbounded (the FMU clips no speed)."""
    high = np.array([1.0, 1.0, np.inf])
    return spaces.Box(low=-high, high=high, dtype=np.float64)


def action_space(max_torque: float) -> spaces.Box:
    """The torque in N.m, as Pendulum-v1's (float32, shape (1,))."""
    return spaces.Box(low=-max_torque, high=max_torque, shape=(1,), dtype=np.float32)


class PendulumFmuEnv(gymnasium.Env):
    """Gymnasium's Pendulum-v1 over the FMU: the same observation, action, reward, reset and step,
    the pendulum integrated by the FMU (FMI 2.0 Co-Simulation) to its tolerance.

    Made by ``gymnasium.make("pendulum_fmu.gym:PendulumFMU-v0", **keywords)``, which adds
    Gymnasium's TimeLimit at 200 steps (its ``max_episode_steps`` keyword changes it), as for
    Pendulum-v1. The FMU is instantiated once; a reset restarts it in place (fmi2Reset and its
    start values), loading nothing again.

    Parameters
    ----------
    render_mode : {None, "human", "rgb_array"}, optional
        Drawn by Gymnasium's own Pendulum-v1 renderer (pygame: ``pip install "gymnasium[classic_control]"``).
    max_torque : float, optional
        The torque limit in N.m; actions are clipped to it.
    dt : float, optional
        The communication step in s.
    tolerance : float, optional
        The FMU's relative tolerance; None for its own (1e-10).
    fmu : str, Path or FmuModel, optional
        The FMU; None for the package's.
    **parameters : float
        The FMU's parameters (mass, length, inertia, gravity, damping) over Pendulum-v1's rod:
        mass 1 kg, length 0.5 m, inertia 1/12 kg.m2, gravity 10 m/s2, damping 0.

    Attributes
    ----------
    settings : Settings
        What it was made with, checked: ``settings.parameters`` (the FMU's, defaults included),
        ``settings.max_torque``, ``settings.dt``, ``settings.tolerance``, ``settings.model``.
    dt, max_torque : float
        As Pendulum-v1 has them.

    Raises
    ------
    InvalidInput
        An unknown keyword, or a value the environment refuses (one line).
    FmuError
        The FMU refused the parameters or the tolerance.

    Examples
    --------
    >>> import gymnasium
    >>> env = gymnasium.make("pendulum_fmu.gym:PendulumFMU-v0")
    >>> observation, info = env.reset(seed=0)
    >>> observation, reward, terminated, truncated, info = env.step([1.5])
    >>> observation.dtype, observation.shape
    (dtype('float64'), (3,))
    >>> env.close()
    """

    # Gymnasium declares metadata an instance attribute of a class-level default.
    metadata: dict[str, Any] = {"render_modes": ["human", "rgb_array"], "render_fps": 20}  # noqa: RUF012

    def __init__(
        self,
        render_mode: str | None = None,
        *,
        max_torque: float = MAX_TORQUE,
        dt: float = DT,
        tolerance: float | None = None,
        fmu: str | Path | FmuModel | None = None,
        **parameters: Any,
    ):
        if render_mode not in (None, *self.metadata["render_modes"]):
            raise InvalidInput(f"render_mode {render_mode!r}: the render modes are {self.metadata['render_modes']}")
        self.settings = settings(
            fmu=fmu,
            max_torque=max_torque,
            dt=dt,
            max_episode_steps=None,
            tolerance=tolerance,
            parameters=parameters,
            keywords=("max_torque", "dt", "tolerance", "fmu", "render_mode"),
        )
        self.render_mode = render_mode
        self.metadata = {**self.metadata, "render_fps": round(1 / self.settings.dt)}
        self.dt = self.settings.dt
        self.max_torque = self.settings.max_torque
        self.observation_space = observation_space()
        self.action_space = action_space(self.max_torque)
        self._batch = self.settings.batch(1)
        self._state: tuple[float, float] | None = None  # (theta_fmu, omega) after the last reset or step
        self._torque: float | None = None  # the last step's, for the renderer
        self._renderer: Any = None

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        """Restart the FMU at a state drawn as Pendulum-v1 draws it: theta in [-pi, pi] (0 up),
        omega in [-1, 1] (options x_init, y_init change the bounds).
        """
        super().reset(seed=seed)
        theta, omega = draw_state(self.np_random, reset_bounds(options))
        self._state = None  # until the FMU has restarted
        batch = self._batch
        batch.start_values[0, -2:] = (fmu_angle(theta), omega)
        batch.modes[0] = RESTART
        batch.advance()
        self._state, self._torque = tuple(batch.outputs[0].tolist()), None
        if self.render_mode == "human":
            self.render()
        return observation(*self._state), {}

    def step(self, action):
        """One communication step of dt with the clipped torque held over it."""
        if self._state is None:
            raise InvalidInput("step before reset (or after a step the FMU refused): call reset() first")
        torque = checked_torque(action, self.max_torque)
        reward = rewards(*self._state, torque)
        batch = self._batch
        batch.inputs[0, 0] = torque
        self._state = None  # a step the FMU refuses leaves no state to step from
        batch.advance()
        self._state, self._torque = tuple(batch.outputs[0].tolist()), torque
        if self.render_mode == "human":
            self.render()
        return observation(*self._state), reward, False, False, {}

    def render(self):
        """The pendulum drawn by Gymnasium's Pendulum-v1 renderer at this state and torque."""
        if self.render_mode is None:
            gymnasium.logger.warn("render() without a render_mode: make the environment with render_mode='rgb_array'")
            return None
        if self._renderer is None:
            from gymnasium.envs.classic_control.pendulum import PendulumEnv

            self._renderer = PendulumEnv(render_mode=self.render_mode)
            self._renderer.metadata = self.metadata
        if self._state is not None:
            self._renderer.state = (self._state[0] - math.pi, self._state[1])
            self._renderer.last_u = self._torque
        return self._renderer.render()

    def close(self):
        """Free the FMU instance (and the renderer's window)."""
        if self._renderer is not None:
            self._renderer.close()
        self._batch.close()
        super().close()
