"""Torque signals: schedules from constants, callables and CSVs; clear errors for bad files."""

import re
from pathlib import Path

import numpy as np
import pytest

from pendulum_fmu.signals import _torque_csv
from pendulum_fmu.signals._schedule_csv import write_torque_csv
from pendulum_fmu.signals._time_grid import BYTES_PER_STEP, step_count
from pendulum_fmu.signals._torque_csv import TorqueFileError, read_torque_csv
from pendulum_fmu.signals._torque_schedule import schedule


def test_csv_jumps_become_communication_points(tmp_path):
    csv = tmp_path / "t.csv"
    csv.write_text("time,torque\n0,1\n0.0105,1\n0.0105,-2\n0.02,-2\n")
    plan = schedule(csv, step_size=0.002)
    assert plan.time[0] == 0 and plan.time[-1] == 0.02
    assert 0.0105 in plan.time
    jump = np.flatnonzero(plan.time == 0.0105)[0]
    assert np.all(plan.torque[:jump] == 1) and np.all(plan.torque[jump:] == -2)
    assert np.all(plan.torque_rate == 0)


def test_ramp_follows_a_linear_csv_segment(tmp_path):
    csv = tmp_path / "t.csv"
    csv.write_text("time,torque\n0,0\n1,10\n")
    plan = schedule(csv, step_size=0.25, ramp=True)
    assert np.allclose(plan.torque, [0, 2.5, 5, 7.5]) and np.allclose(plan.torque_rate, 10)
    held = schedule(csv, step_size=0.25)
    assert np.allclose(held.torque, [0, 2.5, 5, 7.5]) and not held.torque_rate.any()


def test_written_schedule_reads_back(tmp_path):
    plan = schedule(lambda t: 3.0 if t < 0.5 else -1.0, stop_time=1.0, step_size=0.1)
    table = read_torque_csv(write_torque_csv(tmp_path / "t.csv", plan))
    again = schedule(table, step_size=0.1)
    assert np.allclose(again.time, plan.time) and np.array_equal(again.torque, plan.torque)


@pytest.mark.parametrize(
    "content, message",
    [
        ("", "the file is empty"),
        ("t,torque\n0,1\n", "t.csv:1: missing column 'time'"),
        ("time,force\n0,1\n", "t.csv:1: missing column 'torque'"),
        ("time,torque\n0,1\n1,abc\n", "t.csv:3: torque 'abc' is not a number"),
        ("time,torque\n0,1\n1\n", "t.csv:3: torque '' is not a number"),
        ("time,torque\n0,1\n2,1\n1,1\n", "t.csv:4: time 1 goes backwards"),
        ("time,torque\n0,1\n1,nan\n", "t.csv:3: torque is nan"),
        ("time,torque\n0,1\ninf,1\n", "t.csv:3: time is inf"),
        ("time,torque\n0,1\n1,1\n1,2\n1,3\n", "t.csv:5: time 1 appears three times"),
        ("time,torque\n", "no data rows"),
        ("time,torque\n0,1\n1,1_0\n", "t.csv:3: torque '1_0' is not a number"),  # Python's float takes it
        ("time,torque\n0,1\n1,\uff11\n", "t.csv:3: torque '\uff11' is not a number"),  # a fullwidth 1
        ("time,torque\n0,1\n1,2,3\n", "t.csv:3: 3 columns, but the header names 2"),
        ("\n\ntime,torque\n0,1\n", "t.csv:1: the line is blank; the header, e.g. time,torque, must be the first line"),
        ('time,torque\n"0","1,5"\n', "t.csv:2: torque '1,5' is not a number"),
    ],
)
def test_bad_files_name_file_row_and_problem(tmp_path, content, message):
    csv = tmp_path / "t.csv"
    csv.write_text(content, encoding="utf-8")
    with pytest.raises(TorqueFileError, match=re.escape(message)) as error:
        read_torque_csv(csv)
    assert str(error.value).startswith(str(csv))
    assert "\n" not in str(error.value)


def test_missing_file(tmp_path):
    with pytest.raises(TorqueFileError, match="cannot read"):
        read_torque_csv(tmp_path / "absent.csv")


