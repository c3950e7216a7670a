"""Long results as users run into them (issue 48): a bad row deep in a file read by the fast
reader, a file a master is still writing, a last line cut off, a long run judged to JSON and
drawn. The fast reader (pyarrow, for files over ARROW_BYTES) must read what the row reader reads.
"""

import json

import numpy as np
import pytest

from pendulum_fmu import simulate
from pendulum_fmu._drawn_points import drawn_points
from pendulum_fmu.cli import main
from pendulum_fmu.fmu._results import write_csv
from pendulum_fmu.judging import _result_file
from pendulum_fmu.judging._result_file import ARROW_BYTES, ResultFileError, read_result


def _rows(count: int) -> list[str]:
    """time,theta rows of a 1-ms run (theta made up: these files are refused before judging)."""
    times = np.arange(count) * 1e-3
    return [f"{t!r},{theta!r}\n" for t, theta in zip(times.tolist(), np.sin(times).tolist(), strict=True)]


@pytest.mark.slow
def test_a_bad_row_in_the_millionth_line_is_named_in_one_line_and_nothing_is_written(tmp_path, capsys):
    rows = _rows(1_000_001)
    rows[999_998] = "999.998,x\n"  # line 1,000,000 of the file: the header is line 1
    result = tmp_path / "long.csv"
    result.write_text("time,theta\n" + "".join(rows))
    assert result.stat().st_size > ARROW_BYTES  # read by the fast reader, which gives no line
    verdict = tmp_path / "verdict.json"
    assert main(["judge", str(result), "--torque", "20", "--stop-time", "1000", "--json", str(verdict)]) == 2
    assert capsys.readouterr().err == f"pendulum-fmu judge: error: {result}:1000000: theta 'x' is not a number\n"
    assert not verdict.exists()


def test_a_last_line_cut_off_is_named(tmp_path):
    result = tmp_path / "cut.csv"
    result.write_text("time,theta\n0,0\n0.001,1e-7\n0.002,")
    with pytest.raises(ResultFileError, match=r"cut\.csv:4: the last line is cut short \(2 cells, no line end\)"):
        read_result(result)
    # With its line end the same row is a cell missing, said as such.
    result.write_text("time,theta\n0,0\n0.001,1e-7\n0.002,\n")
    with pytest.raises(ResultFileError, match=r"cut\.csv:4: theta '' is not a number"):
        read_result(result)


@pytest.mark.parametrize("fast", [False, True])
def test_a_file_that_grows_while_it_is_read_is_refused(tmp_path, monkeypatch, fast):
    result = tmp_path / "growing.csv"
    result.write_text("time,theta\n" + "".join(_rows(100_000 if fast else 10)))
    monkeypatch.setattr(_result_file, "ARROW_BYTES", 0 if fast else 1 << 40)
    reading = _result_file._read_arrow if fast else _result_file._read_rows

    def appending(*args):
        with open(result, "a") as file:  # a master writing its next rows meanwhile
            file.write("".join(_rows(3)))
        return reading(*args)

    monkeypatch.setattr(_result_file, "_read_arrow" if fast else "_read_rows", appending)
    with pytest.raises(
        ResultFileError, match=r"growing\.csv: the file went from [\d,]+ to [\d,]+ bytes while it was read"
    ):
        read_result(result)


@pytest.mark.slow
def test_a_long_run_judged_to_json_and_drawn_reads_as_the_row_reader_reads(tmp_path, monkeypatch, capsys):
    result = write_csv(simulate(20.0, stop_time=60.0), tmp_path / "long.csv")
    assert result.stat().st_size > ARROW_BYTES
    fast, slow = tmp_path / "fast.json", tmp_path / "slow.json"
    command = ["judge", str(result), "--torque", "20", "--stop-time", "60"]
    assert main([*command, "--json", str(fast), "--plot", str(tmp_path / "long.png")]) == 0
    monkeypatch.setattr(_result_file, "ARROW_BYTES", 1 << 40)
    assert main([*command, "--json", str(slow)]) == 0
    verdict = json.loads(fast.read_text())
    assert verdict == json.loads(slow.read_text())
    assert (verdict["verdict"], verdict["diagnosis"], verdict["points"]) == ("pass", "agrees", 60_001)
    assert verdict["max_abs_dtheta"] < 1e-11
    assert (tmp_path / "long.png").stat().st_size > 10_000


def test_a_long_series_is_drawn_from_few_points_keeping_every_extreme():
    time = np.linspace(0.0, 100.0, 2_000_001)
    spiky = np.sin(time)
    spiky[[12_345, 1_500_000]] = [7.0, -9.0]  # one-point spikes, which a plain thinning loses
    kept = drawn_points(time, spiky, np.cos(time))
    assert len(kept) <= 2000 * 6 and kept[0] == 0 and kept[-1] == len(time) - 1
    assert {12_345, 1_500_000} <= set(kept.tolist())
    # In any stretch, the drawn extremes are the true ones to within one span's change (0.05 s).
    spans = np.array_split(np.arange(len(time)), 97)
    for span in spans:
        drawn = np.intersect1d(kept, span)
        assert spiky[drawn].max() >= spiky[span].max() - 0.05 and spiky[drawn].min() <= spiky[span].min() + 0.05


@pytest.mark.slow
def test_the_memory_a_judge_takes_does_not_grow_with_the_result(tmp_path):
    """Three times the rows, the same peak: the result, the reference and the variants are held a
    window at a time, the regression tools' rows spilled to a temporary file (issue 48). Both
    results are longer than what pyarrow reads ahead (about 16 blocks of 1 MB).
    """
    import tracemalloc

    from pendulum_fmu.fmu._streamed import simulate_to_csv
    from pendulum_fmu.judging._judge import JudgedRun

    peaks = []
    for stop in (300.0, 900.0):
        result = simulate_to_csv(tmp_path / f"run{stop:g}.csv", 20.0, stop_time=stop).path
        run = JudgedRun(20.0, stop_time=stop, window_steps=4096)
        tracemalloc.start()
        judgement = run.judge(result)
        peaks.append(tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()
        assert (judgement.verdict, judgement.points) == ("pass", int(stop * 1000) + 1)
    # The whole result alone would be 40 bytes a row: 24 MB more for the longer run.
    assert peaks[1] < peaks[0] + 2_000_000, [f"{peak / 1e6:.1f} MB" for peak in peaks]
