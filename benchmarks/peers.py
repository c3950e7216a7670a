"""Hooks for the peers others are building: OpenSim 4.6 and a PythonFMU build of the pendulum.

Each compares its peer with our FMU side by side, and skips with a message when the peer's
module or package is missing, so the benchmark runs on any machine.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

from pendulum_fmu.fmu._simulate import simulate
from pendulum_fmu.signals._torque_schedule import schedule

from .builds import BuiltFmu, unzipped
from .fmpy_loop import timed_tutorial_loop
from .report import Row, microseconds, ratio, skipped
from .timing import interleaved, median, timed
from .tutorial import STEP, STEPS, STOP_TIME, TORQUE, max_theta_error

# How much faster per step the FMU should be than each peer, at equal or smaller error.
OPENSIM_TARGET, PYTHONFMU_TARGET = 30.0, 20.0


def opensim_rows(fmu: BuiltFmu, repetitions: int) -> list[Row]:
    """OpenSim's tutorial pendulum against simulate(), each end to end (building or opening the
    model included, as a user pays it), and the theta error of each against the scipy oracle.
    """
    part = "peer OpenSim"
    # engines.opensim imports opensim only when called, so ask for the package itself.
    if importlib.util.find_spec("opensim") is None:
        return [skipped(part, "OpenSim 4.6 against the FMU", "the opensim package is not installed")]
    from pendulum_fmu.engines.opensim import opensim_simulate

    plan = schedule(TORQUE, stop_time=STOP_TIME, step_size=STEP)
    theta = {}

    def opensim_run():
        seconds, out = timed(lambda: opensim_simulate(plan.time, plan.torque))
        theta["opensim"] = out["theta"]
        return seconds

    def fmu_run():
        seconds, out = timed(lambda: simulate(TORQUE, stop_time=STOP_TIME, step_size=STEP, fmu_path=fmu.path))
        theta["fmu"] = out["theta"]
        return seconds

    seconds = interleaved({"opensim": opensim_run, "fmu": fmu_run}, repetitions)
    opensim_step = median(seconds["opensim"]) / STEPS
    fmu_step = median(seconds["fmu"]) / STEPS
    opensim_error, fmu_error = max_theta_error(theta["opensim"]), max_theta_error(theta["fmu"])
    case = f"tutorial 3 s in 1 ms steps, end to end, median of {repetitions}"
    return [
        Row(part, f"OpenSim opensim_simulate(), {case}", f"{microseconds(opensim_step)}/step"),
        Row(part, f"Pendulum FMU simulate(), {case}", f"{microseconds(fmu_step)}/step"),
        Row(
            part,
            "OpenSim / FMU time",
            ratio(opensim_step / fmu_step),
            f">= {OPENSIM_TARGET:g}",
            opensim_step / fmu_step >= OPENSIM_TARGET,
        ),
        Row(
            part,
            "max |theta error| rad: OpenSim / FMU",
            f"{opensim_error:.1e} / {fmu_error:.1e}",
            "FMU <= OpenSim",
            fmu_error <= opensim_error,
        ),
    ]


def pythonfmu_rows(pendulum: BuiltFmu, out_dir: Path, repetitions: int) -> list[Row]:
    """The PythonFMU pendulum against ours in the same fmpy loop as part 1.

    Expects benchmarks/pythonfmu_pendulum/build.py to provide build_pythonfmu_pendulum(out_dir)
    returning the path of the .fmu it built, with variables named torque and theta.
    """
    part = "peer PythonFMU"
    try:
        from .pythonfmu_pendulum.build import build_pythonfmu_pendulum

        fmu_path = build_pythonfmu_pendulum(out_dir / "pythonfmu")
    except ImportError as error:
        return [skipped(part, "PythonFMU pendulum against ours", f"{error}")]
    peer = unzipped(Path(fmu_path), out_dir)
    theta = {}

    def contender(name, fmu):
        def run():
            seconds, theta[name] = timed_tutorial_loop(fmu)
            return seconds

        return run

    seconds = interleaved({"pythonfmu": contender("pythonfmu", peer), "ours": contender("ours", pendulum)}, repetitions)
    peer_step = median(seconds["pythonfmu"]) / STEPS
    ours_step = median(seconds["ours"]) / STEPS
    loop = f"fmpy FMU2Slave loop, {STEPS} x 1 ms, median of {repetitions}"
    peer_error, ours_error = max_theta_error(theta["pythonfmu"]), max_theta_error(theta["ours"])
    return [
        Row(part, f"PythonFMU pendulum, {loop}", f"{microseconds(peer_step)}/step"),
        Row(part, f"Pendulum FMU, {loop}", f"{microseconds(ours_step)}/step"),
        Row(
            part,
            "PythonFMU / ours time",
            ratio(peer_step / ours_step),
            f">= {PYTHONFMU_TARGET:g}",
            peer_step / ours_step >= PYTHONFMU_TARGET,
        ),
        Row(
            part,
            "max |theta error| rad: PythonFMU / ours",
            f"{peer_error:.1e} / {ours_error:.1e}",
            "ours <= PythonFMU",
            ours_error <= peer_error,
        ),
    ]