def test_bad_arguments():
    with pytest.raises(ValueError, match="step size"):
        schedule(1.0, step_size=0)
    with pytest.raises(ValueError, match="stop time"):
        schedule(1.0, stop_time=-1)
    with pytest.raises(ValueError, match=r"the torque is nan at t = 0\.0"):
        schedule(lambda t: float("nan"), stop_time=0.1)


def test_a_byte_order_mark_is_accepted(tmp_path):
    # What spreadsheet programs write when they save UTF-8.
    csv = tmp_path / "t.csv"
    csv.write_bytes("\ufefftime,torque\r\n0,1\r\n2,3\r\n".encode("utf-8"))
    table = read_torque_csv(csv)
    assert table.time.tolist() == [0, 2] and table.torque.tolist() == [1, 3]


def test_another_encoding_names_file_and_line(tmp_path):
    csv = tmp_path / "t.csv"
    csv.write_bytes("time,torque\n0,1\n1,2 # Drehmoment \u00fcber\n".encode("latin-1"))
    with pytest.raises(TorqueFileError, match=r"t.csv:3: byte 0xfc is not UTF-8; save the file as UTF-8"):
        read_torque_csv(csv)


def test_extra_columns_and_blank_lines_are_ignored(tmp_path):
    csv = tmp_path / "t.csv"
    csv.write_text("label,torque,time\na,1,0\n\nb,2,0.5\n")
    table = read_torque_csv(csv)
    assert table.time.tolist() == [0, 0.5] and table.torque.tolist() == [1, 2]


def test_errors_after_blank_lines_name_the_file_line(tmp_path):
    csv = tmp_path / "t.csv"
    csv.write_text("time,torque\n0,1\n\n\n2,1\n1,1\n")
    with pytest.raises(TorqueFileError, match=r"t\.csv:6: time 1 goes backwards"):
        read_torque_csv(csv)


@pytest.mark.skipif(not Path("/proc/meminfo").is_file(), reason="needs Linux's /proc/meminfo as the reference")
def test_a_run_larger_than_the_free_memory_is_refused():
    # The kernel's own figure, read without psutil, which the package now asks on every OS.
    free_kib = next(
        int(line.split()[1])
        for line in Path("/proc/meminfo").read_text().splitlines()
        if line.startswith("MemAvailable:")
    )
    steps = 2 * free_kib * 1024 // BYTES_PER_STEP
    with pytest.raises(ValueError, match=r"needs [\d.]+ GiB and the machine has ([\d.]+) GiB free") as refused:
        step_count(0.0, float(steps), 1.0, max_steps=steps)
    said = float(re.search(r"has ([\d.]+) GiB free", str(refused.value)).group(1))
    assert said == pytest.approx(free_kib / 2**20, rel=0.1)  # other jobs allocate in between


@pytest.mark.parametrize(
    "start, stop, step, count",
    [
        (0.0, 1e308, 1e-3, "about 1e+311"),
        (-1e308, 1e308, 1.0, "about 2e+308"),  # the span itself is past the largest double
        (0.0, 0.01, 1e-320, "about 1e+318"),
        (0.0, 1e20, 1e-3, "about 1e+23"),  # past 2**53 the trailing digits would be a float's rounding
        (0.0, 9e12, 1e-3, "9,000,000,000,000,000"),
    ],
)
def test_a_count_past_the_largest_double_is_refused_like_any_long_run(start, stop, step, count):
    with pytest.raises(ValueError, match=re.escape(f"is {count} steps, over the limit of 10,000,000")):
        step_count(start, stop, step)


def test_a_count_past_the_largest_double_counts_exactly():
    # Raising the limit past it shows the count is the exact ceiling, not an overflowed float.
    with pytest.raises(ValueError, match=r"is about 3e\+320 steps, which needs about 2.68e\+313 GiB"):
        step_count(0.0, 3.0, 1e-320, max_steps=10**400)


