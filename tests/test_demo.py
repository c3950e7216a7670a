"""The tutorial end to end, as `pendulum-fmu demo` runs it."""

import re

import numpy as np
import pyarrow.parquet as pq

from pendulum_fmu.cli import main


def test_demo_runs_the_tutorial_end_to_end(tmp_path, capsys, monkeypatch):
    from pendulum_fmu.figures import _plot as plot

    texts, finish = [], plot._finish

    def keep(fig, axes, title, path):  # every title and legend entry, in the units the text uses
        texts.extend([title, *(label for ax in np.ravel(axes) for label in ax.get_legend_handles_labels()[1])])
        return finish(fig, axes, title, path)

    monkeypatch.setattr(plot, "_finish", keep)
    # A previous demo's overlay and someone's notes: --overwrite replaces the one, keeps the other.
    (tmp_path / "gravity_effect.png").write_text("old")
    (tmp_path / "notes.txt").write_text("mine")
    assert main(["demo", "--output-dir", str(tmp_path), "--overwrite"]) == 0
    assert (tmp_path / "notes.txt").read_text() == "mine"
    assert not [text for text in texts if re.search(r"\bNm\b", text)]
    assert sum("N.m" in text for text in texts) >= 4, texts  # both comparisons' titles, the overlay's legend
    out = capsys.readouterr().out
    assert out.count("tools agree") == 2
    assert "theta(3 s) = 3.0000000000 rad" in out  # gravity off: tau t^2 / (2 I) = 3 rad at 3 s
    assert "theta(3 s) = 0.0814310965 rad" in out
    for figure in (
        "no_gravity/comparison.png",
        "gravity/comparison.png",
        "gravity_effect.png",
        "parameter_study/sweep.png",
    ):
        assert (tmp_path / figure).read_bytes()[:4] == b"\x89PNG"
    study = pq.read_table(tmp_path / "parameter_study/cases")
    assert sorted(study["torque"].to_pylist()) == [5.0, 10.0, 20.0, 40.0]


def test_a_second_demo_into_the_same_folder_is_refused(tmp_path, capsys):
    """Refused before anything runs: the study in parameter_study is what plain sweep refuses to
    replace, and the figures are the previous run's results.
    """
    (tmp_path / "parameter_study").mkdir()
    (tmp_path / "parameter_study/study.json").write_text("{}")
    (tmp_path / "gravity_effect.png").write_text("old")
    assert main(["demo", "--output-dir", str(tmp_path)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.splitlines() == [
        f"pendulum-fmu demo: error: {tmp_path} already holds a demo's outputs (gravity_effect.png, "
        "parameter_study): choose another output directory, or add --overwrite to run the demo again in "
        "their place"
    ]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["gravity_effect.png", "parameter_study"]
    assert (tmp_path / "gravity_effect.png").read_text() == "old"
