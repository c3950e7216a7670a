"""MuJoCo, Drake and PyBullet against the reference: accuracy, defaults, traps, parameters.

Each engine is skipped when its package is not installed. The random step signal is made here
from numpy's generator; the reference is pendulum_fmu.reference (its Taylor series), which
shares no code with the adapters.
"""

import numpy as np
import pytest

from pendulum_fmu.engines import ToolCannotRamp
from pendulum_fmu.fmu._simulate import resolve_parameters
from pendulum_fmu.oracle._reference import reference_schedule
from pendulum_fmu.signals._torque_schedule import schedule

THETA0, OMEGA0 = 0.3, -0.5


def random_steps(stop_time, *, seed=1, hold=0.1, amplitude=300.0, step_size=1e-3):
    """A torque that jumps to a new uniform random level every `hold` seconds."""
    levels = np.random.default_rng(seed).uniform(-amplitude, amplitude, round(stop_time / hold))
    return schedule(
        lambda t: levels[min(int(t / hold + 1e-9), len(levels) - 1)], stop_time=stop_time, step_size=step_size
    )


FOUR_SECONDS = random_steps(4.0)
ONE_SECOND = random_steps(1.0, seed=2)


def error(run, expected, field="theta"):
    assert np.array_equal(run["time"], expected["time"])
    assert np.array_equal(run["torque"], expected["torque"])
    return float(np.max(np.abs(run[field] - expected[field])))


@pytest.fixture(scope="module")
def reference_4s():
    return reference_schedule(FOUR_SECONDS, theta0=THETA0, omega0=OMEGA0)


@pytest.fixture(scope="module")
def reference_1s():
    return reference_schedule(ONE_SECOND, theta0=THETA0, omega0=OMEGA0)


def engine(name):
    pytest.importorskip({"drake": "pydrake"}.get(name, name))
    import importlib

    return importlib.import_module(f"pendulum_fmu.engines.{name}")


# The accurate modes' bounds on max |dtheta| (rad) against the reference over FOUR_SECONDS:
# MuJoCo and Drake as the issue asks; PyBullet's semi-implicit Euler at 10 us substeps measured
# 2.2e-5 rad.
ACCURATE_BOUND = {"mujoco": 1e-9, "drake": 1e-9, "pybullet": 3e-5}


@pytest.mark.parametrize("name", ["mujoco", "drake"])
def test_accurate_meets_its_bound_over_four_seconds(name, reference_4s):
    run = engine(name).run(FOUR_SECONDS, theta0=THETA0, omega0=OMEGA0)
    print(
        f"\n{name} accurate, 4 s random steps: max |dtheta| {error(run, reference_4s):.2e} rad, "
        f"|domega| {error(run, reference_4s, 'omega'):.2e}, |dalpha| {error(run, reference_4s, 'alpha'):.2e}"
    )
    assert error(run, reference_4s) <= ACCURATE_BOUND[name]
    assert error(run, reference_4s, "omega") <= 10 * ACCURATE_BOUND[name]
    assert error(run, reference_4s, "alpha") <= 100 * ACCURATE_BOUND[name]


def test_pybullet_accurate_meets_its_bound(reference_1s):
    run = engine("pybullet").run(ONE_SECOND, theta0=THETA0, omega0=OMEGA0)
    print(f"\npybullet accurate, 1 s random steps: max |dtheta| {error(run, reference_1s):.2e} rad")
    assert error(run, reference_1s) <= ACCURATE_BOUND["pybullet"]
    # alpha is the acceleration PyBullet used over its first substep.
    assert error(run, reference_1s, "alpha") <= 1e-3


@pytest.mark.parametrize("name", ["mujoco", "drake", "pybullet"])
def test_default_mode_runs_and_reports_its_error(name, reference_1s):
    module = engine(name)
    default = module.run(ONE_SECOND, theta0=THETA0, omega0=OMEGA0, mode="default")
    accurate = module.run(ONE_SECOND, theta0=THETA0, omega0=OMEGA0)
    print(
        f"\n{name} default, 1 s random steps: max |dtheta| {error(default, reference_1s):.2e} rad, "
        f"|domega| {error(default, reference_1s, 'omega'):.2e}"
    )
    assert np.all(np.isfinite(default["theta"]))
    assert error(default, reference_1s) > error(accurate, reference_1s)


@pytest.mark.parametrize("name", ["mujoco", "drake", "pybullet"])
def test_a_ramp_is_refused(name):
    ramp = schedule(lambda t: 10 * t, stop_time=0.01, step_size=1e-3, ramp=True)
    with pytest.raises(ToolCannotRamp, match=f"{name} holds the torque"):
        engine(name).run(ramp)


def test_an_unknown_mode_is_refused():
    with pytest.raises(ValueError, match="unknown mode 'fast'"):
        engine("mujoco").run(ONE_SECOND, mode="fast")


# Each change must move the reference far more than the engine's own error.
CHANGES = [
    ("mass", 20.0),
    ("length", 0.8),
    ("inertia", 5.0),
    ("gravity", 3.7),
    ("damping", 20.0),
    ("theta0", 1.2),
    ("omega0", 2.0),
]


