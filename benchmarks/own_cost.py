"""Part 2: the FMU's own cost per 1 ms step, in instructions, free of any Python."""

from __future__ import annotations

from pathlib import Path

from .builds import BuiltFmu
from .callgrind import instructions_per_step, valgrind_missing
from .report import Row, count, skipped
from .tutorial import STEP

PART = "2 own cost"
TARGET_DO_STEP, TARGET_WITH_SET_AND_GET = 500, 600
# What a master calls for a step of the tutorial loop.
STEP_CALLS = ("fmi2SetReal", "fmi2DoStep", "fmi2GetReal")


def own_cost_rows(master: Path, pendulum: BuiltFmu, null: BuiltFmu) -> list[Row]:
    missing = valgrind_missing()
    if missing:
        return [skipped(PART, "instructions per 1 ms fmi2DoStep", missing)]
    do_step = instructions_per_step(master, pendulum, STEP)
    with_set_and_get = instructions_per_step(master, pendulum, STEP, only_in=STEP_CALLS)
    # The whole master step (the calls and the loop) of the pendulum and of the null FMU: their
    # difference is what a master pays for the pendulum being there.
    whole_step = instructions_per_step(master, pendulum, STEP, only_in=())
    null_step = instructions_per_step(master, null, STEP, only_in=())
    return [
        Row(
            PART,
            f"instructions per 1 ms fmi2DoStep (callgrind, C master, tutorial case, default "
            f"tolerance, {do_step.steps} steps)",
            count(do_step.instructions_per_step),
            f"<= {TARGET_DO_STEP:,}",
            do_step.instructions_per_step <= TARGET_DO_STEP,
        ),
        Row(
            PART,
            "instructions per 1 ms fmi2SetReal + fmi2DoStep + fmi2GetReal",
            count(with_set_and_get.instructions_per_step),
            f"<= {TARGET_WITH_SET_AND_GET:,}",
            with_set_and_get.instructions_per_step <= TARGET_WITH_SET_AND_GET,
        ),
        Row(
            PART,
            "instructions per C master step (the calls and the loop): Pendulum / null FMU",
            f"{count(whole_step.instructions_per_step)} / {count(null_step.instructions_per_step)}",
        ),
    ]
