"""Part 5: what simulate() costs before its first step, for a user who calls it in a loop
(optimization, identification, learning), and what that leaves of the lead over OpenSim.

simulate() after the first call in a process, 1 step and 1 s, against the same schedule through
a fresh instance per call (open_fmu, run_schedule, free: what simulate() did before its per-thread
Simulator), and against OpenSim's tutorial loop on 1 s; contenders interleaved.
"""

from __future__ import annotations

import importlib.util

from pendulum_fmu.fmu._instance import open_fmu
from pendulum_fmu.fmu._simulate import run_schedule, simulate
from pendulum_fmu.signals._torque_schedule import schedule

from .builds import BuiltFmu
from .report import Row, microseconds, ratio, skipped
from .timing import interleaved, median, timed
from .tutorial import STEP, TORQUE

PART = "5 simulate() fixed cost"
TARGET_FIXED_COST = 100e-6  # s per 1-step simulate() after the first in a process
OPENSIM_TARGET = 300.0  # OpenSim's 1 s over simulate()'s
CALLS = 200  # calls of a 1-step simulate() per timed repetition: a call is too short to time alone


def _fresh_instance(fmu: BuiltFmu, plan):
    slave = open_fmu(fmu.path)
    try:
        return run_schedule(slave, plan)
    finally:
        slave.terminate()
        slave.freeInstance()


def fixed_cost_rows(fmu: BuiltFmu, repetitions: int) -> list[Row]:
    one_step, one_second = schedule(TORQUE, stop_time=STEP), schedule(TORQUE, stop_time=1.0)
    simulate(TORQUE, stop_time=STEP, fmu_path=fmu.path)  # the first call makes the Simulator

    def calls(function):
        def run():
            return timed(lambda: [function() for _ in range(CALLS)])[0] / CALLS

        return run

    contenders = {
        "simulate 1 step": calls(lambda: simulate(TORQUE, stop_time=STEP, fmu_path=fmu.path)),
        "fresh 1 step": calls(lambda: _fresh_instance(fmu, one_step)),
        "simulate 1 s": lambda: timed(lambda: simulate(TORQUE, stop_time=1.0, fmu_path=fmu.path))[0],
    }
    opensim = importlib.util.find_spec("opensim") is not None
    if opensim:
        from pendulum_fmu.engines.opensim import opensim_simulate

        contenders["opensim 1 s"] = lambda: timed(lambda: opensim_simulate(one_second.time, one_second.torque))[0]
    seconds = {name: median(values) for name, values in interleaved(contenders, repetitions).items()}
    fixed = seconds["simulate 1 step"]
    case = f"median of {repetitions}"
    rows = [
        Row(
            PART,
            f"simulate() of one 1 ms step, after the first call in the process, {case} (of {CALLS} calls each)",
            f"{microseconds(fixed)} = {1 / fixed:,.0f} calls/s",
            f"<= {microseconds(TARGET_FIXED_COST)}",
            fixed <= TARGET_FIXED_COST,
        ),
        Row(
            PART,
            "the same step through a fresh instance per call (open_fmu, run_schedule, free)",
            f"{microseconds(seconds['fresh 1 step'])}",
        ),
        Row(PART, f"simulate() of 1 s in 1 ms steps, {case}", microseconds(seconds["simulate 1 s"])),
    ]
    if not opensim:
        return [*rows, skipped(PART, "OpenSim 4.6 on 1 s", "the opensim package is not installed")]
    lead = seconds["opensim 1 s"] / seconds["simulate 1 s"]
    return [
        *rows,
        Row(
            PART,
            f"OpenSim opensim_simulate() of 1 s in 1 ms steps, end to end, {case}",
            microseconds(seconds["opensim 1 s"]),
        ),
        Row(PART, "OpenSim / simulate() time on 1 s", ratio(lead), f">= {OPENSIM_TARGET:g}", lead >= OPENSIM_TARGET),
    ]
