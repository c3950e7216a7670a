"""compare walked a window of the run at a time (issue 48): the files it writes are those of the
run taken whole, the reference's restarts at the windows' boundaries are rounding, and a tool that
runs only whole is cut into the same windows.
"""

import csv
import dataclasses
import io
import math

import numpy as np
import pytest

from pendulum_fmu.comparing import _compare_tools as compare_tools
from pendulum_fmu.comparing._compare import compare
from pendulum_fmu.comparing._walk import TEXT_ROWS, trajectory_block, write_trajectory_rows
from pendulum_fmu.fmu._results import fields
from pendulum_fmu.fmu._simulate import simulate
from pendulum_fmu.oracle._reference import reference

# A swing with gravity and a sign change of the torque, so that theta and omega turn back.
SIGNAL = dict(torque=lambda t: 20.0 * np.cos(3.0 * t), stop_time=2.0, step_size=1e-3)
WINDOW = 97  # grid steps a window: 21 windows, the last a short one


def run_compare(tmp_path, name, tools="fmu,reference", **options):
    signal = dict(SIGNAL)
    return compare(signal.pop("torque"), tools, output_dir=tmp_path / name, **signal, **options)


def old_trajectories(runs: dict) -> bytes:
    """trajectories.csv as compare wrote it before it walked in windows: the same columns, each
    number its repr, through the csv module.
    """
    columns = {"time": next(iter(runs.values()))["time"]}
    for tool, run in runs.items():
        for name in fields(run)[1:]:
            columns[f"{name}_{tool}"] = run[name]
    text = io.StringIO(newline="")
    writer = csv.writer(text)
    writer.writerow(columns)
    writer.writerows(zip(*(map(repr, np.asarray(v, dtype=float).tolist()) for v in columns.values()), strict=True))
    return text.getvalue().encode()


def read_columns(path) -> dict[str, list[str]]:
    with open(path, newline="") as file:
        rows = list(csv.reader(file))
    return {name: [row[i] for row in rows[1:]] for i, name in enumerate(rows[0])}


def test_trajectory_rows_are_the_csv_modules_text_of_each_numbers_repr():
    rng = np.random.default_rng(48)
    runs = {}
    for label in ("reference", "fmu"):
        run = np.zeros(3 * TEXT_ROWS + 5, dtype=[(name, "f8") for name in ("time", "torque", "theta", "omega")])
        for name in run.dtype.names:
            run[name] = rng.standard_normal(len(run)) * 10.0 ** rng.integers(-300, 300, len(run))
        runs[label] = run
    runs["fmu"]["theta"][:4] = [np.nan, np.inf, -np.inf, -0.0]
    text = io.StringIO(newline="")
    block = trajectory_block(runs)
    write_trajectory_rows(text, block[:7], header=True)
    write_trajectory_rows(text, block[7:])
    assert text.getvalue().encode() == old_trajectories(runs)


def test_a_walked_compare_writes_the_trajectories_of_its_runs_byte_for_byte(tmp_path):
    comparison = run_compare(tmp_path, "walked", window_steps=WINDOW)
    assert comparison.whole == ()
    assert [len(run) for run in comparison.runs.values()] == [2001, 2001]  # a short run is kept whole
    assert comparison.trajectories.read_bytes() == old_trajectories(comparison.runs)
    # The FMU's rows are its whole run's, bit for bit, whatever the windows.
    fmu = simulate(SIGNAL["torque"], stop_time=2.0)
    assert np.array_equal(comparison.runs["fmu"], fmu)


def test_the_reference_restarted_at_every_window_is_the_whole_runs_to_rounding(tmp_path):
    walked = run_compare(tmp_path, "walked", window_steps=WINDOW)
    whole = run_compare(tmp_path, "whole")  # one window
    ours, theirs = read_columns(walked.trajectories), read_columns(whole.trajectories)
    assert list(ours) == list(theirs)
    for name in ours:
        if name == "time" or name.endswith("_fmu"):
            assert ours[name] == theirs[name], name
        else:
            apart = np.abs(np.array(ours[name], dtype=float) - np.array(theirs[name], dtype=float))
            assert apart.max() <= 1e-13, name
    # At each boundary, where the walk restarts the integration, as everywhere else.
    boundaries = np.arange(WINDOW, 2001, WINDOW)
    for name in ("theta", "omega"):
        apart = np.abs(walked.runs["reference"][name] - reference(SIGNAL["torque"], stop_time=2.0)[name])
        assert apart[boundaries].max() <= 1e-13 and apart.max() <= 1e-13
    for row, other in zip(walked.differences, whole.differences, strict=True):
        assert row.keys() == other.keys() and (row["tool"], row["against"]) == (other["tool"], other["against"])
        for key in row:
            if key.endswith(("_max", "_rms")):
                assert abs(row[key] - other[key]) <= 1e-13, key


