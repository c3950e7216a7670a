"""Ctrl-C and SIGTERM at any moment of a real `pendulum-fmu` process leave the old file or the
whole new one at the target, no temporary beside it, and one line on stderr (exit 130 or 143).
"""

import os
import re
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

OLD = "the file from before\n"
STEPS = 1_000_000  # several seconds even on a fast machine: writing 1e6 rows takes the most


def start(arguments, folder):
    return subprocess.Popen(
        [sys.executable, "-m", "pendulum_fmu", *arguments],
        cwd=folder,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def check_target(target, complete_rows):
    """The target is the old file or the complete new one, and nothing else is beside it."""
    text = target.read_text()
    if text != OLD:
        data = np.genfromtxt(target, delimiter=",", names=True)
        assert len(data) == complete_rows and data["time"][-1] == pytest.approx(1.0)
    assert sorted(p.name for p in target.parent.iterdir()) == [target.name]


@pytest.mark.parametrize(
    "signal_number, exit_code, word", [(signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")]
)
@pytest.mark.parametrize("delay", [1.5, 3.0, 6.0])
def test_simulate_output_survives_a_signal(tmp_path, signal_number, exit_code, word, delay):
    out = tmp_path / "out"
    out.mkdir()
    target = out / "result.csv"
    target.write_text(OLD)
    process = start(
        ["simulate", "--torque", "1", "--step-size", str(1 / STEPS), "--stop-time", "1", "--output", str(target)],
        tmp_path,
    )
    time.sleep(delay)
    process.send_signal(signal_number)
    _, stderr = process.communicate(timeout=120)
    assert "Traceback" not in stderr
    if delay < 2:  # too early for any machine to have finished: the signal must have been seen
        assert process.returncode == exit_code, stderr
    if process.returncode != 0:  # the signal arrived before the run ended
        assert process.returncode == exit_code, stderr
        assert stderr.strip().splitlines() == [f"pendulum-fmu simulate: {word}; no output file was left half written"]
    check_target(target, STEPS + 1)


def test_compare_outputs_survive_ctrl_c(tmp_path):
    out = tmp_path / "out"
    process = start(
        [
            "compare",
            "--torque",
            "20",
            "--tools",
            "fmu,reference",
            "--step-size",
            "1e-5",
            "--stop-time",
            "2",
            "--output-dir",
            str(out),
        ],
        tmp_path,
    )
    time.sleep(4.0)
    os.kill(process.pid, signal.SIGINT)
    _, stderr = process.communicate(timeout=120)
    assert "Traceback" not in stderr
    assert process.returncode in (0, 130), stderr
    for path in out.iterdir() if out.exists() else ():
        assert ".partial" not in path.name


@pytest.mark.parametrize("delay", [0.2, 0.3, 0.4, 0.6, 0.8])
def test_ctrl_c_while_the_program_starts_is_one_line_too(tmp_path, delay):
    # The installed program sets its handlers before it imports numpy, fmpy or dask. Before its
    # first line only Python's own start-up runs (tens of milliseconds, out of our reach).
    program = os.path.join(os.path.dirname(sys.executable), "pendulum-fmu")
    process = subprocess.Popen(
        [program, "simulate", "--torque", "1", "--stop-time", "0.5", "--output", str(tmp_path / "out.csv")],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    time.sleep(delay)
    process.send_signal(signal.SIGINT)
    _, stderr = process.communicate(timeout=120)
    assert "Traceback" not in stderr and len(stderr.strip().splitlines()) <= 1, stderr
    assert process.returncode in (0, 130)
    assert [p.name for p in tmp_path.iterdir()] in ([], ["out.csv"])


HANDLER_IN_A_GC_CALLBACK = """
import gc, signal, time
from pendulum_fmu._stop_signals import Stopped, restore_signals, stop_on_signals

previous = stop_on_signals()
fired = []

def callback(phase, info):  # as dask's client has one
    if not fired:
        fired.append(phase)
        signal.raise_signal(signal.SIGINT)  # its handler runs here, where Python drops exceptions

gc.callbacks.append(callback)
try:
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline:
        gc.collect()
        time.sleep(0.01)
    print("ran to the end")
except Stopped as stopped:
    print("stopped by", stopped.signal_number)
restore_signals(previous)
"""


def test_a_signal_whose_handler_runs_in_a_gc_callback_still_stops_the_command():
    # Python prints an exception raised in a garbage collector's callback as "Exception ignored"
    # and goes on: a Ctrl-C that came there must still stop the command, with nothing printed.
    run = subprocess.run([sys.executable, "-c", HANDLER_IN_A_GC_CALLBACK], capture_output=True, text=True, timeout=60)
    assert (run.stdout, run.stderr) == (f"stopped by {int(signal.SIGINT)}\n", "")


def test_ctrl_c_stops_a_long_reference_after_its_progress_lines(tmp_path):
    # Issue 48: the reference takes about 9,500,000 Taylor steps for this spin (300 N.m for
    # 1,900 s, near its limit of 10,000,000), some 7 s in C: off a terminal its progress is a line
    # every 5 s, and Ctrl-C, sent once the first line is out, stops it in one line.
    out = tmp_path / "out"
    arguments = ["compare", "--torque", "300", "--tools", "fmu,reference", "--stop-time", "1900", "--step-size", "1"]
    process = start([*arguments, "--output-dir", str(out)], tmp_path)
    first = process.stderr.readline()
    assert first.startswith("reference: "), first
    process.send_signal(signal.SIGINT)
    _, stderr = process.communicate(timeout=120)
    lines = (first + stderr).strip().splitlines()
    assert process.returncode == 130, stderr
    assert lines[-1] == "pendulum-fmu compare: interrupted; no output file was left half written"
    assert lines[:-1] and all(re.fullmatch(r"reference: [\d.e+]+/1900 s", line) for line in lines[:-1]), stderr
    assert not out.exists() or not list(out.iterdir())
