"""The FMU as a Gymnasium environment: Pendulum-v1's interface over the exact pendulum.

Importing this module registers ``PendulumFMU-v0`` with Gymnasium, so that

    gymnasium.make("pendulum_fmu.gym:PendulumFMU-v0")                    # PendulumFmuEnv
    gymnasium.make_vec("pendulum_fmu.gym:PendulumFMU-v0", num_envs=256)  # PendulumFmuVectorEnv

import it on the way. _conventions is Pendulum-v1's observation, reward and reset over the FMU's
variables; _settings checks the make keywords and starts the FMU instances (fmu/_batch.py);
_env is the single environment, _vector the batch stepped in one native call.

May import: fmu/ and the basics; gymnasium (the [gym] extra), which nothing else of the package
imports.
"""

import gymnasium

from ._env import PendulumFmuEnv
from ._vector import PendulumFmuVectorEnv

__all__ = ["ENV_ID", "PendulumFmuEnv", "PendulumFmuVectorEnv"]

# The id without the module: gymnasium.make(ENV_ID) once this module is imported.
ENV_ID = "PendulumFMU-v0"

if ENV_ID not in gymnasium.registry:
    gymnasium.register(
        id=ENV_ID,
        entry_point="pendulum_fmu.gym._env:PendulumFmuEnv",
        vector_entry_point="pendulum_fmu.gym._vector:PendulumFmuVectorEnv",
        max_episode_steps=200,
    )
