"""The real-time sheet's statements (docs/realtime.md), each held by a C master run.

Each runs benchmarks/realtime_master.c, a bare C master, on the linux64 binary:

- no heap call while stepping, record on or off: tests/c/heap_counter.c, preloaded, counts
  malloc and its kin in the whole process, and the master counts the FMI memory callbacks;
- no system call while stepping with the record off: a seccomp filter, installed after
  initialization, stops the master at any system call but its own writes on stdout and stderr;
  with the record on, one write(2) per call (strace, where it is installed);
- the sub-step bound: each communication step makes at most MAX_INTERNAL_STEPS Taylor steps and
  then at most MAX_INTERNAL_STEPS DOPRI5 tries, counted by the libm calls that mark them
  (sincos per Taylor step, sin per DOPRI5 right-hand side), not by the integrator's counter;
- the capability flags the sheet lists are the model description's.
"""

import os
import platform
import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import pytest

from benchmarks.builds import build_pendulum_fmu
from benchmarks.realtime import (
    BUDGET_SPENT,
    EXHAUSTING_STEP,
    SQUARE_WAVE,
    SquareWave,
    build_realtime_master,
    parse_report,
    realtime_command,
)
from fmu_build import run_tool

ROOT = Path(__file__).resolve().parent.parent
HEAP_COUNTER = Path(__file__).parent / "c/heap_counter.c"
# The bound, read where the C sources set it, so the test follows it.
MAX_INTERNAL_STEPS = int(
    re.search(r"#define MAX_INTERNAL_STEPS (\d+)L", (ROOT / "fmu_src/include/instance.h").read_text()).group(1)
)
# DOPRI5 evaluates the right-hand side once before its first try, then six times per try.
MOST_DOPRI5_EVALUATIONS = 6 * MAX_INTERNAL_STEPS + 1
STEPS = 200_000  # the run: 200 s of 1 ms steps

pytestmark = pytest.mark.skipif(
    sys.platform != "linux" or platform.machine() not in ("x86_64", "aarch64"),
    reason="the master's seccomp filter and the heap counter are for Linux on x86-64 or aarch64",
)


class Harness:
    """The FMU (linux64 only), the master and the preloadable counter, built once."""

    def __init__(self, work: Path):
        self.work = work
        self.fmu = build_pendulum_fmu(work)
        self.master = build_realtime_master(work)
        self.counter = work / "heap_counter.so"
        run_tool(["gcc", "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-shared", "-fPIC",
                  HEAP_COUNTER, "-o", self.counter, "-ldl"], HEAP_COUNTER.name)  # fmt: skip

    def run(self, mode, steps, signal, preload=False, tool=(), **options) -> subprocess.CompletedProcess:
        environment = {**os.environ, "LD_PRELOAD": str(self.counter)} if preload else None
        return subprocess.run(
            [*tool, *realtime_command(self.master, self.fmu, mode, steps, signal, **options)],
            capture_output=True,
            text=True,
            env=environment,
            timeout=120,
        )

    def report(self, mode, steps, signal, **options) -> dict:
        done = self.run(mode, steps, signal, **options)
        assert done.returncode == 0, done.stderr
        return parse_report(done.stdout)

    def counts(self, steps, signal, **options) -> dict:
        return self.report("counters", steps, signal, preload=True, **options)


@pytest.fixture(scope="module")
def harness(tmp_path_factory):
    return Harness(tmp_path_factory.mktemp("realtime"))


# With the record on, each call writes a line to a file: fewer steps keep the test short.
@pytest.mark.parametrize(("record", "steps"), [(False, STEPS), (True, 20_000)], ids=["record off", "record on"])
def test_no_heap_call_while_stepping(harness, tmp_path, record, steps):
    counts = harness.counts(steps, SQUARE_WAVE, record_file=tmp_path / "record.txt" if record else None)
    assert counts["steps_done"] == steps
    assert counts["heap_calls_while_stepping"] == 0
    # Never, not even at instantiation: the FMU declares canNotUseMemoryManagementFunctions.
    assert counts["callback_calls"] == 0
    # The counter is live: loading and instantiating allocate (the FMU's instance is calloc'ed).
    assert counts["heap_calls_before_stepping"] > 0


def test_the_heap_counter_changes_no_number(harness):
    """Preloaded, the counter hands every call on: the run ends on the same theta, bit for bit."""
    counted = harness.counts(2000, SQUARE_WAVE)
    assert counted["theta"] == harness.report("plain", 2000, SQUARE_WAVE)["theta"] != 0


