"""The oracle's integrator (pendulum_fmu/oracle/_taylor.py), against closed-form solutions and
against scipy's solve_ivp at its tightest tolerance (DOP853, and Radau as a second method), and
through reference() on a signal with a jump and a ramp.
"""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from pendulum_fmu import reference
from pendulum_fmu.oracle._taylor import Diverged, integrate_piece

# The tutorial's pendulum: m g l = 40 * 9.81 * 0.5 N.m, I + m l^2 = 20 + 40 * 0.25 kg.m^2.
GRAVITY_MOMENT, TOTAL_INERTIA = 196.2, 30.0
TIGHT = (1e-15, 1e-15)


def scipy_run(theta0, omega0, span, torque, damping, times, method, gravity_moment=GRAVITY_MOMENT):
    u0, rate = torque

    def motion(t, y):
        u = u0 + rate * (t - span[0])
        return (y[1], (u - gravity_moment * math.sin(y[0]) - damping * y[1]) / TOTAL_INERTIA)

    solution = solve_ivp(motion, span, (theta0, omega0), method=method, rtol=2.3e-14, atol=1e-14, t_eval=times)
    return solution.y


def taylor_run(theta0, omega0, span, torque, damping, times, gravity_moment=GRAVITY_MOMENT, tolerance=TIGHT):
    model = (gravity_moment, damping, 1.0 / TOTAL_INERTIA)
    thetas, omegas, theta, omega = integrate_piece(theta0, omega0, span, torque, model, tolerance, list(times))
    return thetas.tolist(), omegas.tolist(), theta, omega


def test_gravity_off_constant_torque_is_the_parabola():
    times = np.linspace(0.0, 10.0, 101)
    thetas, omegas, theta, omega = taylor_run(0.3, -1.0, (0.0, 10.0), (20.0, 0.0), 0.0, times, gravity_moment=0.0)
    alpha = 20.0 / TOTAL_INERTIA
    np.testing.assert_allclose(thetas, 0.3 - times + 0.5 * alpha * times**2, rtol=1e-15, atol=1e-14)
    np.testing.assert_allclose(omegas, -1.0 + alpha * times, rtol=1e-15, atol=1e-14)
    assert (theta, omega) == (thetas[-1], omegas[-1])


def test_gravity_off_damped_ramp_is_the_linear_solution():
    # omega' = (u0 + r t - c omega) / J: omega = A + B t + (omega0 - A) exp(-a t), a = c/J,
    # B = r/c, A = (u0 - J B)/c; theta its integral.
    u0, rate, damping, omega0, theta0 = 5.0, -3.0, 12.0, 2.0, -0.5
    a, b = damping / TOTAL_INERTIA, rate / damping
    constant = (u0 - TOTAL_INERTIA * b) / damping
    times = np.linspace(0.0, 8.0, 801)
    decay = np.exp(-a * times)
    omega_exact = constant + b * times + (omega0 - constant) * decay
    theta_exact = theta0 + constant * times + 0.5 * b * times**2 + (omega0 - constant) * (1 - decay) / a
    thetas, omegas, _, _ = taylor_run(theta0, omega0, (0.0, 8.0), (u0, rate), damping, times, gravity_moment=0.0)
    assert np.max(np.abs(np.array(thetas) - theta_exact)) < 1e-13
    assert np.max(np.abs(np.array(omegas) - omega_exact)) < 1e-13


def test_a_free_swing_keeps_its_energy():
    # No torque, no damping, from near the top: 0.5 J omega^2 - m g l cos(theta) is constant.
    times = np.linspace(0.0, 30.0, 3001)
    thetas, omegas, _, _ = taylor_run(3.0, 0.0, (0.0, 30.0), (0.0, 0.0), 0.0, times)
    energy = 0.5 * TOTAL_INERTIA * np.array(omegas) ** 2 - GRAVITY_MOMENT * np.cos(thetas)
    assert np.max(np.abs(energy - energy[0])) < 1e-12 * GRAVITY_MOMENT
    assert np.ptp(thetas) > 5.9  # it swung from 3.0 to about -3.0 and back


