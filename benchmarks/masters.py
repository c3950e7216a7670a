"""Masters written as a vendor would, on fmpy's FMU2Slave and FMU2Model, that run a scenario of
the kit (pendulum_fmu.scenarios._scenarios) and write NAME_out.csv: a correct one, and ones that make each
mistake the judge names on purpose.

tests/test_scenarios.py and tests/test_judge.py run them; this prints what the judge says of
each (the README's table and the thresholds of _judge.py):

    python -m benchmarks.masters

They read the kit's files themselves (NAME.json, NAME_in.csv) and share no code with the
package's schedule or reference, as a master elsewhere would not.
"""

from __future__ import annotations

import bisect
import csv
import ctypes
import json
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Model, FMU2Slave

OUTPUTS = ("theta", "omega", "alpha")
# (scenario, the mistake a master makes on purpose, the diagnosis it must get)
WRONG_MASTERS = [
    ("random_steps", "late", "input one step late"),
    ("decimal_steps", "late", "input one step late"),
    ("ramp", "late", "input one step late"),
    ("steps_on_grid", "early", "input one step early"),
    ("ramp", "early", "input one step early"),
    ("random_steps", "ramped", "input interpolated linearly"),
    ("steps_on_grid", "ramped", "input interpolated linearly"),
    ("ramp", "held", "input held"),
    ("random_steps", "drift", "time grid drift"),
    ("decimal_steps", "drift", "time grid drift"),
    ("random_steps", "summed_clock", "time grid drift"),
    ("decimal_steps", "summed_clock", "time grid drift"),
    ("random_steps", "exact_events", "time grid drift"),
    ("steps_on_grid", "exact_events", "time grid drift"),
    ("random_steps", "shifted", "time column one step off"),
    ("steps_on_grid", "shifted", "time column one step off"),
    ("resume", "not_restored", "state not restored"),
    ("random_steps", "single", "result in single precision"),
    ("steps_on_grid", "single", "result in single precision"),
    ("constant_torque", "euler", "integration error"),
    ("random_steps", "euler", "integration error"),
    ("constant_torque", "heun", "integration error"),
    ("random_steps", "heun", "integration error"),
    ("random_steps", "late_once", "unexplained"),
    ("steps_on_grid", "scaled", "unexplained"),
    ("constant_torque", "scaled", "unexplained"),
]
# In words, for the table.
MISTAKES = {
    "late": "input one step late",
    "early": "input one step early",
    "ramped": "input derivatives where the signal holds",
    "held": "no input derivatives on a ramp",
    "drift": "time summed in single precision",
    "summed_clock": "steps where its time passes a summed clock",
    "exact_events": "changes fired at exact summed-clock times",
    "shifted": "each step's result filed under its start",
    "not_restored": "resumed without restoring the state",
    "single": "outputs handed out in single precision",
    "euler": "Model Exchange, explicit Euler at the step",
    "heun": "Model Exchange, Heun at the step",
    "late_once": "only the first change one step late",
    "scaled": "1 % too much torque",
}


class Signal:
    """A time,torque CSV in fmpy's convention: linear between rows, a jump where a time repeats;
    a row within a billionth of a step of a time counts as at that time.
    """

    def __init__(self, path: Path, step_size: float):
        with open(path, newline="") as file:
            rows = list(csv.reader(file))[1:]
        self.times = [float(t) for t, _ in rows]
        self.values = [float(u) for _, u in rows]
        self.slack = 1e-9 * step_size

    def _between(self, i: int, t: float) -> float:
        if i <= 0:
            return self.values[0]
        if i >= len(self.times):
            return self.values[-1]
        t0, t1, u0, u1 = self.times[i - 1], self.times[i], self.values[i - 1], self.values[i]
        return u0 + (u1 - u0) * (min(max(t, t0), t1) - t0) / (t1 - t0)

    def after(self, t: float) -> float:
        return self._between(bisect.bisect_right(self.times, t + self.slack), t)

    def before(self, t: float) -> float:
        return self._between(bisect.bisect_left(self.times, t - self.slack), t)


class Kit:
    """One scenario of a kit folder, as its master reads it."""

    def __init__(self, folder: Path, name: str):
        self.folder, self.name = Path(folder), name
        self.settings = json.loads((self.folder / f"{name}.json").read_text())
        s = self.settings
        self.step = s["step_size"]
        self.signal = Signal(self.folder / s["input"], self.step)
        steps = round((s["stop_time"] - s["start_time"]) / self.step)
        self.times = s["start_time"] + self.step * np.arange(steps + 1)
        self.times[-1] = s["stop_time"]
        self.fmu = self.folder / s["fmu"]
        self.description = read_model_description(str(self.fmu))
        self.vr = {v.name: v.valueReference for v in self.description.modelVariables}
        self.unzipped = extract(str(self.fmu))

    def torques(self, times: np.ndarray) -> tuple[list[float], list[float]]:
        """Each step's torque at its start and its slope (zero unless the scenario ramps)."""
        start = [self.signal.after(t) for t in times[:-1]]
        if not self.settings["ramp"]:
            return start, [0.0] * len(start)
        return start, [
            (self.signal.before(t1) - u) / (t1 - t0) for u, t0, t1 in zip(start, times[:-1], times[1:], strict=False)
        ]

    def start_values(self) -> dict[str, float]:
        s = self.settings
        return {**s["parameters"], "theta": s["theta0"], "omega": s["omega0"]}

    def write(self, times, rows) -> Path:
        path = self.folder / self.settings["output"]
        with open(path, "w", newline="") as file:
            file.write("time," + ",".join(OUTPUTS) + "\n")
            for t, row in zip(times, rows, strict=False):
                file.write(",".join(repr(float(v)) for v in (t, *row)) + "\n")
        return path


