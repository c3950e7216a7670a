"""The FMU as a Gymnasium environment (pendulum_fmu.gym), held to independent references: scipy's
solve_ivp for the pendulum, Gymnasium's own Pendulum-v1 for the reward and the reset's draw, and
Gymnasium's SyncVectorEnv for the vector environment's batching and autoreset.
"""

import math

import gymnasium
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import pendulum_fmu.gym
from pendulum_fmu import FmuError, InvalidInput
from pendulum_fmu.fmu._batch import FmuBatch
from pendulum_fmu.fmu._model import fmu_model

ENV_ID = "pendulum_fmu.gym:PendulumFMU-v0"


def rod_trajectory(theta0, omega0, torques, dt, *, gravity=10.0, mass=1.0, rod_length=1.0):
    """(theta, omega) from the top after each held torque: Pendulum-v1's rod equation
    theta'' = 3 g / (2 l) sin(theta) + 3 u / (m l^2), integrated by scipy at its tightest.
    """
    states, state = [], np.array([theta0, omega0])
    for torque in torques:

        def rod(t, x, torque=torque):
            return [x[1], 3 * gravity / (2 * rod_length) * math.sin(x[0]) + 3 * torque / (mass * rod_length**2)]

        state = solve_ivp(rod, (0, dt), state, method="DOP853", rtol=1e-13, atol=1e-13).y[:, -1]
        states.append(state)
    return np.array(states)


def angle(observation):
    return math.atan2(observation[1], observation[0])


def test_an_episode_is_the_exact_rod_from_pendulum_v1s_reset_with_clipped_torques():
    env = gymnasium.make(ENV_ID)
    observation, _ = env.reset(seed=3)
    theta0, omega0 = angle(observation), observation[2]
    actions = np.random.default_rng(0).uniform(-3, 3, 60)  # a third beyond the +-2 N.m limit
    states = np.array([env.step(np.array([action]))[0] for action in actions])
    expected = rod_trajectory(theta0, omega0, np.clip(actions, -2, 2), 0.05)
    assert states.dtype == np.float64
    wrapped = np.angle(np.exp(1j * (np.arctan2(states[:, 1], states[:, 0]) - expected[:, 0])))
    assert np.abs(wrapped).max() < 1e-9
    assert np.abs(states[:, 2] - expected[:, 1]).max() < 1e-8
    assert np.abs(states[:, 2]).max() > 2  # it swung
    env.close()


def test_make_keywords_set_the_fmus_parameters_torque_limit_and_step():
    env = gymnasium.make(ENV_ID, mass=2.0, length=0.4, inertia=0.02, gravity=9.81, damping=0.3, max_torque=5, dt=0.02)
    observation, _ = env.reset(seed=1)
    state = np.array([angle(observation) + math.pi, observation[2]])  # from the bottom, the FMU's way
    inertia = 0.02 + 2.0 * 0.4**2
    for action in (7.0, -1.0, 3.0):
        observation = env.step(np.array([action]))[0]
        clipped = min(action, 5.0)

        def pendulum(t, x, torque=clipped):
            return [x[1], (torque - 2.0 * 9.81 * 0.4 * math.sin(x[0]) - 0.3 * x[1]) / inertia]

        state = solve_ivp(pendulum, (0, 0.02), state, method="DOP853", rtol=1e-13, atol=1e-13).y[:, -1]
        assert abs(math.remainder(angle(observation) + math.pi - state[0], 2 * math.pi)) < 1e-10
        assert observation[2] == pytest.approx(state[1], abs=1e-10)
    env.close()


def test_the_reset_draw_and_the_reward_are_pendulum_v1s():
    ours, theirs = gymnasium.make(ENV_ID), gymnasium.make("Pendulum-v1")
    for seed in (0, 7, 12345):
        observation, _ = ours.reset(seed=seed)
        theirs.reset(seed=seed)
        theta, omega = theirs.unwrapped.state
        assert observation[2] == omega
        assert angle(observation) == pytest.approx(theta, abs=1e-15)
    ours.reset(seed=0, options={"x_init": 0.1, "y_init": 0.2})
    theirs.reset(seed=0, options={"x_init": 0.1, "y_init": 0.2})
    assert ours.unwrapped._state[1] == theirs.unwrapped.state[1]
    # The reward of a step from a state: Gymnasium's computed from that state set in its env.
    for theta, omega, action in [(0.3, -2.0, 1.0), (3.0, 5.0, -4.0), (-7.0, 0.1, 2.5), (12.0, -9.0, 0.0)]:
        ours.unwrapped._state = (theta + math.pi, omega)
        theirs.unwrapped.state = np.array([theta, omega])
        reward = ours.unwrapped.step(np.array([action]))[1]
        assert reward == pytest.approx(theirs.unwrapped.step(np.array([action]))[1], rel=1e-14)
    ours.close()


