"""The signal cases of issue 10: each signal through `simulate` and the independent oracle.

Prints, for each case, the largest |theta - oracle| and |torque received - signal| over the run.
The "before" column of docs/signals.md is this script run against the code before the fix.

    python -m benchmarks.signal_cases
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

from pendulum_fmu.fmu._simulate import simulate
from pendulum_fmu.oracle._reference import reference


def random_step_rows(rng: np.random.Generator, stop_time: float = 4.0, running_sum: bool = False) -> list[tuple]:
    """A random step signal: levels held for random decimal durations (ms resolution). With
    running_sum the times are what a tool accumulating durations writes (0.39100000000000029).
    tests/test_torque_schedule_exactness.py draws its signals here too.
    """
    durations = rng.integers(20, 400, size=60) / 1000
    if running_sum:
        times = np.cumsum(durations)
    else:
        times = np.cumsum(rng.integers(20, 400, size=60)) / 1000
    times = times[times < stop_time]
    levels = rng.uniform(-40, 40, size=len(times) + 1)
    rows = [(0.0, levels[0])]
    for t, before, after in zip(times, levels, levels[1:], strict=False):
        rows += [(repr(float(t)), before), (repr(float(t)), after)]
    rows.append((stop_time, levels[len(times)]))
    return rows


def write_rows(path: Path, rows) -> Path:
    """A time,torque CSV of (time, torque) rows, each written with str()."""
    path.write_text("time,torque\n" + "".join(f"{t},{u}\n" for t, u in rows))
    return path


CASES = [
    # (label, rows, simulate arguments)
    ("jump at 0.027 s, 9 ms steps", [(0, 10), (0.027, 10), (0.027, -20), (2, -20)], dict(step_size=0.009)),
    (
        "jumps at 0.33 and 0.45 s, 30 ms steps",
        [(0, 5), (0.33, 5), (0.33, -30), (0.45, -30), (0.45, 25), (1.5, 25)],
        dict(step_size=0.03),
    ),
    ("first row a jump, 1 ms steps", [(0, 0), (0, 20), (1, 20)], dict(step_size=1e-3)),
    ("4 s random steps, decimal times, 1 ms", random_step_rows(np.random.default_rng(1)), dict(step_size=1e-3)),
    (
        "4 s random steps, running-sum times, 1 ms",
        random_step_rows(np.random.default_rng(1), running_sum=True),
        dict(step_size=1e-3),
    ),
    ("kink at 0.3915 s, ramp, 10 ms steps", [(0, 0), (0.3915, 20), (1, -5), (2, 10)], dict(step_size=0.01, ramp=True)),
    ("kink at 0.3915 s, ramp, 100 ms steps", [(0, 0), (0.3915, 20), (1, -5), (2, 10)], dict(step_size=0.1, ramp=True)),
]


def run_case(rows, arguments, folder: Path) -> tuple[float, float]:
    csv = write_rows(folder / "signal.csv", rows)
    run = simulate(csv, tolerance=1e-12, **arguments)
    oracle = reference(csv, at=run["time"], **arguments)
    return (
        float(np.max(np.abs(run["theta"] - oracle["theta"]))),
        float(np.max(np.abs(run["torque"][:-1] - oracle["torque"][:-1]))),
    )


def main() -> int:
    print(f"{'case':<44} {'max|dtheta| rad':>16} {'max|dtorque| N.m':>17}")
    with tempfile.TemporaryDirectory() as folder:
        for label, rows, arguments in CASES:
            try:
                theta, torque = run_case(rows, arguments, Path(folder))
                print(f"{label:<44} {theta:>16.2e} {torque:>17.2e}")
            except Exception as error:  # the old code refuses some cases outright
                print(f"{label:<44} {'fails: ' + type(error).__name__ + ': ' + str(error)[:60]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
