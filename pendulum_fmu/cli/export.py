"""pendulum-fmu export: the FMU written into the current folder (pendulum_fmu.fmu._export)."""

from __future__ import annotations

import argparse

from .. import FMU_FILES
from ._arguments import output_path


def add_parser(commands) -> argparse.ArgumentParser:
    """Declare `export` and its options, each with its help, among the parser's commands."""
    export = commands.add_parser(
        "export",
        help="write the FMU into the current folder",
        description="Write the FMU (Pendulum.fmu, or Pendulum-fmi3.fmu for FMI 3.0) and say which platforms "
        "it has binaries for.",
    )
    export.add_argument(
        "--fmi-version",
        type=int,
        choices=tuple(FMU_FILES),
        default=2,
        help="FMI standard of the FMU (default: %(default)s)",
    )
    export.add_argument(
        "--output",
        type=output_path,
        default=None,
        help=f"where to write it (default: {FMU_FILES[2]}, or {FMU_FILES[3]} for FMI 3.0, in the current folder)",
    )
    export.add_argument(
        "--overwrite", action="store_true", help="replace a file already at the output path (default: refuse)"
    )
    export.add_argument(
        "--sign",
        metavar="KEY",
        default=None,
        help="sign the FMU's build record with this Ed25519 private key (PEM, as `openssl genpkey -algorithm "
        "ed25519` writes it); `pendulum-fmu verify --public-key` checks it",
    )
    export.set_defaults(run=run)
    return export


def run(args) -> int:
    """Run `pendulum-fmu export` with the parsed arguments; returns the exit status."""
    from ..fmu._export import export_fmu

    exported = export_fmu(args.output, fmi_version=args.fmi_version, overwrite=args.overwrite, sign=args.sign)
    signed = ", its build record signed" if args.sign else ""
    print(f"wrote {exported.path} (binaries for {', '.join(exported.platforms)}{signed})")
    return 0
