"""The FMU under fmpy's own command line: write a step-wise torque CSV in fmpy's convention (a
repeated time marks a step), run `fmpy simulate`, and check the result against the reference.
"""

import argparse
import subprocess
import sys
from pathlib import Path

import numpy as np

from pendulum_fmu import default_fmu, reference, schedule, write_torque_csv


def run(stop_time=3.0, output_dir="out/fmpy_command_line"):
    """Largest |theta - the reference's| in rad, at the times fmpy simulate wrote, for a three-level torque."""
    output_dir = Path(output_dir)
    plan = schedule(
        lambda t: 20.0 if t < stop_time / 3 else (-10.0 if t < 2 * stop_time / 3 else 5.0),
        stop_time=stop_time,
        step_size=stop_time / 6,
    )
    torque_csv = write_torque_csv(output_dir / "torque.csv", plan)
    result_csv = output_dir / "result.csv"
    command = [
        sys.executable,
        "-m",
        "fmpy",
        "simulate",
        str(default_fmu()),
        "--input-file",
        str(torque_csv),
        "--output-interval",
        "0.001",
        "--stop-time",
        str(stop_time),
        "--output-file",
        str(result_csv),
    ]
    print(" ".join(command[1:]))
    subprocess.run(command, check=True)
    result = np.genfromtxt(result_csv, delimiter=",", names=True)
    # fmpy writes both sides of each torque step; the first row of a repeated time is the step's end.
    first = np.unique(result["time"], return_index=True)[1]
    oracle = reference(torque_csv, stop_time=stop_time, at=result["time"][first])
    difference = np.max(np.abs(result["theta"][first] - oracle["theta"]))
    print(f"fmpy simulate against the reference: max |dtheta| = {difference:.2e} rad over {len(first)} points")
    return difference


def main(argv=None):
    """The command line: run() with its options."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--stop-time", type=float, default=3.0, help="s (default: %(default)s)")
    parser.add_argument("--output-dir", default="out/fmpy_command_line", help="where the CSVs go")
    args = parser.parse_args(argv)
    run(args.stop_time, args.output_dir)


if __name__ == "__main__":
    main()
