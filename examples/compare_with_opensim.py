"""One step-wise torque signal through the FMU, the independent reference and OpenSim 4.6, with the
table of differences and the comparison figure (needs pip install -e ".[opensim]").
Exits 1 when two tools differ by more than --tol.
"""

import argparse
import sys
from pathlib import Path

from pendulum_fmu import compare, format_table

# A torque that steps every half second: the kind of signal users compare across tools.
STEPWISE_TORQUE = "time,torque\n0,20\n0.5,20\n0.5,-10\n1,-10\n1,35\n1.5,35\n1.5,0\n2,0\n2,15\n3,15\n"


def run(torque_file=None, stop_time=3.0, output_dir="out/compare_with_opensim", tol=1e-9):
    """The Comparison of the three tools on torque_file (default: STEPWISE_TORQUE), its table printed."""
    output_dir = Path(output_dir)
    if torque_file is None:
        output_dir.mkdir(parents=True, exist_ok=True)
        torque_file = output_dir / "torque.csv"
        torque_file.write_text(STEPWISE_TORQUE)
    comparison = compare(
        torque_file, ("fmu", "reference", "opensim"), output_dir=output_dir, stop_time=stop_time, tolerance=tol
    )
    print(format_table(comparison.differences))
    print(f"worst difference {comparison.worst:.2e} (tolerance {tol:g}); wrote {comparison.figure}")
    return comparison


def main(argv=None):
    """The command line; exit status 0 when the tools agree within --tol, else 1."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument(
        "--torque-file",
        type=Path,
        default=None,
        help="time,torque CSV in fmpy's convention (default: a built-in step signal)",
    )
    parser.add_argument("--stop-time", type=float, default=3.0, help="s (default: %(default)s)")
    parser.add_argument("--output-dir", default="out/compare_with_opensim", help="where results go")
    parser.add_argument("--tol", type=float, default=1e-9, help="rad (default: %(default)s)")
    args = parser.parse_args(argv)
    return 0 if run(args.torque_file, args.stop_time, args.output_dir, args.tol).agree else 1


if __name__ == "__main__":
    sys.exit(main())
