"""Part 9: what one communication step costs, for the real-time sheet (docs/realtime.md).

Runs realtime_master.c, a bare C master, through square waves of torque: instructions of each
fmi2DoStep under callgrind (deterministic, so its median and maximum are benchmark rows), the
steps where the integrator spends its whole sub-step budget, the call record's cost, and the
wall-clock percentiles of the whole master step (information: they depend on the machine and its
load). tests/test_realtime.py runs the same master under an allocation-counting shim and a
seccomp filter.
"""

from __future__ import annotations

import re
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .builds import HERE, BuiltFmu, build_bare_master
from .c_master import MasterError, run
from .callgrind import valgrind_missing
from .own_cost import TARGET_DO_STEP
from .report import Row, count, skipped

PART = "9 real time"
MASTER_SOURCE = HERE / "realtime_master.c"
STEP = 1e-3


@dataclass(frozen=True)
class SquareWave:
    """+amplitude N.m for half_period steps, then -amplitude for as many: half_period 1 jumps at
    every step.
    """

    amplitude: float
    half_period: int

    def __str__(self) -> str:
        every = "every step" if self.half_period == 1 else f"every {self.half_period} steps"
        return f"+-{self.amplitude:g} N.m, a jump {every}"


# The docs' square wave (a 1 Hz period at 1 ms steps), and the same torque jumping at every step.
SQUARE_WAVE = SquareWave(20.0, 500)
JUMP_EVERY_STEP = SquareWave(20.0, 1)
# Where the Taylor method spends its whole budget on each 1 ms step and DOPRI5 then takes it
# (tests/test_realtime.py finds it among the amplitudes it tries).
BUDGET_SPENT = SquareWave(1e15, 1)
# One step so long that both methods spend their budgets and the step is discarded.
EXHAUSTING_STEP = 1e4


def build_realtime_master(out_dir: Path) -> Path:
    """Compile realtime_master.c for this machine."""
    return build_bare_master(out_dir, MASTER_SOURCE)


def realtime_command(
    master: Path,
    fmu: BuiltFmu,
    mode: str,
    steps: int,
    signal: SquareWave,
    step_size: float = STEP,
    tolerance: float | None = None,
    record_file: Path | None = None,
) -> list[str]:
    """The master's command line (realtime_master.c says what each mode prints); tolerance None
    leaves it undefined, so the FMU uses its default; a record_file switches the call record on.
    """
    return [
        str(master),
        str(fmu.library),
        fmu.guid,
        mode,
        str(steps),
        repr(step_size),
        repr(signal.amplitude),
        str(signal.half_period),
        repr(tolerance or 0.0),
        *([str(record_file)] if record_file else []),
    ]


def parse_report(stdout: str) -> dict[str, float]:
    """The master's `name value` lines, but step_ns (wall_clock_ns reads those)."""
    return {
        name: float(value)
        for name, value in (line.split() for line in stdout.splitlines() if line.strip())
        if name != "step_ns"
    }


def instructions_per_do_step(master: Path, fmu: BuiltFmu, steps: int, signal: SquareWave, **options) -> np.ndarray:
    """Instructions inside each fmi2DoStep, in order: callgrind counts only in fmi2DoStep
    (--toggle-collect) and writes its counts after each call (--dump-after), one file per call.
    """
    with tempfile.TemporaryDirectory() as scratch:
        profile = Path(scratch) / "callgrind.out"
        run(
            [
                "valgrind",
                "--tool=callgrind",
                f"--callgrind-out-file={profile}",
                "--toggle-collect=fmi2DoStep",
                "--dump-after=fmi2DoStep",
                *realtime_command(master, fmu, "plain", steps, signal, **options),
            ]
        )
        dumps = sorted(Path(scratch).glob("callgrind.out.*"), key=lambda path: int(path.suffix[1:]))
        counts = []
        for dump in dumps:
            totals = re.search(r"^totals:\s*(\d+)", dump.read_text(), re.MULTILINE)
            if not totals:
                raise MasterError(f"no totals line in the callgrind dump {dump.name}")
            counts.append(int(totals.group(1)))
    return np.array(counts)


