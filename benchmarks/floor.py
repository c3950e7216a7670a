"""Part 1: the pendulum FMU against the null FMU in the same fmpy loop.

What the null FMU costs is what any fmpy master pays per step; the pendulum should add little.
"""

from __future__ import annotations

from .builds import BuiltFmu
from .fmpy_loop import timed_tutorial_loop
from .report import Row, microseconds, ratio
from .timing import interleaved, median
from .tutorial import STEPS

PART = "1 floor"
TARGET_RATIO = 1.10


def floor_rows(pendulum: BuiltFmu, null: BuiltFmu, repetitions: int) -> list[Row]:
    seconds = interleaved(
        {
            "null": lambda: timed_tutorial_loop(null)[0],
            "pendulum": lambda: timed_tutorial_loop(pendulum)[0],
        },
        repetitions,
    )
    null_step = median(seconds["null"]) / STEPS
    pendulum_step = median(seconds["pendulum"]) / STEPS
    pendulum_over_null = pendulum_step / null_step
    return [
        Row(
            PART,
            f"null FMU in fmpy FMU2Slave loop (setReal, doStep, getReal), {STEPS} x 1 ms, median of {repetitions}",
            f"{microseconds(null_step)}/step",
        ),
        Row(PART, "Pendulum FMU in the same loop", f"{microseconds(pendulum_step)}/step"),
        Row(
            PART,
            "Pendulum / null",
            ratio(pendulum_over_null),
            f"<= {TARGET_RATIO:.2f}",
            pendulum_over_null <= TARGET_RATIO,
        ),
    ]
