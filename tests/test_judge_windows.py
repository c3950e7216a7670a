"""A result judged a window of its run at a time (issue 48) is judged as in one window: every
wrong master of tests/test_judge.py, its verdict, diagnosis and every candidate's residual and
effect, with the run cut into windows of a few steps, so that each window's boundary falls
inside the mistake (a late input's carried step, a skipped step, a restart, a drifting clock).
"""

import math

import pytest

from benchmarks.masters import WRONG_MASTERS, run
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
        assert windowed.candidates.keys() == whole.candidates.keys()
        for candidate, score in whole.candidates.items():
            other = windowed.candidates[candidate]
            assert (score is None) == (other is None), candidate
            if score is not None:
                assert _close(other["residual"], score["residual"]), candidate
                assert _close(other["effect"], score["effect"]), candidate
        for ours, theirs in zip(windowed.regression_tools, whole.regression_tools, strict=True):
            assert {k: v for k, v in ours.items() if k != "half_height"} == {
                k: v for k, v in theirs.items() if k != "half_height"
            }
            assert _close(ours["half_height"], theirs["half_height"])
