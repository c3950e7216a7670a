"""The scenarios of the kit (_scenarios.py): each one's torque rows, times and start state."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Scenario:
    """One run of the kit: its torque rows (s, N.m) and the rest of its definition."""

    name: str
    description: str
    rows: tuple[tuple[float, float], ...]
    stop_time: float
    step_size: float
    parameters: dict = field(default_factory=dict)  # overrides of the FMU's defaults
    theta0: float = 0.0
    omega0: float = 0.0
    ramp: bool = False
    resume_time: float | None = None
    start_time: float = 0.0


def _random_steps(seed: int, stop_time: float, amplitude: float) -> tuple[tuple[float, float], ...]:
    """Levels in -amplitude..amplitude N.m (to the mN.m), jumping at random times on the ms grid
    50 to 400 ms apart.
    """
    rng = np.random.default_rng(seed)
    jumps_ms = np.cumsum(rng.integers(50, 400, size=int(stop_time * 20) + 1))
    jumps = [int(ms) / 1000 for ms in jumps_ms if ms < stop_time * 1000]
    levels = [round(float(level), 3) for level in rng.uniform(-amplitude, amplitude, len(jumps) + 1)]
    rows = [(0.0, levels[0])]
    for t, before, after in zip(jumps, levels, levels[1:], strict=False):
        rows += [(t, before), (t, after)]
    return tuple([*rows, (stop_time, levels[-1])])


SCENARIOS = (
    Scenario(
        "constant_torque",
        "The OpenSim tutorial's case: 20 N.m from rest, gravity on, 3 s in 1 ms steps.",
        ((0.0, 20.0), (3.0, 20.0)),
        stop_time=3.0,
        step_size=1e-3,
    ),
    Scenario(
        "steps_on_grid",
        "Jumps on communication points (0, 40 N.m from 0.5 s, -40 from 1.5 s, 10 "
        "from 2.5 s), gravity off so theta is a parabola between jumps, from theta = 0.2 rad and "
        "omega = -0.5 rad/s; 1 ms steps. At a jump, the step that starts there holds the value "
        "after it.",
        ((0.0, 0.0), (0.5, 0.0), (0.5, 40.0), (1.5, 40.0), (1.5, -40.0), (2.5, -40.0), (2.5, 10.0), (3.0, 10.0)),
        stop_time=3.0,
        step_size=1e-3,
        parameters={"gravity": 0.0},
        theta0=0.2,
        omega0=-0.5,
    ),
    Scenario(
        "random_steps",
        "A random level in -40..40 N.m, jumping every 50 to 400 ms on the ms grid, "
        "4 s in 1 ms steps, with damping 0.5 N.m.s/rad, from theta = 0.3 rad and omega = -0.5 "
        "rad/s.",
        _random_steps(25, 4.0, 40.0),
        stop_time=4.0,
        step_size=1e-3,
        parameters={"damping": 0.5},
        theta0=0.3,
        omega0=-0.5,
    ),
    Scenario(
        "decimal_steps",
        "9 ms steps with jumps at 0.027, 0.333 and 0.45 s: decimals that are no "
        "binary fractions (3 x 0.009 is 0.026999999999999996 in binary), so a master that "
        "compares times for equality or sums its steps misses them; 0.9 s.",
        (
            (0.0, 10.0),
            (0.027, 10.0),
            (0.027, -20.0),
            (0.333, -20.0),
            (0.333, 30.0),
            (0.45, 30.0),
            (0.45, 5.0),
            (0.9, 5.0),
        ),
        stop_time=0.9,
        step_size=0.009,
    ),
    Scenario(
        "ramp",
        "The torque is the CSV's own line, kinks on communication points: each 10 ms step "
        "ramps, so a master sends the slope with fmi2SetRealInputDerivatives (order 1) before "
        "each fmi2DoStep; 3 s.",
        ((0.0, 0.0), (0.5, 40.0), (1.5, -40.0), (2.5, 20.0), (3.0, 20.0)),
        stop_time=3.0,
        step_size=0.01,
        ramp=True,
    ),
    Scenario(
        "resume",
        "Stopped at 1.5 s and resumed through a saved FMU state: take the state there "
        "(fmi2GetFMUstate, and fmi2SerializeFMUstate to keep it), free the instance, restore the "
        "state into a new one (fmi2DeSerializeFMUstate, fmi2SetFMUstate) and go on to 3 s, setting "
        "the torque again: it jumps from 20 to -20 N.m at 1.5 s. From theta = -0.2 rad and omega = 1 "
        "rad/s, 1 ms steps. The result equals an uninterrupted run.",
        ((0.0, 20.0), (1.5, 20.0), (1.5, -20.0), (3.0, -20.0)),
        stop_time=3.0,
        step_size=1e-3,
        theta0=-0.2,
        omega0=1.0,
        resume_time=1.5,
    ),
)
