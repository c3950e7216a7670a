"""pendulum-fmu demo: the OpenSim tutorial end to end."""

from __future__ import annotations

import argparse
from pathlib import Path

from ._arguments import output_path


def add_parser(commands) -> argparse.ArgumentParser:
    """Declare `demo` and its options, each with its help, among the parser's commands."""
    demo = commands.add_parser(
        "demo",
        help="the OpenSim tutorial end to end",
        description="Gravity off and on against the reference (and "
        "OpenSim when installed), the overlay and the "
        "parameter study; prints the error table and writes "
        "the figures.",
    )
    demo.add_argument(
        "--output-dir",
        type=output_path,
        default=Path("demo"),
        help="folder for the figures and tables (default: %(default)s)",
    )
    demo.add_argument(
        "--workers",
        type=int,
        default=None,
        help="run the parameter study on a local dask cluster of this many workers "
        "(default: none: a study this small runs in the process)",
    )
    demo.add_argument(
        "--overwrite",
        action="store_true",
        help="replace the outputs of a previous demo --output-dir holds (without it, such a folder is refused)",
    )
    demo.set_defaults(run=run)
    return demo


def run(args) -> int:
    """Run `pendulum-fmu demo` with the parsed arguments; returns the exit status."""
    from ..comparing._demo import run_demo

    return 0 if run_demo(args.output_dir, workers=args.workers, overwrite=args.overwrite) else 1
