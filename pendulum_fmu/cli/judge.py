"""pendulum-fmu judge: a result file from any tool against the reference, with the mistake named."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

from .._errors import InvalidInput
from ._arguments import (
    add_signal_arguments,
    check_outputs,
    float_number,
    output_path,
    parameters_of,
    signal_options,
    torque_signal,
)

if TYPE_CHECKING:
    from ..judging._judge import Judgement


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
        nargs="?",
        help="the result CSV, or a folder written by pendulum-fmu scenarios holding NAME_out.csv files",
    )
    judge.add_argument(
        "--calls",
        type=Path,
        default=None,
        metavar="LOG",
        help="judge what a master did instead of a result: LOG is the FMU's call record, or a master's "
        "whole log holding it or its own call log (fmpy --fmi-logging, fmusim --log-fmi-calls); with "
        "the run's options, names each difference by step, else prints the timeline (docs/calls.md)",
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
    judge.add_argument(
        "--ssp",
        type=Path,
        default=None,
        metavar="ClosedLoop.ssp",
        help="judge a closed-loop result (time, theta) of this SSP from any master, or with --calls the "
        "pendulum's call record of its run: name its coupling, whether the parameter sets arrived, its step "
        "and stop time (with --calls: each torque wrong for the coupling) (docs/ssp.md)",
    )
    judge.set_defaults(run=run)
    return judge


def run(args) -> int:
    """Run `pendulum-fmu judge` with the parsed arguments; returns the exit status."""
    from ..judging._judge import format_judgement, format_kit, judge, judge_kit, write_json

    if args.ssp is not None:
        return _judge_ssp(args)

    signal = torque_signal(args)
    if args.calls is not None:
        return _judge_calls(args, signal)
    if args.result is None:
        raise InvalidInput("judge needs a result file, a kit's folder, or --calls LOG")
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
    if figures:
        from ..figures._plot import plot_judgement  # matplotlib: loaded only to draw

    for title, path in figures.items():
        print(f"wrote {plot_judgement(judged[title], path, title)}")
    if args.json:
        print(f"wrote {write_json(verdicts, args.json)}")
    return 0 if all(judgement.passed for judgement in judged.values()) else 1


def _judge_ssp(args) -> int:
    """`judge RESULT --ssp` or `judge --calls LOG --ssp`: what a master did with ClosedLoop.ssp."""
    if (args.result is None) == (args.calls is None):
        raise InvalidInput(
            "judge --ssp reads the master's result CSV or the pendulum's call record, one of them: "
            "pendulum-fmu judge RESULT.csv --ssp ClosedLoop.ssp [--map theta=COLUMN], or "
            "pendulum-fmu judge --calls LOG --ssp ClosedLoop.ssp"
        )
    if args.calls is not None:
        from ..ssp._ssp_calls import format_ssp_calls_verdict, judge_ssp_calls

        calls_verdict = judge_ssp_calls(args.calls, args.ssp)
        print(format_ssp_calls_verdict(calls_verdict))
        return 0 if calls_verdict.passed else 1
    from ..ssp._ssp_judge import format_ssp_verdict, judge_ssp_result

    verdict = judge_ssp_result(args.result, args.ssp, mapping=args.mapping)
    print(format_ssp_verdict(verdict))
    return 0 if verdict.passed else 1


def _judge_calls(args, signal) -> int:
    """`judge --calls LOG`: the master's calls (read by _call_record) against the intended run
    (_call_judge).
    """
    from ..fmu._parameters import variables
    from ..judging._call_judge import IntendedRun, format_calls, judge_calls, write_calls_json

    if args.result is not None:
        raise InvalidInput(f"--calls judges a log, not a result: leave out {args.result}")
    check_outputs({"--json": args.json, "--plot": args.plot}, {"--calls": args.calls})
    intended = (
        None
        if signal is None
        else IntendedRun(
            signal,
            ramp=args.ramp,
            parameters=parameters_of(args.assignments),
            start_time=args.start_time,
            start_values={"theta0": args.theta0, "omega0": args.omega0},
        )
    )
    names = {variable.valueReference: name for name, variable in variables(args.fmu).items()}
    judged = judge_calls(args.calls, intended, names)
    print(format_calls(judged))
    if args.plot:
        from ..figures._plot import plot_calls

        print(f"wrote {plot_calls(judged, args.plot, args.calls.name)}")
    if args.json:
        print(f"wrote {write_calls_json(judged, args.json)}")
    return 0 if all(not result["differences"] for result in judged.values()) else 1
