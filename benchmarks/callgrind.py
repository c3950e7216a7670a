"""Instructions per communication step, counted by callgrind on the bare C master.

Instruction counts do not depend on the machine's load, so unlike timings they are repeatable.
A run's count includes start-up (loading, instantiation, the first step finding its internal step
size); the difference of a short and a long run leaves only the steady-state steps.
"""

from __future__ import annotations

import re
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path

from .builds import BuiltFmu
from .c_master import master_command, run

# Simulated seconds of the short and the long run. 10 s of difference covers about four periods
# of the tutorial pendulum, so the count averages over its swing; at 1 ms these are the runs of
# 2000 and 12000 steps.
SHORT_RUN = 2.0
LONG_RUN = 12.0


def valgrind_missing() -> str | None:
    """Why callgrind cannot run here, or None when it can."""
    return None if shutil.which("valgrind") else "valgrind not found (apt-get install valgrind)"


def count_instructions(
    master: Path, fmu: BuiltFmu, steps: int, step_size: float, tolerance: float | None, only_in: tuple[str, ...]
) -> int:
    """Instructions of one master run; with only_in, just those inside those functions and what
    they call (callgrind's --toggle-collect).
    """
    with tempfile.TemporaryDirectory() as scratch:
        profile = Path(scratch) / "callgrind.out"
        command = [
            "valgrind",
            "--tool=callgrind",
            f"--callgrind-out-file={profile}",
            *(f"--toggle-collect={function}" for function in only_in),
            *master_command(master, fmu, steps, step_size, tolerance),
        ]
        run(command)
        totals = re.search(r"^totals:\s*(\d+)", profile.read_text(), re.MULTILINE)
        if not totals:
            raise RuntimeError(f"no totals line in the callgrind profile of {' '.join(command)}")
        return int(totals.group(1))


@dataclass(frozen=True)
class StepCost:
    steps: int  # steps in the difference
    instructions_per_step: float


def instructions_per_step(
    master: Path,
    fmu: BuiltFmu,
    step_size: float,
    tolerance: float | None = None,
    only_in: tuple[str, ...] = ("fmi2DoStep",),
) -> StepCost:
    """Steady-state instructions per communication step: (long run - short run) / extra steps."""
    short_steps, long_steps = round(SHORT_RUN / step_size), round(LONG_RUN / step_size)
    short, long = (count_instructions(master, fmu, n, step_size, tolerance, only_in) for n in (short_steps, long_steps))
    extra = long_steps - short_steps
    return StepCost(extra, (long - short) / extra)
