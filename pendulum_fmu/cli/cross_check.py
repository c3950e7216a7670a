"""pendulum-fmu cross-check: reference results in the FMI cross-check layout."""

from __future__ import annotations

import argparse

from ._arguments import add_fmu_argument, output_path


def add_parser(commands) -> argparse.ArgumentParser:
    """Declare `cross-check` and its options, each with its help, among the parser's commands."""
    cross_check = commands.add_parser(
        "cross-check",
        help="reference results in the FMI cross-check layout",
        description="Write fmus/2.0/cs/<platform>/pendulum_fmu/<version>/Pendulum/ (the FMU, "
        "_in.csv, _ref.csv, _ref.opt, ReadMe.md) for a step-wise torque, one folder "
        "per platform the FMU has a binary for.",
    )
    cross_check.add_argument("--output-dir", type=output_path, required=True, help="the cross-check repository's root")
    add_fmu_argument(cross_check)
    cross_check.set_defaults(run=run)
    return cross_check


def run(args) -> int:
    """Run `pendulum-fmu cross-check` with the parsed arguments; returns the exit status."""
    from ..fmu._cross_check import write_cross_check

    for folder in write_cross_check(args.output_dir, args.fmu):
        print(f"wrote {folder}")
    return 0