def wall_clock_ns(master: Path, fmu: BuiltFmu, steps: int, signal: SquareWave, **options) -> np.ndarray:
    """Nanoseconds of each master step (fmi2SetReal + fmi2DoStep + fmi2GetReal), natively."""
    done = subprocess.run(
        realtime_command(master, fmu, "timing", steps, signal, **options), capture_output=True, text=True
    )
    if done.returncode != 0:
        raise MasterError(f"realtime_master failed:\n{done.stderr[-2000:]}")
    return np.array([int(line.split()[1]) for line in done.stdout.splitlines() if line.startswith("step_ns ")])


def instruction_rows(master: Path, pendulum: BuiltFmu, scratch: Path) -> list[Row]:
    """Median and maximum instructions per fmi2DoStep at the square wave, a jump every step,
    the spent budget and the record on, and the one discarded step that spends both budgets.
    """
    missing = valgrind_missing()
    if missing:
        return [skipped(PART, "instructions per fmi2DoStep", missing)]
    rows = []
    cases = [
        (f"{SQUARE_WAVE}, 2000 x 1 ms", 2000, SQUARE_WAVE, {}),
        (f"{JUMP_EVERY_STEP}, 2000 x 1 ms", 2000, JUMP_EVERY_STEP, {}),
        (
            f"{SQUARE_WAVE}, 2000 x 1 ms, call record on (user space only)",
            2000,
            SQUARE_WAVE,
            {"record_file": scratch / "realtime_record.txt"},
        ),
        (f"{BUDGET_SPENT} (Taylor budget spent each step), 3 x 1 ms", 3, BUDGET_SPENT, {}),
    ]
    for label, steps, signal, options in cases:
        counts = instructions_per_do_step(master, pendulum, steps, signal, **options)
        # The square wave's worst step is held to what part 2 holds its average step to.
        held = signal == SQUARE_WAVE and not options
        rows.append(
            Row(
                PART,
                f"instructions per fmi2DoStep (callgrind), median / max: {label}",
                f"{count(float(np.median(counts)))} / {count(float(counts.max()))}",
                f"max <= {TARGET_DO_STEP:,}" if held else "",
                bool(counts.max() <= TARGET_DO_STEP) if held else None,
            )
        )
    [exhausting] = instructions_per_do_step(master, pendulum, 1, JUMP_EVERY_STEP, step_size=EXHAUSTING_STEP)
    rows.append(
        Row(
            PART,
            f"instructions of one {EXHAUSTING_STEP:g} s fmi2DoStep that spends both budgets (discarded)",
            count(float(exhausting)),
        )
    )
    return rows


def percentiles(nanoseconds: np.ndarray) -> str:
    p50, p99, p999 = np.percentile(nanoseconds, [50, 99, 99.9]) / 1000
    return f"p50 {p50:.3f} / p99 {p99:.3f} / p99.9 {p999:.3f} / max {nanoseconds.max() / 1000:.1f} µs"


def realtime_rows(pendulum: BuiltFmu, scratch: Path) -> list[Row]:
    """The part's rows: instructions (callgrind) and wall-clock percentiles (information)."""
    master = build_realtime_master(scratch)
    rows = instruction_rows(master, pendulum, scratch)
    steps = 200_000
    worst = wall_clock_ns(master, pendulum, 5, BUDGET_SPENT)
    [exhausting] = wall_clock_ns(master, pendulum, 1, JUMP_EVERY_STEP, step_size=EXHAUSTING_STEP)
    rows.append(
        Row(
            PART,
            f"wall clock per master step at {BUDGET_SPENT}, 5 x 1 ms, median / max; the {EXHAUSTING_STEP:g} s step",
            f"{np.median(worst) / 1e6:.1f} / {worst.max() / 1e6:.1f} ms; {exhausting / 1e6:.1f} ms",
        )
    )
    for label, options in (("record off", {}), ("call record on", {"record_file": scratch / "realtime_timed.txt"})):
        rows.append(
            Row(
                PART,
                f"wall clock per master step (set, step, get; C master), {SQUARE_WAVE}, {steps:,} x 1 ms, {label}",
                percentiles(wall_clock_ns(master, pendulum, steps, SQUARE_WAVE, **options)),
            )
        )
    return rows
