"""PendulumFmuVectorEnv: N FMU instances stepped in one native call, as a Gymnasium VectorEnv."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from .._errors import InvalidInput
from ..fmu._batch import HOLD, RESTART
from ..fmu._model import FmuModel
from ._conventions import (
    DT,
    MAX_EPISODE_STEPS,
    MAX_TORQUE,
    checked_actions,
    draw_state,
    fmu_angle,
    observations,
    reset_bounds,
    rewards,
)
from ._env import action_space, observation_space
from ._settings import MAX_ENVS, MAX_THREADS, count, settings


def default_threads(num_envs: int) -> int:
    """The cores this process may use, at most one per 512 environments.

    A step of the FMU at 0.05 s costs about 0.4 us, and waking a thread tens of us: on the 2-core
    machine of docs/reinforcement_learning.md's table, 256 environments stepped faster on one
    thread than on two, 1,024 faster on two.
    """
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
    return max(1, min(cores, num_envs // 512))


class PendulumFmuVectorEnv(VectorEnv):
    """num_envs PendulumFmuEnv in one: every step advances all their FMU instances in one call into
    the native loop (fmi2SetReal, fmi2DoStep, fmi2GetReal each, spread over num_threads threads),
    with Gymnasium 1.x's autoreset (next step).

    Made by ``gymnasium.make_vec("pendulum_fmu.gym:PendulumFMU-v0", num_envs=N, **keywords)``.
    Environment i is PendulumFmuEnv made with the same keywords and seeded with seed + i, as
    Gymnasium's SyncVectorEnv seeds its copies: the two give the same numbers bit for bit. An
    episode is truncated after max_episode_steps steps; the step after an episode ends resets that
    environment (its action ignored, its reward 0) and returns the new episode's first observation.

    Parameters
    ----------
    num_envs : int
        The number of environments, 1 to 1,000,000.
    max_episode_steps : int, optional
        The steps of an episode.
    num_threads : int, optional
        The threads a step runs on, the caller's included; None: the cores this process may use,
        at most one per 512 environments.
    max_torque, dt, tolerance, fmu, **parameters
        As PendulumFmuEnv.

    Attributes
    ----------
    settings : Settings
        What it was made with, checked, as PendulumFmuEnv's.
    num_threads : int
        The threads a step runs on.

    Raises
    ------
    InvalidInput
        An unknown keyword, or a value the environment refuses (one line).
    FmuError
        The FMU refused the parameters or the tolerance.

    Examples
    --------
    >>> import gymnasium
    >>> envs = gymnasium.make_vec("pendulum_fmu.gym:PendulumFMU-v0", num_envs=4)
    >>> observations, infos = envs.reset(seed=0)
    >>> observations, rewards, terminations, truncations, infos = envs.step(envs.action_space.sample())
    >>> observations.shape, rewards.shape
    ((4, 3), (4,))
    >>> envs.close()
    """

    # Gymnasium declares metadata an instance attribute of a class-level default.
    metadata: dict[str, Any] = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}  # noqa: RUF012

    def __init__(
        self,
        num_envs: int,
        *,
        max_episode_steps: int = MAX_EPISODE_STEPS,
        num_threads: int | None = None,
        max_torque: float = MAX_TORQUE,
        dt: float = DT,
        tolerance: float | None = None,
        fmu: str | Path | FmuModel | None = None,
        render_mode: None = None,
        **parameters: Any,
    ):
        if render_mode is not None:
            raise InvalidInput(f"render_mode {render_mode!r}: the vector environment draws nothing; render one env")
        self.num_envs = count("num_envs", num_envs, MAX_ENVS)
        threads = default_threads(self.num_envs) if num_threads is None else num_threads
        self.num_threads = count("num_threads", threads, MAX_THREADS)
        self.settings = settings(
            fmu=fmu,
            max_torque=max_torque,
            dt=dt,
            max_episode_steps=max_episode_steps,
            tolerance=tolerance,
            parameters=parameters,
            keywords=("max_torque", "dt", "tolerance", "fmu", "max_episode_steps", "num_threads"),
        )
        self._max_episode_steps = int(max_episode_steps)
        self.single_observation_space = observation_space()
        self.single_action_space = action_space(self.settings.max_torque)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.render_mode = None
        self._batch = self.settings.batch(self.num_envs, self.num_threads)
        self._rngs: list[np.random.Generator] = []  # each environment's, made by the first reset
        self._bounds = reset_bounds(None)
        self._elapsed = np.zeros(self.num_envs, np.int64)
        self._autoreset = np.zeros(self.num_envs, np.bool_)
        self._started = False

    def reset(self, *, seed: int | list[int | None] | None = None, options: dict[str, Any] | None = None):
        """Reset every environment (or those of options["reset_mask"]) at a state drawn as
        PendulumFmuEnv draws it, environment i from seed + i (a list: a seed each; None: fresh
        entropy for environments never seeded).
        """
        seeds = self._seeds(seed)
        options = dict(options or {})
        mask = self._reset_mask(options.pop("reset_mask", None))
        self._bounds = reset_bounds(options)
        if not self._rngs:
            self._rngs = [seeding.np_random(seed)[0] for seed in seeds]
        else:
            for i in np.flatnonzero(mask):
                if seeds[i] is not None:
                    self._rngs[i], _ = seeding.np_random(seeds[i])
        self._batch.modes[:] = HOLD
        self._restart(mask)
        self._batch.advance()
        self._elapsed[mask] = 0
        self._autoreset[mask] = False
        self._started = True
        return observations(self._batch.outputs[:, 0], self._batch.outputs[:, 1]), {}

    def step(self, actions):
        """One communication step of every environment; those whose episode ended the step
        before are reset instead.
        """
        if not self._started:
            raise InvalidInput("step before reset: call reset() first")
        torques = checked_actions(actions, (self.num_envs, 1), self.settings.max_torque)[:, 0]
        batch = self._batch
        restarting = self._autoreset.copy()
        reward = np.where(restarting, 0.0, rewards(batch.outputs[:, 0], batch.outputs[:, 1], torques))
        if restarting.any():
            self._restart(restarting)
        batch.inputs[:, 0] = torques
        self._started = False  # a step the FMU refuses leaves the batch in no state to step from
        batch.advance()
        self._started = True
        self._elapsed = np.where(restarting, 0, self._elapsed + 1)
        truncated = self._elapsed >= self._max_episode_steps
        self._autoreset = truncated
        terminated = np.zeros(self.num_envs, np.bool_)
        return observations(batch.outputs[:, 0], batch.outputs[:, 1]), reward, terminated, truncated.copy(), {}

    def _restart(self, mask: np.ndarray) -> None:
        """Mark the environments of mask for a restart at a state each draws from its generator."""
        batch = self._batch
        for i in np.flatnonzero(mask):
            theta, omega = draw_state(self._rngs[i], self._bounds)
            batch.start_values[i, -2:] = (fmu_angle(theta), omega)
        batch.modes[mask] = RESTART

    def _seeds(self, seed) -> list[int | None]:
        if seed is None:
            return [None] * self.num_envs
        if isinstance(seed, int | np.integer):
            return [int(seed) + i for i in range(self.num_envs)]
        seeds = list(seed)
        if len(seeds) != self.num_envs:
            raise InvalidInput(f"{len(seeds)} seeds for {self.num_envs} environments: give one seed, or one each")
        return seeds

    def _reset_mask(self, mask) -> np.ndarray:
        if mask is None:
            return np.ones(self.num_envs, np.bool_)
        mask = np.asarray(mask)
        if mask.shape != (self.num_envs,) or mask.dtype != np.bool_:
            raise InvalidInput(f"reset_mask must be a bool array of shape ({self.num_envs},): got {mask.dtype}")
        return mask

    def close_extras(self, **kwargs: Any) -> None:
        """Free every FMU instance and the threads."""
        self._batch.close()
