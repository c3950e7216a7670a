"""Part 2: the FMU's own cost per 1 ms step, in instructions, free of any Python."""

from __future__ import annotations

from pathlib import Path

from .builds import BuiltFmu
from .callgrind import instructions_per_step, valgrind_missing
from .report import Row, count, skipped
from .tutorial import STEP

PART = "2 own cost"
TARGET_INSTRUCTIONS = 1500


def own_cost_rows(master: Path, pendulum: BuiltFmu, null: BuiltFmu) -> list[Row]:
    missing = valgrind_missing()
    if missing:
        return [skipped(PART, "instructions per 1 ms fmi2DoStep", missing)]
    do_step = instructions_per_step(master, pendulum, STEP)
    # The whole master step (setReal, doStep, getReal and the loop) of the pendulum and of the
    # null FMU: their difference is what a master pays for the pendulum being there.
    whole_step = instructions_per_step(master, pendulum, STEP, only_in=None)
    null_step = instructions_per_step(master, null, STEP, only_in=None)
    return [
        Row(PART, f"instructions per 1 ms fmi2DoStep (callgrind, C master, tutorial case, default "
                  f"tolerance, {do_step.steps} steps)", count(do_step.instructions_per_step),
            f"< {TARGET_INSTRUCTIONS:,}", do_step.instructions_per_step < TARGET_INSTRUCTIONS),
        Row(PART, "instructions per C master step (setReal, doStep, getReal): Pendulum / null FMU",
            f"{count(whole_step.instructions_per_step)} / {count(null_step.instructions_per_step)}"),
    ]