def test_the_differences_are_those_of_the_whole_runs(tmp_path):
    comparison = run_compare(tmp_path, "walked", window_steps=WINDOW)
    (row,) = comparison.differences
    fmu, judge = comparison.runs["fmu"], comparison.runs["reference"]
    for name in ("theta", "omega", "alpha"):
        difference = np.abs(fmu[name] - judge[name])
        assert row[f"{name}_max"] == difference.max()
        assert math.isclose(row[f"{name}_rms"], np.sqrt(np.mean(difference**2)), rel_tol=1e-12)
    # The reference samples the callable itself: the same torque, to rounding.
    assert row["torque_max"] == np.abs(fmu["torque"] - judge["torque"]).max() < 1e-13
    assert comparison.largest_torque == 20.0 and comparison.agree
    with open(comparison.table, newline="") as file:
        (written,) = csv.DictReader(file)
    assert float(written["theta_max"]) == row["theta_max"] and float(written["seconds_per_step"]) > 0


def test_a_tool_that_runs_whole_is_cut_into_the_same_windows(tmp_path, monkeypatch):
    walked = run_compare(tmp_path, "walked", window_steps=WINDOW)
    monkeypatch.setitem(compare_tools.KINDS, "fmu", dataclasses.replace(compare_tools.KINDS["fmu"], windowed=None))
    whole = run_compare(tmp_path, "whole", window_steps=WINDOW)
    assert whole.whole == ("fmu",) and walked.whole == ()
    assert whole.trajectories.read_bytes() == walked.trajectories.read_bytes()
    for row, other in zip(walked.differences, whole.differences, strict=True):
        assert {**row, "seconds_per_step": 0} == {**other, "seconds_per_step": 0}


@pytest.mark.filterwarnings("ignore:gymnasium. Pendulum-v1 clipped the torque")
def test_engines_and_windowed_tools_compare_together(tmp_path):
    pytest.importorskip("gymnasium")
    comparison = run_compare(tmp_path, "mixed", "fmu,gymnasium,reference", window_steps=WINDOW)
    assert comparison.whole == ("gymnasium",)
    assert list(comparison.runs) == ["reference", "fmu", "gymnasium"]
    assert all(len(run) == 2001 for run in comparison.runs.values())
    rows = {(row["tool"], row["against"]): row for row in comparison.differences}
    assert list(rows) == [("fmu", "reference"), ("gymnasium", "reference"), ("fmu", "gymnasium")]
    gym, judge = comparison.runs["gymnasium"], comparison.runs["reference"]
    assert rows["gymnasium", "reference"]["theta_max"] == np.abs(gym["theta"] - judge["theta"]).max() > 1e-6
    assert comparison.trajectories.read_bytes() == old_trajectories(comparison.runs)


def test_a_long_walk_keeps_the_rows_its_figure_draws(tmp_path):
    comparison = compare(20.0, "fmu,reference", output_dir=tmp_path / "long", stop_time=60.0, window_steps=4096)
    kept = comparison.runs
    assert list(kept) == ["reference", "fmu"] and len(kept["fmu"]) < 60001 / 2
    assert np.array_equal(kept["fmu"]["time"], kept["reference"]["time"])
    written = read_columns(comparison.trajectories)
    assert len(written["time"]) == 60001
    for name in ("theta", "omega"):
        values = np.array(written[f"{name}_fmu"], dtype=float)
        assert kept["fmu"][name].max() == values.max() and kept["fmu"][name].min() == values.min()
        apart = np.abs(values - np.array(written[f"{name}_reference"], dtype=float))
        assert np.abs(kept["fmu"][name] - kept["reference"][name]).max() == apart.max()
    assert kept["fmu"]["time"][[0, -1]].tolist() == [0.0, 60.0]
    assert comparison.figure.read_bytes()[:4] == b"\x89PNG"


def test_ctrl_c_mid_walk_leaves_the_files_that_were_there(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "trajectories.csv").write_text("the old one\n")

    def torque(t):
        if t > 1.0:  # sampled as the walk makes the window that holds t
            raise KeyboardInterrupt
        return 20.0

    with pytest.raises(KeyboardInterrupt):
        compare(torque, "fmu,reference", output_dir=out, stop_time=2.0, window_steps=WINDOW)
    assert sorted(path.name for path in out.iterdir()) == ["trajectories.csv"]
    assert (out / "trajectories.csv").read_text() == "the old one\n"


@pytest.mark.slow
def test_the_memory_a_walked_compare_takes_does_not_grow_with_the_run(tmp_path):
    """Four times the windows, the same peak but for the figure's points: each window of the
    schedule is let go once the reference and the FMU have both taken it (itertools.tee held them
    in links of 57 windows, 1 MB each here).
    """
    import tracemalloc

    peaks = []
    for windows in (2, 2, 8):  # the first a warm-up: what a first run loads once
        stop = windows * 32.768
        tracemalloc.start()
        comparison = compare(
            20.0, "fmu,reference", output_dir=tmp_path / str(windows), stop_time=stop, window_steps=32768
        )
        peaks.append(tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()
        assert comparison.agree
    assert peaks[2] < peaks[1] + 3_000_000, [f"{peak / 1e6:.1f} MB" for peak in peaks]
