"""Gymnasium's and EnvPool's Pendulum-v1 as compare tools: the mapping of the FMU's parameters
held to the reference (first-order convergence), their clips, where the two differ, their
refusals, and the judge naming a Pendulum-v1 result semi-implicit Euler.

Each tool is skipped when its package is not installed. The reference is pendulum_fmu.reference
(its Taylor series), which shares no code with the tools.
"""

import itertools
import math
import warnings

import numpy as np
import pytest

from pendulum_fmu import Clipped, compare
from pendulum_fmu.cli import main
from pendulum_fmu.engines._pendulum_v1 import NotRepresentable
from pendulum_fmu.fmu._results import write_csv
from pendulum_fmu.judging._diagnoses import INTEGRATION, SEMI_IMPLICIT_EULER
from pendulum_fmu.judging._judge import judge
from pendulum_fmu.oracle._reference import reference_schedule
from pendulum_fmu.signals._torque_schedule import schedule

# Pendulum-v1's own rod (1 kg, 1 m, uniform) under g = 10, in the FMU's parameters.
ROD = {"mass": 1.0, "length": 0.5, "inertia": 1 / 12, "gravity": 10.0, "damping": 0.0}
# The FMU's defaults without damping: no rod, so the mapping onto one is what is tested.
HEAVY = {"mass": 40.0, "length": 0.5, "inertia": 20.0, "gravity": 9.81, "damping": 0.0}


def smooth(t):
    """A torque that stays inside Pendulum-v1's clip."""
    return 1.5 * math.sin(3.0 * t)


def tool(name):
    pytest.importorskip(name)
    import importlib

    return importlib.import_module(f"pendulum_fmu.engines.{name}")


def _run(module, plan, parameters, theta0, omega0):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = module.run(plan, parameters=parameters, theta0=theta0, omega0=omega0)
    return out, [str(warning.message) for warning in caught if warning.category is Clipped]


@pytest.mark.parametrize("parameters", [ROD, HEAVY], ids=["rod", "heavy"])
def test_gymnasium_converges_to_the_reference_at_first_order(parameters):
    """Semi-implicit Euler's error halves with the step: the mapped equation is the FMU's."""
    errors = []
    for step in (0.05, 0.025, 0.0125):
        plan = schedule(smooth, stop_time=3.0, step_size=step)
        out, clipped = _run(tool("gymnasium"), plan, parameters, 1.0, 0.5)
        expected = reference_schedule(plan, parameters=parameters, theta0=1.0, omega0=0.5)
        assert clipped == [] and np.array_equal(out["torque"][:-1], plan.torque)
        errors.append(float(np.max(np.abs(out["theta"] - expected["theta"]))))
    print(f"\ngymnasium, {errors} rad at 0.05, 0.025, 0.0125 s")
    assert 1e-4 < errors[-1] < 0.05
    assert all(1.6 < coarse / fine < 2.5 for coarse, fine in itertools.pairwise(errors))


def test_a_gymnasium_result_is_judged_semi_implicit_euler(tmp_path):
    plan = schedule(smooth, stop_time=10.0, step_size=0.05)
    out, clipped = _run(tool("gymnasium"), plan, HEAVY, 1.0, 0.5)
    assert clipped == []
    judgement = judge(
        write_csv(out, tmp_path / "gymnasium.csv"),
        smooth,
        stop_time=10.0,
        step_size=0.05,
        parameters=HEAVY,
        theta0=1.0,
        omega0=0.5,
    )
    assert judgement.verdict == "fail" and judgement.max_abs_dtheta > 0.01
    assert (judgement.diagnosis, judgement.integrator) == (INTEGRATION, SEMI_IMPLICIT_EULER)
    assert judgement.residual < 1e-12
    assert judgement.summary()["integrator"] == SEMI_IMPLICIT_EULER


def test_gymnasium_clips_the_torque_and_says_so():
    plan = schedule(3.0, stop_time=1.0, step_size=0.05)
    out, clipped = _run(tool("gymnasium"), plan, ROD, 0.0, 0.0)
    assert clipped == [
        "gymnasium: Pendulum-v1 clipped the torque to +-2 N.m in 20 of 20 steps (first from t = 0 s): "
        "its result is the clipped run's"
    ]
    assert np.all(out["torque"] == 2.0)
    at_two, _ = _run(tool("gymnasium"), schedule(2.0, stop_time=1.0, step_size=0.05), ROD, 0.0, 0.0)
    assert np.array_equal(out["theta"], at_two["theta"])


@pytest.fixture(scope="module")
def spin():
    """2 N.m from EnvPool's start: the rod falls from near the top and spins past 8 rad/s."""
    theta0, omega0 = tool("envpool").start()
    plan = schedule(2.0, stop_time=2.0, step_size=0.05)
    return plan, theta0, omega0


