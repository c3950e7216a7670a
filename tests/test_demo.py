"""The tutorial end to end, as `pendulum-fmu demo` runs it."""

import pyarrow.parquet as pq

from pendulum_fmu.cli import main


def test_demo_runs_the_tutorial_end_to_end(tmp_path, capsys):
    assert main(["demo", "--output-dir", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert out.count("tools agree") == 2
    assert "theta(3 s) = 3.0000000000 rad" in out  # gravity off: tau t^2 / (2 I) = 3 rad at 3 s
    assert "theta(3 s) = 0.0814310965 rad" in out
    for figure in ("no_gravity/comparison.png", "gravity/comparison.png", "gravity_effect.png",
                   "parameter_study/sweep.png"):
        assert (tmp_path / figure).read_bytes()[:4] == b"\x89PNG"
    study = pq.read_table(tmp_path / "parameter_study/cases")
    assert sorted(study["torque"].to_pylist()) == [5.0, 10.0, 20.0, 40.0]