def _slave(kit: Kit, start_time: float, name: str) -> FMU2Slave:
    slave = FMU2Slave(
        guid=kit.description.guid,
        unzipDirectory=kit.unzipped,
        modelIdentifier=kit.description.coSimulation.modelIdentifier,
        instanceName=name,
    )
    slave.instantiate()
    slave.setupExperiment(tolerance=kit.settings["relative_tolerance"], startTime=start_time)
    slave.enterInitializationMode()
    start = kit.start_values()
    slave.setReal([kit.vr[n] for n in start], list(start.values()))
    slave.exitInitializationMode()
    return slave


def co_simulation(kit: Kit, mistake: str | None = None) -> Path:
    """A Co-Simulation master: set the torque (and its slope), read the outputs, step; with a
    resume_time, keep the FMU state there and go on in a new instance.
    """
    times = kit.times
    if mistake == "drift":
        # Time summed in single precision, as a master with a float clock does.
        clock = np.cumsum(
            np.r_[np.float32(kit.settings["start_time"]), np.full(len(times) - 2, np.float32(kit.step))],
            dtype=np.float32,
        )
        times = np.r_[clock.astype(float), kit.settings["stop_time"]]
    torque, slope = kit.torques(times)
    if mistake == "late":  # step k gets what step k - 1 should
        torque, slope = [torque[0], *torque[:-1]], [slope[0], *slope[:-1]]
    elif mistake == "early":
        torque, slope = [*torque[1:], torque[-1]], [*slope[1:], 0.0]
    elif mistake == "exact_events":  # a change only where a summed clock equals its time (ECOS's scenarios)
        clock = np.cumsum(np.r_[times[0], np.full(len(torque) - 1, kit.step)])
        applied = [torque[0]]
        for k in range(1, len(torque)):
            applied.append(torque[k] if torque[k] != torque[k - 1] and clock[k] == times[k] else applied[-1])
        torque = applied
    elif mistake == "late_once":  # only the first change of the torque reaches the FMU a step late
        k = next(k for k in range(1, len(torque)) if torque[k] != torque[k - 1])
        torque = [*torque[:k], torque[k - 1], *torque[k + 1 :]]
    elif mistake == "scaled":  # a unit slip: 1 % too much torque
        torque = [1.01 * u for u in torque]
    elif mistake == "ramped":  # a slope towards the next step's value where the signal holds
        slope = [(b - a) / (t1 - t0) for a, b, t0, t1 in zip(torque, torque[1:], times, times[1:], strict=False)] + [
            0.0
        ]
    elif mistake == "held":  # no input derivatives where the run asks for a ramp
        slope = [0.0] * len(torque)
    ramps = any(slope)
    resume = kit.settings["resume_time"]
    slave = _slave(kit, times[0], "first")
    torque_vr, outputs = [kit.vr["torque"]], [kit.vr[n] for n in OUTPUTS]
    rows = []
    for k, (t, h) in enumerate(zip(times[:-1], np.diff(times), strict=False)):
        if resume is not None and abs(t - resume) < 1e-9 * kit.step:
            state = slave.getFMUstate()
            blob = slave.serializeFMUstate(state)
            slave.freeFMUstate(state)
            slave.terminate()
            slave.freeInstance()
            slave = _slave(kit, t, "resumed")
            if mistake != "not_restored":
                slave.setFMUstate(slave.deSerializeFMUstate(blob))
        slave.setReal(torque_vr, [torque[k]])
        if ramps:
            slave.setRealInputDerivatives(torque_vr, [1], [slope[k]])
        rows.append(slave.getReal(outputs))
        slave.doStep(currentCommunicationPoint=t, communicationStepSize=h)
    rows.append(slave.getReal(outputs))
    if mistake == "shifted":  # each step's result under its start time, one more step at the end (cofmupy)
        slave.doStep(currentCommunicationPoint=times[-1], communicationStepSize=times[-1] - times[-2])
        rows = [*rows[1:], slave.getReal(outputs)]
    elif mistake == "single":  # outputs as float32 (fmugym's observations)
        rows = [np.float32(row).tolist() for row in rows]
    slave.terminate()
    slave.freeInstance()
    return kit.write(times, rows)


