"""A sweep's grid of cases: every combination of its axes, and the values it refuses."""

import pytest

from pendulum_fmu.sweep import Study, sweep_grid


@pytest.mark.parametrize(
    "arguments, message",
    [
        (([1.0], [9.81], {"colour": [1.0]}), "cannot sweep 'colour': extra takes mass, length, inertia, damping"),
        (([1.0], [9.81], {"gravity": [1.0]}), "give gravity values as the gravities argument"),
        (([], [9.81]), "no values given for torque"),
        (([1.0], [9.81], {"mass": []}), "no values given for mass"),
        (([1.0], [float("nan")]), "gravity values must be finite"),
        (([float("inf")],), "torque values must be finite"),
        ((["heavy"],), "torque values must be numbers"),
        (([[1.0, 2.0]],), "torque values must be a flat list"),
        (([1.0, 2.0, 1.0],), "torque values repeat"),
    ],
)
def test_bad_grids(arguments, message):
    with pytest.raises(ValueError, match=message):
        sweep_grid(*arguments)


def test_a_grid_is_the_product_of_its_axes():
    grid = sweep_grid([1.0, 2.0], [0.0, 9.81], {"damping": [0.5, 1.5, 2.5]})
    assert len(grid) == 12 and grid[0] == {"torque": 1.0, "gravity": 0.0, "damping": 0.5}
    assert grid[-1] == {"torque": 2.0, "gravity": 9.81, "damping": 2.5}
    assert grid[7] == {"torque": 2.0, "gravity": 0.0, "damping": 1.5}
    with pytest.raises(IndexError):
        grid[12]


@pytest.mark.parametrize(
    "cases, stop_time, chunk_cases",
    [
        (100_000, 0.01, 1_563),  # short cases: about 64 chunks, as their steps allow
        (4_096, 3.0, 64),  # about 64 chunks
        (1_000_000, 3.0, 888),  # 888 3-s cases: their 3 x 3,001 doubles each within 64 MB
        (1_000_000, 1.0, 2_664),  # shorter cases: more, as many as 64 MB of recordings hold
        (256, 600.0, 4),  # long cases: still about 64 chunks
        (100, 2_000.0, 1),  # a chunk's recordings within 64 MB: a 2,000-s case's 3 x 2,000,001 doubles are 48 MB
    ],
)
def test_a_study_is_cut_into_chunks_of_a_bounded_size(cases, stop_time, chunk_cases):
    study = Study(sweep_grid([float(t) for t in range(1, cases + 1)]), stop_time=stop_time)
    assert study.chunk_cases() == chunk_cases