def test_a_reset_restarts_the_same_instance_and_replays_a_fresh_envs_episode_bit_for_bit():
    env = gymnasium.make(ENV_ID)
    component = env.unwrapped._batch.instances[0].component
    actions = [np.array([a]) for a in np.random.default_rng(2).uniform(-2, 2, 200)]

    def episode(env, seed):
        observations = [env.reset(seed=seed)[0]]
        for action in actions:
            observation, reward, terminated, truncated, _ = env.step(action)
            observations.append(np.append(observation, reward))
        assert truncated and not terminated
        return np.concatenate(observations)

    episode(env, 5)
    replayed = episode(env, 11)
    fresh = gymnasium.make(ENV_ID)
    assert np.array_equal(replayed, episode(fresh, 11))
    assert env.unwrapped._batch.instances[0].component == component
    env.close()
    fresh.close()


@pytest.mark.parametrize("num_threads", [1, 3])
def test_the_vector_env_is_gymnasiums_sync_vector_env_of_the_single_env(num_threads):
    keywords = dict(num_envs=5, max_episode_steps=7, mass=1.5, damping=0.1)
    ours = gymnasium.make_vec(ENV_ID, num_threads=num_threads, **keywords)
    sync = gymnasium.make_vec(ENV_ID, vectorization_mode="sync", **keywords)
    assert isinstance(ours.unwrapped, pendulum_fmu.gym.PendulumFmuVectorEnv)
    rng = np.random.default_rng(4)
    for seed in (3, None):
        if seed is None:  # a second reset, the generators carried on
            steps = 9
        else:
            steps = 17  # past two episodes: the autoreset's steps included
        observations, _ = ours.reset(seed=seed)
        expected, _ = sync.reset(seed=seed)
        np.testing.assert_array_max_ulp(observations, expected, maxulp=2)
        for _ in range(steps):
            actions = rng.uniform(-3, 3, (5, 1))
            step, expected_step = ours.step(actions), sync.step(actions)
            np.testing.assert_array_max_ulp(step[0], expected_step[0], maxulp=2)
            for ours_part, sync_part in zip(step[1:4], expected_step[1:4], strict=True):
                assert np.array_equal(ours_part, sync_part)
    ours.close()
    sync.close()


def test_a_partial_reset_leaves_the_other_environments_as_they_are():
    envs = gymnasium.make_vec(ENV_ID, num_envs=3)
    envs.reset(seed=0)
    before = envs.step(np.ones((3, 1)))[0]
    after, _ = envs.reset(seed=[None, 9, None], options={"reset_mask": np.array([False, True, False])})
    assert np.array_equal(after[[0, 2]], before[[0, 2]])
    single = gymnasium.make(ENV_ID)
    np.testing.assert_array_max_ulp(after[1], single.reset(seed=9)[0], maxulp=2)
    envs.close()


def test_the_native_batch_and_its_python_reference_agree_bit_for_bit():
    model = fmu_model()
    outputs = []
    for native in (True, False):
        batch = FmuBatch(
            model,
            3,
            start_names=("gravity", "theta", "omega"),
            input_names=("torque",),
            output_names=("theta", "omega", "alpha"),
            step_size=0.01,
            threads=2,
            native=native,
        )
        batch.start_values[:] = [[9.81, 0.1, 0.0], [1.0, 2.0, -1.0], [0.0, 3.0, 4.0]]
        batch.advance()
        trajectory = [batch.outputs.copy()]
        for k in range(30):
            batch.inputs[:, 0] = [math.sin(k), 20.0, -k]
            if k == 10:
                batch.modes[1] = 1  # RESTART
            if k == 20:
                batch.modes[2] = 2  # HOLD
            batch.advance()
            trajectory.append(batch.outputs.copy())
        outputs.append(np.array(trajectory))
        batch.close()
    assert np.array_equal(*outputs)
    assert np.array_equal(outputs[0][11, 1], outputs[0][0, 1])  # restarted where it started
    assert np.array_equal(outputs[0][21, 2], outputs[0][20, 2])  # held


