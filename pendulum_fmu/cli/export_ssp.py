"""pendulum-fmu export-ssp: the pendulum under the PID controller as ClosedLoop.ssp, for any SSP master."""

from __future__ import annotations

import argparse
from pathlib import Path

from ._arguments import assignment, float_number, output_path, parameters_of


def add_parser(commands) -> argparse.ArgumentParser:
    """Declare `export-ssp` and its options, each with its help, among the parser's commands."""
    export = commands.add_parser(
        "export-ssp",
        help="write ClosedLoop.ssp: the pendulum and the PID controller for any SSP master",
        description="Write the closed loop as an SSP 1.0 archive: both FMUs, their connections, a parameter "
        "set per FMU, the DefaultExperiment and the fixed-step annotations of libcosim and OMSimulator "
        "(docs/ssp.md).",
    )
    export.add_argument(
        "output",
        type=output_path,
        nargs="?",
        default=Path("ClosedLoop.ssp"),
        help="the .ssp to write (default: %(default)s)",
    )
    export.add_argument(
        "--controller",
        type=assignment,
        action="append",
        metavar="NAME=VALUE",
        help="controller parameter in its set: setpoint (default 0.3), kp, ki, kd (repeatable)",
    )
    export.add_argument(
        "--set",
        dest="assignments",
        type=assignment,
        action="append",
        metavar="NAME=VALUE",
        help="pendulum parameter in its set: mass, length, inertia, gravity, damping (repeatable)",
    )
    export.add_argument(
        "--stop-time",
        type=float_number,
        default=3.0,
        help="the DefaultExperiment's stop time in s (default: %(default)s)",
    )
    export.add_argument(
        "--step-size", type=float_number, default=1e-3, help="the fixed communication step in s (default: %(default)s)"
    )
    export.add_argument(
        "--call-record",
        default=None,
        metavar="FILE",
        help="put the pendulum's callRecordFile in its parameter set: each master that applies the set "
        "has the pendulum write the record of its FMI calls to FILE, for judge --calls FILE --ssp (docs/ssp.md)",
    )
    export.add_argument("--overwrite", action="store_true", help="replace an existing output")
    export.set_defaults(run=run)
    return export


def run(args) -> int:
    """Run `pendulum-fmu export-ssp` with the parsed arguments; returns the exit status."""
    from ..ssp._ssp import export_ssp

    written = export_ssp(
        args.output,
        controller=dict(args.controller or ()),
        parameters=parameters_of(args.assignments),
        stop_time=args.stop_time,
        step_size=args.step_size,
        call_record=args.call_record,
        overwrite=args.overwrite,
    )
    print(f"wrote {written}")
    return 0