@pytest.mark.parametrize("name", ["mujoco", "drake", "pybullet"])
@pytest.mark.parametrize("quantity, value", CHANGES)
def test_parameters_and_start_values_reach_the_engine(name, quantity, value, reference_1s):
    module = engine(name)
    start = {"theta0": THETA0, "omega0": OMEGA0}
    parameters = {}
    if quantity in start:
        start[quantity] = value
    else:
        parameters[quantity] = value
    expected = reference_schedule(ONE_SECOND, parameters=parameters, **start)
    run = module.run(ONE_SECOND, parameters=parameters, **start)
    moved = error(expected, reference_1s)
    assert moved > 1e-2
    assert error(run, expected) <= ACCURATE_BOUND[name]


def _pybullet_without(flag):
    return lambda m: m.Setup(m.DEFAULT.largest_step, **{flag: False})


# (engine, trap, the correct setup, the setup with the trap turned back on, field, the trap's
# error at least) on ONE_SECOND; docs/engines.md states the measured figures.
TRAPS = [
    ("mujoco", "MuJoCo's own 2 ms timestep", lambda m: m.DEFAULT, lambda m: m.Setup("Euler", None), "theta", 0.3),
    (
        "mujoco",
        "ctrlrange -100..100",
        lambda m: m.ACCURATE,
        lambda m: m.Setup("RK4", 1e-3, ctrlrange=(-100, 100)),
        "theta",
        0.1,
    ),
    (
        "mujoco",
        "sensors read after mj_step",
        lambda m: m.ACCURATE,
        lambda m: m.Setup("RK4", 1e-3, read_sensors=True),
        "theta",
        1e-3,
    ),
    (
        "drake",
        "sampled output ports",
        lambda m: m.SETUPS["default"],
        lambda m: m.Setup(True, sampled_outputs=True),
        "alpha",
        5.0,
    ),
    (
        "drake",
        "actuation port left unfixed",
        lambda m: m.SETUPS["accurate"],
        lambda m: m.Setup(False, fix_input=False),
        "theta",
        0.3,
    ),
    ("pybullet", "no setGravity", lambda m: m.DEFAULT, _pybullet_without("set_gravity"), "theta", 0.1),
    ("pybullet", "inertia from the shapes", lambda m: m.DEFAULT, _pybullet_without("inertia_from_file"), "theta", 0.1),
    ("pybullet", "hidden link damping", lambda m: m.DEFAULT, _pybullet_without("remove_hidden_damping"), "theta", 1e-2),
    (
        "pybullet",
        "default velocity motor",
        lambda m: m.DEFAULT,
        _pybullet_without("disable_velocity_motor"),
        "theta",
        0.3,
    ),
    (
        "pybullet",
        "torque applied only when it changes",
        lambda m: m.DEFAULT,
        _pybullet_without("reapply_torque"),
        "theta",
        0.3,
    ),
]


@pytest.mark.parametrize(
    "name, trap, correct, trapped, field, at_least", TRAPS, ids=[f"{case[0]}: {case[1]}" for case in TRAPS]
)
def test_each_trap_turned_back_on_grows_the_error(name, trap, correct, trapped, field, at_least, reference_1s):
    module = engine(name)
    parameters = resolve_parameters({})
    right = error(module.simulate(ONE_SECOND, parameters, THETA0, OMEGA0, correct(module)), reference_1s, field)
    wrong = error(module.simulate(ONE_SECOND, parameters, THETA0, OMEGA0, trapped(module)), reference_1s, field)
    print(f"\n{name}, {trap}: max |d{field}| {wrong:.2e} (handled: {right:.2e})")
    assert wrong >= at_least
    assert wrong >= 10 * right


def test_pybullet_velocity_limit_is_raised():
    # Gravity off, no torque, 150 rad/s: theta = 150 t. PyBullet clamps at 100 rad/s by default.
    pybullet = engine("pybullet")
    parameters = resolve_parameters({"gravity": 0.0})
    coasting = schedule(0.0, stop_time=0.1, step_size=1e-3)
    expected = 150.0 * coasting.time
    run = pybullet.simulate(coasting, parameters, 0.0, 150.0, pybullet.DEFAULT)
    clamped = pybullet.simulate(
        coasting, parameters, 0.0, 150.0, pybullet.Setup(pybullet.DEFAULT.largest_step, raise_velocity_limit=False)
    )
    assert np.max(np.abs(run["theta"] - expected)) < 1e-12
    assert np.max(np.abs(clamped["theta"] - expected)) > 4.0


def off_grid_plan():
    """A CSV jump off the 1 ms grid and a short last step: communication steps of three sizes."""
    from pendulum_fmu.signals._torque_csv import TorqueTable

    table = TorqueTable(np.array([0.0, 0.0305, 0.0305, 0.1003]), np.array([40.0, 40.0, -60.0, -60.0]))
    plan = schedule(table, step_size=1e-3)
    assert len(set(np.round(plan.step_size, 12))) == 3
    return plan


@pytest.mark.parametrize("name", ["mujoco", "drake", "pybullet"])
def test_accurate_modes_take_unequal_steps(name):
    plan = off_grid_plan()
    run = engine(name).run(plan, theta0=THETA0, omega0=OMEGA0)
    assert error(run, reference_schedule(plan, theta0=THETA0, omega0=OMEGA0)) <= ACCURATE_BOUND[name]


def test_drake_default_refuses_unequal_steps():
    drake = engine("drake")
    with pytest.raises(drake.UnequalSteps, match="drake:default steps a discrete plant at one period"):
        drake.run(off_grid_plan(), mode="default")