# It warns that the rate is unbounded: it is (no speed clip), as it warns of Pendulum-v1's +-2 N.m.
@pytest.mark.filterwarnings("ignore:.*(infinity|symmetric and normalized)")
def test_gymnasiums_env_checker_passes():
    from gymnasium.utils.env_checker import check_env

    env = pendulum_fmu.gym.PendulumFmuEnv()
    check_env(env, skip_render_check=True)
    env.close()


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: gymnasium.make(ENV_ID, masss=2.0), "unknown keyword 'masss': the keywords are the FMU's parameters"),
        (lambda: gymnasium.make(ENV_ID, dt=0.0), "dt = 0.0 s must be positive and finite"),
        (lambda: gymnasium.make(ENV_ID, max_torque=math.inf), "max_torque = inf N.m must be positive and finite"),
        (lambda: gymnasium.make(ENV_ID, mass=-1.0), "mass must be > 0"),
        (lambda: gymnasium.make_vec(ENV_ID, num_envs=0), "num_envs = 0 must be from 1 to 1,000,000"),
        (lambda: gymnasium.make_vec(ENV_ID, num_envs=10**7), "num_envs = 10000000 must be from 1 to 1,000,000"),
        (lambda: gymnasium.make_vec(ENV_ID, num_envs=2, num_threads=0), "num_threads = 0 must be from 1 to 1,024"),
        (lambda: gymnasium.make_vec(ENV_ID, num_envs=2, max_episode_steps=2.5), "max_episode_steps = 2.5 is not"),
    ],
)
def test_a_bad_keyword_is_refused_in_one_line(make, message):
    with pytest.raises((InvalidInput, FmuError, TypeError)) as error:
        make()
    assert message in str(error.value)
    assert "\n" not in str(error.value)


@pytest.mark.parametrize(
    ("action", "message"),
    [
        (np.array([math.nan]), "is not finite"),
        (np.array([1.0, 2.0]), "action of shape (2,): the action space's shape is (1,)"),
        ("left", "is not numbers"),
    ],
)
def test_a_bad_action_is_refused_and_nothing_is_stepped(action, message):
    env, fresh = gymnasium.make(ENV_ID), gymnasium.make(ENV_ID)
    env.reset(seed=0)
    fresh.reset(seed=0)
    with pytest.raises(InvalidInput) as error:
        env.step(action)
    assert message in str(error.value)
    assert np.array_equal(env.step(np.array([0.5]))[0], fresh.step(np.array([0.5]))[0])
    env.close()
    fresh.close()


def test_a_step_before_reset_is_refused():
    env = pendulum_fmu.gym.PendulumFmuEnv()
    with pytest.raises(InvalidInput, match="step before reset"):
        env.step(np.array([0.0]))
    envs = pendulum_fmu.gym.PendulumFmuVectorEnv(2)
    with pytest.raises(InvalidInput, match="step before reset"):
        envs.step(np.zeros((2, 1)))
    with pytest.raises(InvalidInput, match=r"action of shape \(2,\): the action space's shape is \(2, 1\)"):
        envs.reset(seed=0)
        envs.step(np.zeros(2))
    env.close()
    envs.close()


@pytest.mark.parametrize("name", ["PendulumFmuEnv", "PendulumFmuVectorEnv"])
def test_the_docstring_examples_run_as_written(name):
    import doctest

    thing = getattr(pendulum_fmu.gym, name)
    [test] = doctest.DocTestFinder(recurse=False).find(thing, name, globs={})
    runner = doctest.DocTestRunner()
    runner.run(test)
    assert runner.failures == 0 and runner.tries > 3


def test_the_docs_pages_python_runs_as_written():
    import re
    from pathlib import Path

    page = (Path(__file__).resolve().parent.parent / "docs" / "reinforcement_learning.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```python\n(.*?)```", page, re.S)
    namespace: dict = {}
    for block in blocks:
        exec(block, namespace)
    assert len(blocks) == 4
    assert namespace["observations"].shape == (1024, 3) and namespace["system"].nstates == 2
    namespace["env"].close()
