"""pendulum-fmu build: the FMU from fmu_src/ and modelDescription.xml, in a checkout only.

It runs the repository's build tool (fmu_build/, beside the package), the developer's build that
`python build_fmu.py` runs too; an installed package does not list this command.
"""

from __future__ import annotations

import argparse
import zipfile

from .. import FMU_FILES
from .._checkout import CHECKOUT_FMUS, build_tool
from .._errors import BuildError
from ._arguments import output_path


def _platforms(text: str) -> tuple[str, ...]:
    platforms = tuple(name.strip() for name in text.split(",") if name.strip())
    try:
        build_tool().check_platforms(platforms)
    except BuildError as error:
        raise argparse.ArgumentTypeError(str(error)) from None
    return platforms


def add_parser(commands) -> argparse.ArgumentParser:
    """Declare `build` and its options, each with its help, among the parser's commands."""
    # Every command's parser builds this one: the build tool's platforms alone are read (its
    # platforms.py), not its sources.py (start-up time).
    tool = build_tool()
    build = commands.add_parser(
        "build",
        help="build the FMU in a checkout (same as python build_fmu.py)",
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
        choices=tuple(FMU_FILES),
        default=2,
        help="FMI standard of the FMU (default: %(default)s)",
    )
    build.add_argument(
        "--platforms",
        type=_platforms,
        default=None,
        help=f"comma-separated, among {', '.join(tool.PLATFORMS)} and, for FMI 3.0, {tool.WASM} (the "
        "WebAssembly component) (default: every one whose compiler is installed; the others are skipped "
        "with a note)",
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
    tool = build_tool()
    output = args.output or CHECKOUT_FMUS[args.fmi_version]
    path = tool.build_fmu(output, platforms=args.platforms, fmi_version=args.fmi_version, linux_glibc=args.linux_glibc)
    with zipfile.ZipFile(path) as fmu:
        binaries = [name for name in fmu.namelist() if name.startswith("binaries/")]
    print(f"wrote {path} ({', '.join(binaries)})")
    return 0
