"""pendulum-fmu scenarios: a kit of scenarios for testing a master with this FMU."""

from __future__ import annotations

import argparse

from ._arguments import add_fmu_argument, output_path


def add_parser(commands) -> argparse.ArgumentParser:
    """Declare `scenarios` and its options, each with its help, among the parser's commands."""
    scenarios = commands.add_parser(
        "scenarios",
        help="write a kit of scenarios for testing a master with this FMU",
        description="Write the FMU (carrying the kit as FMI-LS-REF related files) and, per scenario, "
        "its torque (NAME_in.csv), settings (NAME.json) and reference (NAME_ref.csv), "
        "with a ReadMe.md: run each in your master, write NAME_out.csv beside it, then "
        "pendulum-fmu judge FOLDER.",
    )
    scenarios.add_argument("--output-dir", type=output_path, required=True, help="the kit's folder")
    scenarios.add_argument(
        "--overwrite",
        action="store_true",
        help="replace the kit --output-dir holds, once the new one is whole; "
        "results (NAME_out.csv) are kept (without it, a folder holding a "
        "kit is refused)",
    )
    scenarios.add_argument(
        "--closed-loop",
        action="store_true",
        help="also write the pendulum under the PID controller as ClosedLoop.ssp, with its settings "
        "(ClosedLoop.json) and a reference per coupling (ClosedLoop_ref.csv)",
    )
    add_fmu_argument(scenarios)
    scenarios.set_defaults(run=run)
    return scenarios


def run(args) -> int:
    """Run `pendulum-fmu scenarios` with the parsed arguments; returns the exit status."""
    from ..scenarios._scenarios import write_scenarios

    written = write_scenarios(args.output_dir, args.fmu, overwrite=args.overwrite)
    if args.closed_loop:
        from ..ssp._ssp_kit import write_closed_loop_kit

        written += write_closed_loop_kit(args.output_dir, overwrite=args.overwrite)
    for path in written:
        print(f"wrote {path}")
    return 0
