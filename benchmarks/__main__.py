"""Run every benchmark of the pendulum FMU and print one table.

Builds the pendulum FMU, the null FMU and the C master from this checkout into a scratch
directory, runs every part and prints one table of results (and the accuracy grid).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

from .accuracy_cost import accuracy_cost_rows
from .builds import build_fmi3_fmu, build_null_fmu, build_pendulum_fmu, build_step_master
from .case_cost import case_cost_rows
from .fixed_cost import fixed_cost_rows
from .floor import floor_rows
from .judge_cost import judge_cost_rows
from .own_cost import own_cost_rows
from .peers import opensim_rows, pythonfmu_rows
from .python_loop import python_loop_rows
from .realtime import realtime_rows
from .report import as_markdown, as_text, main_table
from .scale import scale_rows
from .small_studies import small_study_rows
from .wasm_cost import wasm_cost_rows

PARTS = (
    "floor",
    "own-cost",
    "accuracy",
    "python-loop",
    "fixed-cost",
    "opensim",
    "pythonfmu",
    "scale",
    "small-studies",
    "realtime",
    "wasm",
    "judge",
)
DEFAULT_FIGURE = Path(__file__).resolve().parent / "accuracy_cost.png"


def parse_arguments(argv):
    parser = argparse.ArgumentParser(
        prog="python -m benchmarks", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument(
        "--quick", action="store_true", help="5 repetitions instead of 21, and 4 tolerances instead of 10"
    )
    parser.add_argument(
        "--skip",
        action="append",
        choices=PARTS,
        default=[],
        metavar="PART",
        help=f"leave a part out (repeatable): {', '.join(PARTS)}",
    )
    parser.add_argument(
        "--only",
        action="append",
        choices=PARTS,
        default=[],
        metavar="PART",
        help="run only this part (repeatable); the others are left out",
    )
    parser.add_argument(
        "--markdown", type=Path, metavar="FILE", help="also write the tables as markdown to FILE (for the README)"
    )
    parser.add_argument(
        "--figure",
        type=Path,
        default=DEFAULT_FIGURE,
        metavar="FILE",
        help="where the accuracy/cost figure goes (default: %(default)s)",
    )
    parser.add_argument(
        "--before",
        type=Path,
        metavar="CHECKOUT",
        help="small-studies: a checkout of another version (e.g. main's) to run side by side with this one",
    )
    return parser.parse_args(argv)


def progress(message: str) -> None:
    print(f"benchmarks: {message}", file=sys.stderr, flush=True)


def main(argv=None) -> int:
    args = parse_arguments(argv)
    repetitions = 5 if args.quick else 21
    wanted = [part for part in PARTS if part not in args.skip and (not args.only or part in args.only)]
    rows, grid = [], None
    with tempfile.TemporaryDirectory(prefix="pendulum-benchmarks-") as scratch:
        scratch = Path(scratch)
        progress("building the pendulum FMU, the null FMU and the C master")
        pendulum, null = build_pendulum_fmu(scratch), build_null_fmu(scratch)
        master = build_step_master(scratch)
        for part in wanted:
            progress(f"running {part}")
            if part == "floor":
                rows += floor_rows(pendulum, null, repetitions)
            elif part == "own-cost":
                rows += own_cost_rows(master, pendulum, null)
            elif part == "accuracy":
                accuracy, grid = accuracy_cost_rows(master, pendulum, args.quick, args.figure)
                rows += accuracy
            elif part == "python-loop":
                rows += python_loop_rows(pendulum, repetitions)
            elif part == "fixed-cost":
                rows += fixed_cost_rows(pendulum, repetitions)
            elif part == "opensim":
                rows += opensim_rows(pendulum, repetitions)
            elif part == "pythonfmu":
                rows += pythonfmu_rows(pendulum, scratch, repetitions)
            elif part == "scale":
                rows += scale_rows(pendulum, args.quick) + case_cost_rows(pendulum, args.quick)
            elif part == "small-studies":
                rows += small_study_rows(pendulum.path, args.quick, args.before)
            elif part == "realtime":
                rows += realtime_rows(pendulum, scratch)
            elif part == "wasm":
                rows += wasm_cost_rows(build_fmi3_fmu(scratch), repetitions)
            elif part == "judge":
                rows += judge_cost_rows(3 if args.quick else 5)
    tables = [main_table(rows)] + ([grid] if grid else [])
    print("\n\n".join(as_text(table) for table in tables))
    if args.markdown:
        args.markdown.parent.mkdir(parents=True, exist_ok=True)
        args.markdown.write_text("\n\n".join(as_markdown(table) for table in tables) + "\n")
        progress(f"wrote {args.markdown}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
