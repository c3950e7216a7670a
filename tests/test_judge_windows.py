"""A result judged a window of its run at a time (issue 48) is judged as in one window: every
wrong master of tests/test_judge.py, its verdict, diagnosis and every candidate's residual and
effect, with the run cut into windows of a few steps, so that each window's boundary falls
inside the mistake (a late input's carried step, a skipped step, a restart, a drifting clock).
"""

import math

import numpy as np
import pytest

from benchmarks.masters import WRONG_MASTERS, run
from pendulum_fmu.fmu._results import write_csv
from pendulum_fmu.fmu._simulate import simulate
from pendulum_fmu.judging._diagnoses import AGREES
from pendulum_fmu.judging._judge import JudgedRun
from pendulum_fmu.scenarios._scenario_settings import read_settings
from pendulum_fmu.scenarios._scenarios import write_scenarios


@pytest.fixture(scope="module")
def kit(tmp_path_factory, fmu):
    folder = tmp_path_factory.mktemp("kit")
    write_scenarios(folder, fmu)
    return folder


def _judged(kit, name, window_steps):
    settings = read_settings(kit / f"{name}.json")
    output = kit / settings.pop("output")
    return JudgedRun(**settings, window_steps=window_steps).judge(output)


def _close(a, b):
    # The series restarts at each window's end: the same to rounding, relative to the difference.
    return a == b or math.isclose(a, b, rel_tol=1e-6, abs_tol=1e-12)


def _same_candidates(windowed, whole):
    """Every candidate applies in both judgements or in neither, with the same residual and effect."""
    assert windowed.candidates.keys() == whole.candidates.keys()
    for candidate, score in whole.candidates.items():
        other = windowed.candidates[candidate]
        assert (score is None) == (other is None), candidate
        if score is not None:
            assert _close(other["residual"], score["residual"]), candidate
            assert _close(other["effect"], score["effect"]), candidate


@pytest.mark.parametrize(("name", "mistake", "expected"), WRONG_MASTERS, ids=[f"{n}-{m}" for n, m, _ in WRONG_MASTERS])
def test_a_wrong_master_judged_in_windows_is_judged_as_in_one(kit, name, mistake, expected):
    run(kit, name, mistake)
    whole = _judged(kit, name, 1 << 30)
    for window_steps in (7, 64):
        windowed = _judged(kit, name, window_steps)
        assert (windowed.verdict, windowed.diagnosis, windowed.integrator) == (
            whole.verdict,
            whole.diagnosis,
            whole.integrator,
        )
        assert windowed.diagnosis == expected
        # Not the rows equal to the reference exactly, nor the worst of near ties: the reference's
        # rounding differs.
        assert windowed.points == whole.points
        assert _close(windowed.max_abs_dtheta, whole.max_abs_dtheta)
        _same_candidates(windowed, whole)
        for ours, theirs in zip(windowed.regression_tools, whole.regression_tools, strict=True):
            assert {k: v for k, v in ours.items() if k != "half_height"} == {
                k: v for k, v in theirs.items() if k != "half_height"
            }
            assert _close(ours["half_height"], theirs["half_height"])


def test_a_run_with_events_between_its_points_is_judged_in_windows_as_in_one(tmp_path):
    # Changes at random times, between the 1-ms points and on them, some twice (a jump): the
    # result has a row at each change between points, rows the summed-clock master
    # (SteppedOnClock) cannot make. Its lag once left a window's frame (an IndexError).
    rng = np.random.default_rng(0)
    between, on = rng.uniform(0.0, 0.4, 40), np.round(rng.uniform(0.0, 0.4, 20), 3)
    times = np.sort(np.r_[between, on, between[:5]])
    torque = tmp_path / "torque.csv"
    values = rng.uniform(-30.0, 30.0, len(times))
    np.savetxt(torque, np.c_[times, values], delimiter=",", header="time,torque", comments="")
    result = tmp_path / "result.csv"
    write_csv(simulate(str(torque), stop_time=0.4), result)
    whole = JudgedRun(str(torque), stop_time=0.4, window_steps=1 << 30).judge(result)
    windowed = JudgedRun(str(torque), stop_time=0.4, window_steps=20).judge(result)
    assert (windowed.verdict, windowed.diagnosis) == (whole.verdict, whole.diagnosis) == ("pass", AGREES)
    _same_candidates(windowed, whole)
