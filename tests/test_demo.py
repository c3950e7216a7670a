"""The tutorial end to end, as `pendulum-fmu demo` runs it."""

import re

import numpy as np
import pyarrow.parquet as pq

from pendulum_fmu.cli import main


def test_demo_runs_the_tutorial_end_to_end(tmp_path, capsys, monkeypatch):
    from pendulum_fmu import plot

    texts, finish = [], plot._finish

    def keep(fig, axes, title, path):  # every title and legend entry, in the units the text uses
        texts.extend([title, *(label for ax in np.ravel(axes) for label in ax.get_legend_handles_labels()[1])])
        return finish(fig, axes, title, path)

    monkeypatch.setattr(plot, "_finish", keep)
    assert main(["demo", "--output-dir", str(tmp_path)]) == 0
    assert not [text for text in texts if re.search(r"\bNm\b", text)]
    assert sum("N.m" in text for text in texts) >= 4, texts  # both comparisons' titles, the overlay's legend
    out = capsys.readouterr().out
    assert out.count("tools agree") == 2
    assert "theta(3 s) = 3.0000000000 rad" in out  # gravity off: tau t^2 / (2 I) = 3 rad at 3 s
    assert "theta(3 s) = 0.0814310965 rad" in out
    for figure in ("no_gravity/comparison.png", "gravity/comparison.png", "gravity_effect.png",
                   "parameter_study/sweep.png"):
        assert (tmp_path / figure).read_bytes()[:4] == b"\x89PNG"
    study = pq.read_table(tmp_path / "parameter_study/cases")
    assert sorted(study["torque"].to_pylist()) == [5.0, 10.0, 20.0, 40.0]