def summed_clock(kit: Kit) -> Path:
    """A master that steps the FMU while its own time is at or past the FMU's next point on a
    clock summed step by step, compared without a tolerance, then sets the signal at its time for
    the next step (FMI++'s FixedStepSizeFMU.sync): where the clocks round apart, a step skipped,
    two taken later.
    """
    slave = _slave(kit, kit.times[0], "summed")
    torque_vr, outputs = [kit.vr["torque"]], [kit.vr[n] for n in OUTPUTS]
    torque, _ = kit.torques(kit.times)
    slave.setReal(torque_vr, [torque[0]])
    clock, rows = kit.times[0], [slave.getReal(outputs)]
    for k, t in enumerate(kit.times[1:], start=1):
        while t >= clock + kit.step:
            slave.doStep(currentCommunicationPoint=clock, communicationStepSize=kit.step)
            clock += kit.step
        rows.append(slave.getReal(outputs))
        if k < len(torque):
            slave.setReal(torque_vr, [torque[k]])
    slave.terminate()
    slave.freeInstance()
    return kit.write(kit.times, rows)


def model_exchange(kit: Kit, method: str) -> Path:
    """A master that integrates the Model Exchange interface itself, one solver step per
    communication step, holding each step's torque: explicit Euler, or Heun (second order).
    """
    model = FMU2Model(
        guid=kit.description.guid,
        unzipDirectory=kit.unzipped,
        modelIdentifier=kit.description.modelExchange.modelIdentifier,
        instanceName="me",
    )
    model.instantiate()
    model.setupExperiment(startTime=kit.times[0])
    model.enterInitializationMode()
    start = kit.start_values()
    model.setReal([kit.vr[n] for n in start], list(start.values()))
    model.exitInitializationMode()
    model.newDiscreteStates()
    model.enterContinuousTimeMode()
    x = np.array([start["theta"], start["omega"]])
    states, derivatives = (ctypes.c_double * 2)(), (ctypes.c_double * 2)()

    def f(t, x):
        model.setTime(t)
        states[:] = x.tolist()
        model.setContinuousStates(states, 2)
        model.getDerivatives(derivatives, 2)
        return np.array(derivatives[:])

    torque, _ = kit.torques(kit.times)
    outputs, rows = [kit.vr[n] for n in OUTPUTS], []
    for t, h, u in zip(kit.times[:-1], np.diff(kit.times), torque, strict=False):
        model.setReal([kit.vr["torque"]], [u])
        slope = f(t, x)
        rows.append(model.getReal(outputs))
        if method == "euler":
            x = x + h * slope
        else:
            x = x + h / 2 * (slope + f(t + h, x + h * slope))
    f(kit.times[-1], x)
    rows.append(model.getReal(outputs))
    model.terminate()
    model.freeInstance()
    return kit.write(kit.times, rows)


def run(folder: Path, name: str, mistake: str | None = None) -> Path:
    """Run scenario `name` of the kit in `folder`, making `mistake` (None: none); returns the
    NAME_out.csv written.
    """
    kit = Kit(folder, name)
    if mistake in ("euler", "heun"):
        return model_exchange(kit, mistake)
    if mistake == "summed_clock":
        return summed_clock(kit)
    return co_simulation(kit, mistake)


def main() -> int:
    """Every wrong master of WRONG_MASTERS on a fresh kit, and what the judge says of it."""
    import tempfile

    from pendulum_fmu.judging._judge import judge
    from pendulum_fmu.scenarios._scenario_settings import read_settings
    from pendulum_fmu.scenarios._scenarios import write_scenarios

    # residual: of the diagnosis (for integration error without a variant, the difference
    # itself); others: the smallest residual of every other candidate; both as fractions of
    # max|dtheta|. input: max|dtheta| over the smallest difference an input-timing mistake makes.
    print(
        f"{'scenario':<16} {'mistake made':<43} {'diagnosis':<28} {'max|dtheta|':>11} {'residual':>9} "
        f"{'others':>8} {'input':>8}"
    )
    with tempfile.TemporaryDirectory() as folder:
        write_scenarios(folder)
        for name, mistake, _ in WRONG_MASTERS:
            settings = read_settings(Path(folder, f"{name}.json"))
            settings.pop("output")
            judgement = judge(run(Path(folder), name, mistake), **settings)
            raw = judgement.max_abs_dtheta
            others = min(
                s["residual"] for c, s in judgement.candidates.items() if s is not None and c != judgement.diagnosis
            )
            input_effect = judgement.smallest_input_effect
            print(
                f"{name:<16} {MISTAKES[mistake]:<43} {judgement.diagnosis:<28} {raw:>11.2e} "
                f"{judgement.residual / raw:>9.1e} {others / raw:>8.1e} "
                f"{'' if input_effect is None else f'{raw / input_effect:.1e}':>8}"
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
