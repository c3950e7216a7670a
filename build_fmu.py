"""Build dist/Pendulum.fmu (FMI 2.0), or dist/Pendulum-fmi3.fmu (FMI 3.0), from fmu_src/ and
modelDescription.xml."""

import argparse
import sys

from pendulum_fmu.build import DEFAULT_FMU, DEFAULT_FMU3, BuildError, build_fmu


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--output", default=None,
                        help=f"where to write the FMU (default: {DEFAULT_FMU}, or {DEFAULT_FMU3} "
                             "for FMI 3.0)")
    parser.add_argument("--fmi-version", type=int, choices=(2, 3), default=2,
                        help="FMI standard of the FMU (default: %(default)s)")
    parser.add_argument("--cc", default=None, help="C compiler (default: $CC or gcc)")
    parser.add_argument("--platforms", default="linux64",
                        help="comma-separated, among linux64 and win64 (cross-compiled with "
                             "mingw-w64) (default: %(default)s)")
    args = parser.parse_args(argv)
    try:
        output = args.output or (DEFAULT_FMU3 if args.fmi_version == 3 else DEFAULT_FMU)
        path = build_fmu(output, compiler=args.cc, fmi_version=args.fmi_version,
                         platforms=tuple(p.strip() for p in args.platforms.split(",")))
    except BuildError as error:
        print(f"build_fmu.py: {error}", file=sys.stderr)
        return 1
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
