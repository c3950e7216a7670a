"""pendulum-fmu build: the FMU from fmu_src/ and modelDescription.xml."""

from __future__ import annotations

import argparse
import zipfile

from ..build import CHECKOUT_FMUS, FMI_VERSIONS, PLATFORMS, BuildError, check_platforms
from ._arguments import output_path


def _platforms(text: str) -> tuple[str, ...]:
    platforms = tuple(name.strip() for name in text.split(",") if name.strip())
    try:
        check_platforms(platforms)
    except BuildError as error:
        raise argparse.ArgumentTypeError(str(error)) from None
    return platforms


def add_parser(commands) -> argparse.ArgumentParser:
    """Declare `build` and its options, each with its help, among the parser's commands."""
    build = commands.add_parser(
        "build",
        help="build the FMU (same as python build_fmu.py)",
        description="Build the FMU from fmu_src/ and modelDescription.xml (a source checkout or the unpacked sdist).",
    )
    build.add_argument(
        "--output",
        type=output_path,
        default=None,
        help=f"where to write the FMU (default: {CHECKOUT_FMUS[2]}, or {CHECKOUT_FMUS[3]} for FMI 3.0)",
    )
    build.add_argument(
        "--fmi-version",
        type=int,
        choices=FMI_VERSIONS,
        default=2,
        help="FMI standard of the FMU (default: %(default)s)",
    )
    build.add_argument(
        "--platforms",
        type=_platforms,
        default=None,
        help=f"comma-separated, among {', '.join(PLATFORMS)} (default: every one "
        "whose compiler is installed; the others are skipped with a note)",
    )
    build.add_argument(
        "--linux-glibc",
        default=None,
        metavar="VERSION",
        help="build the Linux binaries with zig (pip install ziglang) to load on this glibc "
        "and every later one, such as 2.17, manylinux2014's (default: with gcc, for "
        "this machine's glibc)",
    )
    build.set_defaults(run=run)
    return build


def run(args) -> int:
    """Run `pendulum-fmu build` with the parsed arguments; returns the exit status."""
    from ..build import build_fmu

    output = args.output or CHECKOUT_FMUS[args.fmi_version]
    path = build_fmu(output, platforms=args.platforms, fmi_version=args.fmi_version, linux_glibc=args.linux_glibc)
    with zipfile.ZipFile(path) as fmu:
        binaries = [name for name in fmu.namelist() if name.startswith("binaries/")]
    print(f"wrote {path} ({', '.join(binaries)})")
    return 0
