"""simulate --output written as it runs (issue 48): a window of steps at a time through one FMU
instance that carries its state on, the file byte for byte what write_csv(simulate(...)) writes,
for every kind of signal and loop; nothing left behind when the run is refused or fails.
"""

import filecmp
import shutil

import numpy as np
import pytest

from pendulum_fmu import InvalidInput
from pendulum_fmu._drawn_points import DrawnRows, drawn_points
from pendulum_fmu.cli import main
from pendulum_fmu.fmu import _native_loop
from pendulum_fmu.fmu._results import write_csv
from pendulum_fmu.fmu._simulate import simulate
from pendulum_fmu.fmu._streamed import simulate_to_csv

# Jumps between grid points (0.0123, 0.0371) and on one (0.02), a kink, a ramp down.
TORQUE_CSV = "time,torque\n0,5\n0.0123,5\n0.0123,-30\n0.02,-30\n0.02,12\n0.0371,40\n0.0371,0\n0.05,-7\n"

SIGNALS = {
    "constant": (20.0, {}),
    "callable": (lambda t: 30.0 * np.sin(40.0 * t) + 5.0 * t, {}),
    "csv": ("torque.csv", {"step_size": 1e-3}),
    "csv ramp": ("torque.csv", {"step_size": 1e-3, "ramp": True}),
    "callable ramp": (lambda t: 30.0 * np.sin(40.0 * t), {"ramp": True}),
}
CASE = dict(stop_time=0.06, parameters={"damping": 0.5}, theta0=0.2, omega0=-1.0, tolerance=1e-8)


def _signal(name, folder):
    torque, options = SIGNALS[name]
    if torque == "torque.csv":
        torque = folder / "torque.csv"
        torque.write_text(TORQUE_CSV)
    return torque, {**CASE, **options}


def _same_as_whole(folder, torque, options, window_steps, **streamed_options):
    whole = write_csv(simulate(torque, **options), folder / "whole.csv")
    streamed = simulate_to_csv(
        folder / "streamed.csv", torque, window_steps=window_steps, **options, **streamed_options
    )
    assert filecmp.cmp(whole, streamed.path, shallow=False)
    return streamed


@pytest.mark.parametrize("name", SIGNALS)
@pytest.mark.parametrize("window_steps", [1, 7, 20, 10_000])
def test_the_file_written_as_it_runs_is_the_whole_runs_byte_for_byte(fmu, tmp_path, name, window_steps):
    torque, options = _signal(name, tmp_path)
    streamed = _same_as_whole(tmp_path, torque, {**options, "fmu_path": fmu}, window_steps)
    whole = simulate(torque, **options, fmu_path=fmu)
    assert streamed.steps == len(whole) - 1 and streamed.last.tolist() == whole[-1:].tolist()
    assert streamed.largest["theta"] == np.max(np.abs(whole["theta"]))
    assert not list(tmp_path.glob(".*partial*"))  # the temporary was renamed into place


@pytest.mark.parametrize("name", ["constant", "csv ramp"])
def test_the_python_loop_streams_the_same_file(fmu, tmp_path, monkeypatch, name):
    torque, options = _signal(name, tmp_path)
    whole = write_csv(simulate(torque, **options, fmu_path=fmu), tmp_path / "native.csv")
    # Another file name is another Simulator, made without the native loop.
    copy = tmp_path / "Pendulum.fmu"
    shutil.copy(fmu, copy)
    monkeypatch.setattr(_native_loop, "available", lambda: False)
    streamed = simulate_to_csv(tmp_path / "python.csv", torque, window_steps=9, **options, fmu_path=copy)
    assert filecmp.cmp(whole, streamed.path, shallow=False)


def test_an_fmi3_fmu_streams_the_same_file(fmu3, tmp_path):
    _same_as_whole(tmp_path, 20.0, {**CASE, "fmu_path": fmu3}, 11)


def test_the_webassembly_binary_streams_the_same_file(tmp_path):
    pytest.importorskip("wasmtime", reason="the wasm extra (wasmtime) is not installed")
    _same_as_whole(tmp_path, 20.0, {**CASE, "platform": "wasm32-wasip2"}, 13)


@pytest.mark.slow
def test_a_run_of_300001_rows_in_six_windows_is_the_whole_runs_byte_for_byte(fmu, tmp_path):
    torque = lambda t: 20.0 + 5.0 * np.sin(t)  # noqa: E731
    _same_as_whole(tmp_path, torque, {"stop_time": 300.0, "fmu_path": fmu}, 50_000)


def test_a_refused_run_leaves_nothing_and_says_what_simulate_says(fmu, tmp_path):
    for options in ({"stop_time": -1.0}, {"parameters": {"mass": -1.0}}):
        with pytest.raises(InvalidInput) as whole:
            simulate(20.0, fmu_path=fmu, **options)
        with pytest.raises(InvalidInput) as streamed:
            simulate_to_csv(tmp_path / "out.csv", 20.0, fmu_path=fmu, **options)
        assert str(streamed.value) == str(whole.value)
        assert list(tmp_path.iterdir()) == []


def test_the_command_writes_the_file_and_the_figure_and_prints_what_it_printed(fmu, tmp_path, capsys):
    arguments = ["simulate", "--torque", "20", "--stop-time", "2", "--fmu", str(fmu)]
    assert main(arguments) == 0
    printed = capsys.readouterr().out
    assert main([*arguments, "--output", str(tmp_path / "out.csv"), "--plot", str(tmp_path / "out.png")]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == printed.strip() and lines[2] == f"wrote {tmp_path / 'out.png'}"
    assert filecmp.cmp(
        write_csv(simulate(20.0, stop_time=2, fmu_path=fmu), tmp_path / "whole.csv"), tmp_path / "out.csv"
    )
    assert (tmp_path / "out.png").stat().st_size > 1000


def test_the_rows_drawn_of_a_run_in_blocks_keep_every_extreme_of_their_spans():
    rng = np.random.default_rng(48)
    rows = np.zeros(400_001, dtype=[("time", "f8"), ("theta", "f8"), ("omega", "f8")])
    rows["time"] = np.arange(len(rows)) * 1e-3
    rows["theta"], rows["omega"] = np.cumsum(rng.normal(size=(2, len(rows))), axis=1)
    span = (0.0, 400.0)
    drawn = DrawnRows(("theta", "omega"), span, columns=200)
    for block in np.array_split(rows, np.sort(rng.integers(1, len(rows), 30))):
        drawn.add(block)
    kept = drawn.rows
    assert 200 * 2 <= len(kept) <= 200 * 6 and np.all(np.diff(kept["time"]) > 0)
    # Every span: its first, last, least and greatest rows are among the kept.
    column = np.minimum((rows["time"] / 2.0).astype(np.int64), 199)
    kept_column = np.minimum((kept["time"] / 2.0).astype(np.int64), 199)
    for span_index in range(200):
        inside, kept_inside = rows[column == span_index], kept[kept_column == span_index]
        for name in ("theta", "omega"):
            assert kept_inside[name].max() == inside[name].max() and kept_inside[name].min() == inside[name].min()
        assert kept_inside["time"][0] == inside["time"][0] and kept_inside["time"][-1] == inside["time"][-1]
    # A short run is kept whole, as drawn_points keeps it.
    short = DrawnRows(("theta",), (0.0, 0.999))
    short.add(rows[:1000])
    assert (
        np.array_equal(short.rows, rows[:1000]) and len(drawn_points(rows["time"][:1000], rows["theta"][:1000])) == 1000
    )
