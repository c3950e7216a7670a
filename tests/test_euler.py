"""Integration error's Euler stepping (pendulum_fmu/judging/_euler.py): its C code against the
Python loop it transcribes, bit for bit, and both against the closed form of a pendulum without
gravity; the judge's candidates the same with the C code and without it.
"""

import numpy as np
import pytest

from pendulum_fmu.judging import _euler
from pendulum_fmu.judging._judge import judge

MODEL = (196.2, 0.0, 1.0 / 30.0)  # the tutorial's: mass*gravity*length, damping, 1/inertia


def test_the_native_stepping_is_built():
    assert _euler.library() is not None, "build it: pip install -e ."


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("semi_implicit", [False, True])
def test_the_c_steps_are_the_python_steps_bit_for_bit(seed, semi_implicit):
    rng = np.random.default_rng(seed)
    count = int(rng.integers(0, 5000))
    steps = rng.choice([1e-3, 1e-2, 0.3]) * rng.uniform(0.5, 1.5, count)
    torques = rng.normal(0, 10 ** rng.uniform(0, 3), count)
    model = (rng.uniform(0, 500), rng.choice([0.0, rng.uniform(0, 20)]), 1 / rng.uniform(1, 50))
    state = (rng.uniform(-10, 10), rng.uniform(-50, 50))
    native = _euler.euler_steps(state, steps, torques, model, semi_implicit)
    python = _euler._python_steps(state, steps, torques, model, semi_implicit)
    assert np.array_equal(native[0], python[0]) and np.array_equal(native[1], python[1])


@pytest.mark.parametrize("native", [True, False])
def test_without_gravity_explicit_euler_is_its_closed_form(monkeypatch, native):
    # I omega' = u - c omega, stepped: omega_k = u/c + (omega_0 - u/c) r**k, r = 1 - h c / I, and
    # theta_k = theta_0 + h (omega_0 + ... + omega_(k-1)).
    if not native:
        monkeypatch.setattr(_euler, "library", lambda: None)
    h, u, c, inertia, count = 1e-3, 20.0, 4.0, 30.0, 3000
    thetas, omegas = _euler.euler_steps((0.5, 2.0), np.full(count, h), np.full(count, u), (0.0, c, 1 / inertia), False)
    k = np.arange(count + 1)
    r, settled = 1 - h * c / inertia, u / c
    expected_omega = settled + (2.0 - settled) * r**k
    expected_theta = 0.5 + h * (settled * k + (2.0 - settled) * (1 - r**k) / (1 - r))
    np.testing.assert_allclose(omegas, expected_omega, rtol=1e-12)
    np.testing.assert_allclose(thetas, expected_theta, rtol=1e-12)


def test_step_sizes_and_torques_of_different_lengths_are_refused():
    with pytest.raises(ValueError, match="3 step sizes need as many torques, not 2"):
        _euler.euler_steps((0.0, 0.0), np.ones(3), np.ones(2), MODEL, False)


def test_judge_is_the_same_with_and_without_the_native_stepping(monkeypatch, tmp_path):
    from pendulum_fmu import simulate

    t = np.arange(2001) * 1e-3
    signal = tmp_path / "torque.csv"
    np.savetxt(signal, np.c_[t, 20 * np.sin(2 * np.pi * 0.5 * t)], delimiter=",", header="time,torque", comments="")
    result = simulate(str(signal), stop_time=2.0)
    native = judge(result, str(signal), stop_time=2.0)
    monkeypatch.setattr(_euler, "library", lambda: None)
    python = judge(result, str(signal), stop_time=2.0)
    assert native.candidates == python.candidates
    assert (native.verdict, native.diagnosis, native.residual) == (python.verdict, python.diagnosis, python.residual)