def test_the_speed_clip_moves_gymnasium_by_the_clipped_speed_and_envpool_by_the_unclipped(spin):
    plan, theta0, omega0 = spin
    runs = {name: _run(tool(name), plan, ROD, theta0, omega0) for name in ("gymnasium", "envpool")}
    for name, (out, clipped) in runs.items():
        assert len(clipped) == 1 and clipped[0].startswith(f"{name}: Pendulum-v1 clipped the speed to +-8 rad/s in ")
        assert np.max(np.abs(out["omega"])) == 8.0
    gym, pool = runs["gymnasium"][0], runs["envpool"][0]
    held = np.flatnonzero(np.abs(gym["omega"][1:]) == 8.0)  # the steps whose new speed was clipped
    assert len(held) > 5
    # Gymnasium: theta += clipped speed * dt; EnvPool: theta += unclipped speed * dt, more.
    np.testing.assert_allclose(np.diff(gym["theta"])[held], 8.0 * 0.05, rtol=1e-12)
    first = held[0]
    assert np.diff(pool["theta"])[first] > 8.0 * 0.05 + 1e-3
    # Up to the first clip the two are one run, to EnvPool's float32 observation.
    assert np.max(np.abs(gym["theta"][: first + 1] - pool["theta"][: first + 1])) < 1e-6
    assert abs(gym["theta"][first + 1] - pool["theta"][first + 1]) > 1e-3


def test_envpool_agrees_with_gymnasium_to_its_float32_observation_where_no_clip_bites(spin):
    _, theta0, omega0 = spin
    levels = np.random.default_rng(0).uniform(-2, 2, 40).astype(np.float32).astype(float)
    plan = schedule(levels, step_size=0.05)
    (gym, gym_clipped), (pool, pool_clipped) = (
        _run(tool(name), plan, ROD, theta0, omega0) for name in ("gymnasium", "envpool")
    )
    assert gym_clipped == pool_clipped == []
    assert np.max(np.abs(gym["theta"] - pool["theta"])) < 1e-6
    assert np.max(np.abs(gym["omega"] - pool["omega"])) < 1e-5
    expected = reference_schedule(plan, parameters=ROD, theta0=theta0, omega0=omega0)
    assert np.max(np.abs(pool["theta"] - expected["theta"])) > 1e-3  # Euler at 0.05 s, not the pendulum


@pytest.mark.parametrize(
    ("name", "change", "message"),
    [
        ("gymnasium", {"parameters": {**ROD, "damping": 2.0}}, "gymnasium: Pendulum-v1 has no damping"),
        ("envpool", {"parameters": {**ROD, "damping": 2.0}}, "envpool: Pendulum-v1 has no damping"),
        ("envpool", {"parameters": HEAVY}, "these parameters give 30 kg.m2 and 196.2 N.m"),
        ("envpool", {"step_size": 0.01}, "this run's steps are 0.01 s"),
        ("envpool", {"omega0": 0.0}, "cannot be put in a state"),
    ],
)
def test_a_run_pendulum_v1_cannot_represent_is_refused_in_one_line(spin, name, change, message):
    _, theta0, omega0 = spin
    run = {"parameters": ROD, "theta0": theta0, "omega0": omega0, "step_size": 0.05, **change}
    plan = schedule(1.0, stop_time=0.5, step_size=run.pop("step_size"))
    with pytest.raises(NotRepresentable, match=message) as refused:
        tool(name).run(plan, **run)
    assert "\n" not in str(refused.value) and "leave" in str(refused.value)


def test_compare_runs_both_and_the_command_says_the_clip_in_one_line(spin, tmp_path, capsys):
    _, theta0, omega0 = spin
    with pytest.warns(Clipped, match="clipped the speed"):
        comparison = compare(
            2.0,
            ["reference", "gymnasium", "envpool"],
            output_dir=tmp_path,
            stop_time=2.0,
            step_size=0.05,
            parameters=ROD,
            theta0=theta0,
            omega0=omega0,
        )
    assert sorted(comparison.runs) == ["envpool", "gymnasium", "reference"]
    assert not comparison.agree
    argv = ["compare", "--torque", "3", "--tools", "fmu,gymnasium", "--step-size", "0.05", "--stop-time", "0.5"]
    argv += ["--set", "mass=1", "--set", "inertia=0.08333333333333333", "--set", "gravity=10"]
    assert main([*argv, "--output-dir", str(tmp_path / "cli")]) == 1
    assert (
        "pendulum-fmu compare: gymnasium: Pendulum-v1 clipped the torque to +-2 N.m in 10 of 10 steps"
        in capsys.readouterr().err.splitlines()[0]
    )
