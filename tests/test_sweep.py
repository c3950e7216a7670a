"""The parameter study on a local dask cluster."""

import numpy as np
import pytest

from pendulum_fmu.reference import reference
from pendulum_fmu.sweep import run_sweep, sweep_grid

I_TOTAL = 30.0


def test_grid_on_a_local_cluster_matches_references(fmu, tmp_path, capsys):
    cases = sweep_grid([5.0, 20.0], [0.0, 9.81], {"damping": [0.0, 4.0]})
    assert len(cases) == 8
    summary = run_sweep(cases, output_dir=tmp_path, stop_time=0.5, workers=2, fmu_path=fmu)
    assert "100% Completed" in capsys.readouterr().out
    table = np.genfromtxt(summary["results"], delimiter=",", names=True)
    assert table.dtype.names == ("case", "torque", "gravity", "damping", "time", "theta", "omega", "alpha")
    assert len(table) == 8 * 501
    for number, case in enumerate(cases):
        rows = table[table["case"] == number]
        assert (rows["torque"][0], rows["gravity"][0], rows["damping"][0]) == (case["torque"], case["gravity"], case["damping"])
        if case["gravity"] == 0.0 and case["damping"] == 0.0:
            expected = 0.5 * case["torque"] / I_TOTAL * rows["time"] ** 2
            assert np.max(np.abs(rows["theta"] - expected)) < 1e-12
        else:
            oracle = reference(case["torque"], stop_time=0.5,
                               parameters={"gravity": case["gravity"], "damping": case["damping"]})
            assert np.max(np.abs(rows["theta"] - oracle["theta"])) < 1e-10
    assert summary["figure"].read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("arguments, message", [
    (([1.0], [9.81], {"colour": [1.0]}), "cannot sweep 'colour'"),
    (([], [9.81], None), "no values given for torque"),
    (([1.0], [float("nan")], None), "gravity values must be finite"),
])
def test_bad_grids(arguments, message):
    with pytest.raises(ValueError, match=message):
        sweep_grid(*arguments)
