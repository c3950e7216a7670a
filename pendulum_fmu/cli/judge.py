"""pendulum-fmu judge: a result file from any tool against the reference, with the mistake named."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import InvalidInput
from ._arguments import (
    add_signal_arguments,
    check_outputs,
    float_number,
    output_path,
    signal_options,
    torque_signal,
)

if TYPE_CHECKING:
    from ..judge import Judgement


def add_parser(commands) -> argparse.ArgumentParser:
    """Declare `judge` and its options, each with its help, among the parser's commands."""
    judge = commands.add_parser(
        "judge",
        help="judge a result file from any tool, and name the mistake",
        description="Compare a result file from any tool (a CSV with time and theta, optionally "
        "omega and alpha) with the independent reference at its own times: pass when "
        "max |dtheta| <= --tol (exit 0), else fail (exit 1) with the mistake that "
        "explains the difference (input one step late or early, interpolated, held, "
        "time grid drift, state not restored, integration error, or unexplained). "
        "Given a scenario kit's folder, judges every NAME_out.csv in it.",
    )
    judge.add_argument(
        "result",
        type=Path,
        help="the result CSV, or a folder written by pendulum-fmu scenarios holding NAME_out.csv files",
    )
    add_signal_arguments(judge, required=False)
    judge.add_argument(
        "--start-time", type=float_number, default=0.0, help="start of the run in s (default: %(default)s)"
    )
    judge.add_argument(
        "--ramp", action="store_true", help="the run ramped the torque along the CSV's line (input derivatives)"
    )
    judge.add_argument(
        "--tol",
        type=float_number,
        default=None,
        help="largest |dtheta| in rad that passes (default: 1e-9, or for a kit each scenario's own)",
    )
    judge.add_argument(
        "--map",
        dest="mapping",
        default=None,
        metavar="QUANTITY=COLUMN[*FACTOR],...",
        help="the result's column names for time, theta, omega and alpha, with a factor "
        "to SI where it uses other units, e.g. theta=phi*0.0174532925",
    )
    judge.add_argument(
        "--json",
        type=output_path,
        default=None,
        help="write the verdict, diagnosis, max |dtheta|, worst time and every candidate's residual (rad) as JSON",
    )
    judge.add_argument(
        "--plot",
        type=output_path,
        default=None,
        help="write a PNG of the torque, theta and |dtheta| (for a kit: a folder, one NAME.png per scenario)",
    )
    judge.set_defaults(run=run)
    return judge


def run(args) -> int:
    """Run `pendulum-fmu judge` with the parsed arguments; returns the exit status."""
    from ..judge import format_judgement, format_kit, judge, judge_kit, write_json
    from ..plot import plot_judgement

    signal = torque_signal(args)
    is_kit = args.result.is_dir()
    kit_files = [path for path in args.result.iterdir() if path.is_file()] if is_kit else []
    check_outputs(
        {"--json": args.json, **({} if is_kit else {"--plot": args.plot})},
        {
            "the result": args.result,
            "--torque-file": args.torque_file,
            "--fmu": args.fmu,
            **{f"the kit's {path.name}": path for path in kit_files},
        },
    )
    if is_kit:
        if signal is not None:
            raise InvalidInput(
                f"{args.result} is a folder, judged as a scenario kit whose NAME.json "
                "files define the runs: leave out --torque and --torque-file"
            )
        kit = judge_kit(args.result, tolerance=args.tol, mapping=args.mapping, fmu_path=args.fmu)
        print(format_kit(kit))
        judged = {name: judgement for name, judgement in kit.items() if judgement is not None}
        verdicts: dict[str, Judgement | None] | Judgement = kit
        figures = {name: args.plot / f"{name}.png" for name in judged} if args.plot else {}
    else:
        if signal is None:
            raise InvalidInput(
                "judging a result file needs the run's torque: give --torque N.m or "
                "--torque-file F.csv (or judge a scenario kit's folder)"
            )
        verdicts = judgement = judge(
            args.result,
            signal,
            start_time=args.start_time,
            tolerance=args.tol,
            mapping=args.mapping,
            **signal_options(args),
        )
        print(format_judgement(judgement))
        judged = {args.result.name: judgement}
        figures = {args.result.name: args.plot} if args.plot else {}
    for title, path in figures.items():
        print(f"wrote {plot_judgement(judged[title], path, title)}")
    if args.json:
        print(f"wrote {write_json(verdicts, args.json)}")
    return 0 if all(judgement.passed for judgement in judged.values()) else 1
