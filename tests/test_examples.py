"""Every example, run small, against independent references."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from pendulum_fmu.oracle._reference import reference, reference_schedule
from pendulum_fmu.signals._torque_schedule import TorqueSchedule

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def load(name):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_constant_torque(tmp_path):
    runs = load("constant_torque").run(stop_time=0.5, output_dir=tmp_path)
    fmu, _ = runs[0.0]
    assert np.max(np.abs(fmu["theta"] - 10 / 30 * fmu["time"] ** 2)) < 1e-12
    fmu, _ = runs[9.81]
    assert np.max(np.abs(fmu["theta"] - reference(20.0, stop_time=0.5, parameters={"gravity": 9.81})["theta"])) < 1e-10
    assert {p.name for p in tmp_path.iterdir()} == {"no_gravity.png", "with_gravity.png"}


def test_gravity_overlay(tmp_path):
    runs = load("gravity_overlay").run(stop_time=0.5, output_dir=tmp_path)
    assert abs(runs["No gravity"]["theta"][-1] - 10 / 30 * 0.25) < 1e-12
    assert abs(runs["With gravity"]["theta"][-1] - reference(20.0, stop_time=0.5)["theta"][-1]) < 1e-10
    assert (tmp_path / "gravity_overlay.png").exists()


def test_parameter_study(tmp_path):
    table = load("parameter_study").run(torques=(5.0, 40.0), stop_time=0.5, output_dir=tmp_path)
    for torque in (5.0, 40.0):
        theta = table["theta"][table["torque"] == torque]
        assert np.max(np.abs(theta - reference(torque, stop_time=0.5)["theta"])) < 1e-10


def test_closed_loop_pd_settles_and_follows_the_applied_torques():
    example = load("closed_loop_pd")
    time, theta, omega, torque = example.run(stop_time=3.0)
    assert abs(theta[-1] - 0.5) < 2e-3
    assert example.settling_time(time, theta, 0.5) < 2.5
    # The same torque sequence through the reference gives the same trajectory.
    oracle = reference_schedule(TorqueSchedule(time=time, torque=torque, torque_rate=np.zeros_like(torque)))
    assert np.max(np.abs(theta - oracle["theta"])) < 1e-10
    assert np.max(np.abs(omega - oracle["omega"])) < 1e-10


def test_compare_with_opensim(tmp_path):
    pytest.importorskip("opensim", reason="OpenSim not installed: pip install -e '.[opensim]'")
    comparison = load("compare_with_opensim").run(stop_time=1.0, output_dir=tmp_path)
    assert comparison.agree and comparison.worst < 1e-9
    assert {(row["tool"], row["against"]) for row in comparison.differences} == {
        ("fmu", "reference"),
        ("opensim", "reference"),
        ("fmu", "opensim"),
    }


def test_fmpy_command_line(tmp_path):
    assert load("fmpy_command_line").run(stop_time=0.6, output_dir=tmp_path) < 1e-10
    assert (tmp_path / "result.csv").exists()


def test_every_example_has_help():
    for path in EXAMPLES.glob("*.py"):
        with pytest.raises(SystemExit) as exit_:
            load(path.stem).main(["--help"])
        assert exit_.value.code == 0


def test_swing_up_lqr_swings_up_and_holds_upright_in_both_environments(tmp_path):
    pytest.importorskip("gymnasium", reason="Gymnasium not installed: pip install -e '.[gym]'")
    pytest.importorskip("control", reason="python-control not installed: pip install -e '.[control]'")
    seeds = (0, 1, 2, 3, 4)
    episodes = load("swing_up_lqr").run(seeds=seeds, output_dir=tmp_path)
    assert (tmp_path / "swing_up_lqr.png").exists()
    for label, runs in episodes.items():
        for seed, run in zip(seeds, runs, strict=True):
            # Upright and held there for the last 50 steps (2.5 s) of the 200, in a return no
            # worse than 260 (seed 4 starts hanging nearly still: about -250 in both).
            assert len(run["torque"]) == 200, (label, seed)
            assert np.max(np.abs(run["theta"][-50:])) < 0.05, (label, seed)
            assert run["return"] > -260, (label, seed)
    # The same controller in the same physics: the returns within 3 % seed by seed.
    fmu, gym = episodes.values()
    np.testing.assert_allclose([run["return"] for run in fmu], [run["return"] for run in gym], rtol=0.03, atol=0.2)
    # The FMU environment's steps are the exact pendulum's: each step from the observed state
    # with the torque it held, through the reference, lands on the next observation.
    from pendulum_fmu.gym._conventions import PENDULUM_V1_PARAMETERS

    run = fmu[0]
    for k in range(200):
        step = reference(
            run["torque"][k],
            stop_time=0.05,
            step_size=0.05,
            parameters=PENDULUM_V1_PARAMETERS,
            theta0=run["theta"][k] + np.pi,
            omega0=run["omega"][k],
        )
        assert abs(np.angle(np.exp(1j * (step["theta"][-1] - np.pi - run["theta"][k + 1])))) < 1e-9, k
        assert abs(step["omega"][-1] - run["omega"][k + 1]) < 1e-9, k