@pytest.mark.parametrize(
    ("theta0", "omega0", "torque", "damping", "stop"),
    [
        (0.0, 0.0, (20.0, 0.0), 0.0, 3.0),  # the tutorial's case
        (0.3, -1.0, (-20.0, 5.0), 1.5, 3.0),  # a ramp with damping
        (0.0, 0.0, (500.0, 0.0), 0.0, 4.0),  # spun over the top, theta into the hundreds
        (1.0, 4.0, (0.0, -40.0), 0.2, 6.0),
        (-2.5, 0.0, (1e-3, 0.0), 0.0, 0.002),  # one short step
    ],
)
@pytest.mark.parametrize("method", ["DOP853", "Radau"])
def test_agrees_with_solve_ivp_at_its_tightest(theta0, omega0, torque, damping, stop, method):
    times = np.linspace(0.0, stop, 1201)
    expected = scipy_run(theta0, omega0, (0.0, stop), torque, damping, times, method)
    thetas, omegas, theta, omega = taylor_run(theta0, omega0, (0.0, stop), torque, damping, times)
    # scipy's own error at its tightest is about 1e-12 of the state here (DOP853 and Radau differ
    # from each other by as much); the Taylor series' is far below.
    scale = max(1.0, np.max(np.abs(expected)))
    assert np.max(np.abs(np.array(thetas) - expected[0])) < 2e-11 * scale
    assert np.max(np.abs(np.array(omegas) - expected[1])) < 2e-11 * scale
    assert (theta, omega) == (thetas[-1], omegas[-1])


def test_a_tighter_tolerance_converges():
    # The tolerance bounds each step's error; over 20 s of swings near the top (where errors grow
    # most) the end is within a thousand times it of the run at 1e-16.
    tolerances = (1e-8, 1e-12, 1e-16)
    ends = [taylor_run(3.0, 0.0, (0.0, 20.0), (0.0, 0.0), 0.0, [], tolerance=(t, t))[2] for t in tolerances]
    assert abs(ends[0] - ends[2]) < 1e3 * tolerances[0]
    assert abs(ends[1] - ends[2]) < 1e3 * tolerances[1]
    assert abs(ends[1] - ends[2]) < 1e-3 * abs(ends[0] - ends[2])


def test_reports_at_the_start_and_the_end_are_the_state_itself():
    thetas, omegas, theta, omega = taylor_run(0.25, -0.5, (1.0, 2.0), (3.0, 0.0), 0.0, [1.0, 1.0, 2.0])
    assert thetas[:2] == [0.25, 0.25] and omegas[:2] == [-0.5, -0.5]
    assert (thetas[2], omegas[2]) == (theta, omega)
    assert taylor_run(0.25, -0.5, (1.0, 1.0), (3.0, 0.0), 0.0, [1.0]) == ([0.25], [-0.5], 0.25, -0.5)


@pytest.mark.parametrize("gravity_moment", [1e308, math.inf, math.nan])
def test_values_past_the_largest_double_are_refused(gravity_moment):
    with pytest.raises(Diverged, match="not finite"):
        taylor_run(0.5, 0.0, (0.0, 1.0), (20.0, 0.0), 0.0, [1.0], gravity_moment=gravity_moment)


def test_reference_restarts_the_series_at_a_jump_and_follows_a_ramp(tmp_path):
    # 20 N.m to 1 s, a jump to -20 N.m, a ramp to 10 N.m at 2.5 s, held: solve_ivp over each
    # piece in turn, restarted at 1 s and 2.5 s, the torque just after each time.
    csv = tmp_path / "torque.csv"
    csv.write_text("time,torque\n0,20\n1,20\n1,-20\n2.5,10\n3,10\n")
    oracle = reference(csv, ramp=True)
    state, expected = (0.0, 0.0), []
    for start, stop, torque in ((0.0, 1.0, (20.0, 0.0)), (1.0, 2.5, (-20.0, 20.0)), (2.5, 3.0, (10.0, 0.0))):
        times = oracle["time"][(oracle["time"] >= start) & (oracle["time"] < stop)]
        y = scipy_run(*state, (start, stop), torque, 0.0, [*times, stop], "DOP853")
        expected.append(y[:, :-1])
        state = tuple(y[:, -1])
    expected.append(np.array(state)[:, None])
    theta = np.concatenate([y[0] for y in expected])
    assert len(theta) == len(oracle) == 3001
    assert np.max(np.abs(oracle["theta"] - theta)) < 1e-11
    assert oracle["torque"][1000] == -20.0 and oracle["torque"][999] == 20.0
    assert oracle["torque"][2000] == pytest.approx(-20.0 + 20.0 * 1.0, abs=1e-12)