@pytest.mark.filterwarnings("error")  # numpy's overflow warning was a line on stderr
def test_rows_near_the_largest_double_interpolate_without_overflow(tmp_path):
    csv = tmp_path / "t.csv"
    csv.write_text("time,torque\n0,1e308\n0.01,-1e308\n")
    plan = schedule(csv, step_size=0.0025)
    assert plan.torque.tolist() == pytest.approx([1e308, 0.5e308, 0.0, -0.5e308], rel=1e-15, abs=1e293)
    with pytest.raises(
        ValueError,
        match=re.escape(
            f"{csv} ramps from 1e+308 to 5e+307 N.m between t = 0 and 0.0025 s, a rate past the largest double"
        ),
    ):
        schedule(csv, step_size=0.0025, ramp=True)


def test_ordinary_rows_keep_the_documented_interpolation(tmp_path):
    # The overflow fallback weighs the rows differently; it must not touch finite results.
    csv = tmp_path / "t.csv"
    csv.write_text("time,torque\n0,0.1\n0.3,0.7\n")
    t = np.array([0.1, 0.2])
    assert read_torque_csv(csv).value_after(t).tolist() == (0.1 + (0.7 - 0.1) * (t - 0) / 0.3).tolist()


def test_quoted_cells_are_numbers(tmp_path):
    csv = tmp_path / "t.csv"
    csv.write_text('time,torque\n"0","1"\n1,2\n')
    assert read_torque_csv(csv).torque.tolist() == [1, 2]


# Cells each reader takes in its own way or refuses: the Python reader of a small file must
# leave every one of them to pyarrow, or read it to pyarrow's double.
UNUSUAL_CELLS = ["1.", ".5", "-.5", "1E+05", "-0", "007", "+1", " 1", "1 ", "1_0", "\u0663", "inf", "1e400"]
UNUSUAL_CELLS += ["nan", "", '"2"', "0x10", "1e-400", "4.9e-324", "2.4703282292062328e-324", "9007199254740993"]


def _random_decimal(rng: np.random.Generator) -> str:
    """A decimal of up to 25 significant digits, subnormal to near the largest double: the
    numbers whose rounding to a double two parsers could disagree on.
    """
    digits = "".join(rng.choice(list("0123456789"), size=rng.integers(1, 26)))
    return f"{'-' if rng.random() < 0.5 else ''}{digits[:1]}.{digits[1:]}e{rng.integers(-330, 309)}"


def _read(path) -> tuple:
    try:
        table = read_torque_csv(path)
    except TorqueFileError as error:
        return ("refused", str(error))
    return (table.time.tolist(), table.torque.view(np.int64).tolist())  # the doubles' bits


def test_a_small_file_reads_as_pyarrow_reads_it(tmp_path, monkeypatch):
    """Every file, read in Python where it is small and plain, gives what pyarrow alone gives:
    the same doubles, or the same refusal.
    """
    rng = np.random.default_rng(42)
    read_in_python = 0
    for case in range(300):
        plain = case % 2 == 0
        rows = []
        for number in range(int(rng.integers(1, 6))):
            time = str(number) if plain or rng.random() < 0.7 else str(rng.choice(UNUSUAL_CELLS))
            torque = _random_decimal(rng) if plain or rng.random() < 0.5 else str(rng.choice(UNUSUAL_CELLS))
            rows.append(f"{time},{torque},x" + ("" if plain or rng.random() < 0.9 else ",y"))
        ending = str(rng.choice(["\n", "\r\n"] if plain else ["\n", "\r\n", "\r"]))
        blank = ending if rng.random() < 0.3 else ""
        path = tmp_path / f"t{case}.csv"
        path.write_bytes(("time,torque,note" + ending + blank + ending.join(rows) + ending).encode())
        raw, names = path.read_bytes(), ["time", "torque", "note"]
        read_in_python += _torque_csv._parse_plain_numbers(raw, names, (0, 1)) is not None
        in_python = _read(path)
        with monkeypatch.context() as only_pyarrow:
            only_pyarrow.setattr(_torque_csv, "SMALL_FILE_BYTES", -1)
            assert in_python == _read(path), path.read_bytes()
    assert read_in_python >= 150  # every plain file was read in Python
