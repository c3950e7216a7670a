"""Part 4: our Python master loop (run_schedule_python, simulate()'s reference path) against
fmpy's FMU2Slave wrappers making the same FMI calls, and the native loop (cs_loop, what
simulate() runs when it is built) making them from C; same FMU, same results bit for bit.
"""

from __future__ import annotations

import numpy as np
from fmpy.fmi2 import FMU2Slave

from pendulum_fmu.fmu import _native_loop as cs_loop, _results as results
from pendulum_fmu.fmu._instance import open_fmu
from pendulum_fmu.fmu._parameters import value_reference
from pendulum_fmu.fmu._simulate import run_schedule, run_schedule_python
from pendulum_fmu.signals._torque_schedule import TorqueSchedule, schedule

from . import tutorial
from .builds import BuiltFmu
from .report import Row, microseconds, ratio
from .timing import interleaved, median, timed

PART = "4 Python loop"
TARGET_RATIO = 0.5


def fmpy_schedule_loop(slave: FMU2Slave, plan: TorqueSchedule) -> np.ndarray:
    """run_schedule's calls for a held torque (setReal torque, getReal theta/omega/alpha, doStep),
    each through fmpy's wrapper, which builds its ctypes arrays and checks the status anew.
    """
    torque_vr = [value_reference("torque")]
    output_vrs = [value_reference(n) for n in ("theta", "omega", "alpha")]
    out = results.empty(len(plan.time))
    out["time"] = plan.time
    rows = []
    for t, h, torque in zip(plan.time[:-1], plan.step_size, plan.torque, strict=False):
        slave.setReal(torque_vr, [torque])
        rows.append((torque, *slave.getReal(output_vrs)))
        slave.doStep(t, h)
    rows.append((*slave.getReal(torque_vr), *slave.getReal(output_vrs)))
    for field, column in zip(("torque", "theta", "omega", "alpha"), zip(*rows, strict=False), strict=False):
        out[field] = column
    return out


def _timed_on_fresh_instance(loop, fmu: BuiltFmu, plan: TorqueSchedule) -> tuple[float, np.ndarray]:
    slave = open_fmu(fmu.path)
    try:
        return timed(lambda: loop(slave, plan))
    finally:
        slave.terminate()
        slave.freeInstance()


def python_loop_rows(fmu: BuiltFmu, repetitions: int) -> list[Row]:
    plan = schedule(tutorial.TORQUE, stop_time=tutorial.STOP_TIME, step_size=tutorial.STEP)
    theta = {}

    def contender(name, loop):
        def run():
            seconds, out = _timed_on_fresh_instance(loop, fmu, plan)
            theta[name] = out["theta"]
            return seconds

        return run

    contenders = {"ours": contender("ours", run_schedule_python), "fmpy": contender("fmpy", fmpy_schedule_loop)}
    if cs_loop.available():
        contenders["native"] = contender("native", run_schedule)
    seconds = interleaved(contenders, repetitions)
    # Same FMU, same calls, same order: anything but bit-for-bit equality is a bug.
    for name in theta:
        assert np.array_equal(theta["ours"], theta[name]), f"run_schedule_python and {name} differ in theta"
    ours_step = median(seconds["ours"]) / tutorial.STEPS
    fmpy_step = median(seconds["fmpy"]) / tutorial.STEPS
    ours_over_fmpy = ours_step / fmpy_step
    return [
        Row(
            PART,
            f"the Python loop, run_schedule_python (setReal, getReal x3, doStep), {tutorial.STEPS} "
            f"x 1 ms, median of {repetitions}",
            f"{microseconds(ours_step)}/step",
        ),
        Row(PART, "fmpy FMU2Slave wrappers making the same calls", f"{microseconds(fmpy_step)}/step"),
        Row(
            PART, "Python loop / fmpy", ratio(ours_over_fmpy), f"<= {TARGET_RATIO:.2f}", ours_over_fmpy <= TARGET_RATIO
        ),
        Row(PART, "theta arrays identical (asserted)", "yes"),
    ] + (
        [
            Row(
                PART,
                "native loop (cs_loop: the same calls from C, one call per run)",
                f"{microseconds(median(seconds['native']) / tutorial.STEPS)}/step",
            ),
            Row(PART, "native / Python loop", ratio(median(seconds["native"]) / median(seconds["ours"]))),
        ]
        if "native" in seconds
        else []
    )