def test_no_system_call_while_stepping(harness):
    done = harness.run("seccomp", STEPS, SQUARE_WAVE)
    if done.returncode == 4:
        pytest.skip(f"the kernel refuses the seccomp filter here: {done.stderr.strip()}")
    assert done.returncode == 0, done.stderr
    sealed = parse_report(done.stdout)
    assert sealed["steps_done"] == STEPS
    assert sealed["theta"] == harness.report("plain", STEPS, SQUARE_WAVE)["theta"]


def test_the_filter_stops_the_call_records_write(harness, tmp_path):
    """The filter is no formality: with the record on, the first record line a step writes
    (write(2) on the record file) stops the master.
    """
    done = harness.run("seccomp", 10, SQUARE_WAVE, record_file=tmp_path / "record.txt")
    if done.returncode == 4:
        pytest.skip(f"the kernel refuses the seccomp filter here: {done.stderr.strip()}")
    assert done.returncode == 3, done.stderr
    assert "(write) while stepping" in done.stderr


@pytest.mark.skipif(shutil.which("strace") is None, reason="strace not found (apt-get install strace)")
def test_the_record_writes_once_per_call(harness, tmp_path):
    """Each call's record line is flushed at once: one write(2) per call, on the record file."""
    record, trace = tmp_path / "record.txt", tmp_path / "trace.txt"
    steps = 1000
    done = harness.run(
        "plain", steps, SQUARE_WAVE, record_file=record, tool=("strace", "-qq", "-e", "trace=write", "-o", trace)
    )
    assert done.returncode == 0, done.stderr
    lines = record.read_text().splitlines()
    record_writes = [line for line in trace.read_text().splitlines() if '"[pendulum-calls] ' in line]
    assert len(record_writes) == len(lines) >= 3 * steps
    assert sum(" fmi2DoStep(" in line for line in lines) == steps


# Per 1 ms step, jumping at every step: the most Taylor steps (sincos calls) and DOPRI5
# right-hand sides (sin calls) one communication step made, at the FMU's default tolerance (None)
# or a tighter one, from the docs' 20 N.m to the largest finite torque (the docs allow any
# finite value).
HARDEST_SIGNALS = [
    (20.0, None, 2000, 1, 0),
    (20.0, 1e-16, 2000, 1, 0),
    (1e4, None, 2000, 1, 0),
    (1e8, None, 2000, 6, 0),
    (1e12, None, 200, 1406, 0),
    (BUDGET_SPENT.amplitude, None, 5, MAX_INTERNAL_STEPS, 7),
    (1e100, None, 200, 1, 7),
    (sys.float_info.max, None, 200, 1, 7),
]


@pytest.mark.parametrize(("amplitude", "tolerance", "steps", "taylor_steps", "dopri5_evaluations"), HARDEST_SIGNALS)
def test_sub_steps_at_a_jump_every_step(harness, amplitude, tolerance, steps, taylor_steps, dopri5_evaluations):
    counts = harness.counts(steps, SquareWave(amplitude, 1), tolerance=tolerance)
    assert counts["steps_done"] == steps and "discarded_at" not in counts
    assert (counts["most_sincos_per_step"], counts["most_sin_per_step"]) == (taylor_steps, dopri5_evaluations)
    assert counts["most_sincos_per_step"] <= MAX_INTERNAL_STEPS
    assert counts["most_sin_per_step"] <= MOST_DOPRI5_EVALUATIONS


def test_a_step_past_the_bound_is_discarded_at_the_bound(harness):
    """A step too long for either budget spends each exactly and no more, then is discarded."""
    counts = harness.counts(1, SquareWave(20.0, 1), step_size=EXHAUSTING_STEP)
    assert counts["discarded_at"] == 0
    assert counts["total_sincos"] == MAX_INTERNAL_STEPS
    assert counts["total_sin"] == MOST_DOPRI5_EVALUATIONS


def test_the_sheet_lists_the_declared_capability_flags():
    """docs/realtime.md's table of capability flags is the model description's, value for value."""
    description = ElementTree.parse(ROOT / "modelDescription.xml").getroot()
    declared = {
        f"{interface.tag}.{flag}": value
        for interface in (description.find("ModelExchange"), description.find("CoSimulation"))
        for flag, value in interface.attrib.items()
        if flag != "modelIdentifier"
    }
    sheet = (ROOT / "docs/realtime.md").read_text()
    listed = {
        f"{interface}.{flag}": value
        for flag, value, interfaces in re.findall(r"^\| `(\w+)` \| `(\w+)` \| ([\w ,]+) \|", sheet, re.MULTILINE)
        for interface in re.split(r",\s*", interfaces.strip())
    }
    assert listed == declared
