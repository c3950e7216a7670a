"""Build dist/Pendulum.fmu (FMI 2.0 Co-Simulation) from fmu_src/ and modelDescription.xml."""

import argparse
import sys

from pendulum_fmu.build import DEFAULT_FMU, BuildError, build_fmu


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--output", default=str(DEFAULT_FMU),
                        help="where to write the FMU (default: %(default)s)")
    parser.add_argument("--cc", default=None, help="C compiler (default: $CC or gcc)")
    parser.add_argument("--platforms", default="linux64",
                        help="comma-separated, among linux64 and win64 (cross-compiled with "
                             "mingw-w64) (default: %(default)s)")
    args = parser.parse_args(argv)
    try:
        path = build_fmu(args.output, compiler=args.cc,
                         platforms=tuple(p.strip() for p in args.platforms.split(",")))
    except BuildError as error:
        print(f"build_fmu.py: {error}", file=sys.stderr)
        return 1
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
