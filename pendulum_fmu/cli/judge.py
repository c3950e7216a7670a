"""pendulum-fmu judge: a result file from any tool against the reference, with the mistake named."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

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
        nargs="*",
        help="the result CSV; several results of the same run, judged against one reference; or a "
        "folder written by pendulum-fmu scenarios holding NAME_out.csv files",
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
    results: list[Path] = args.result
    if len(results) > 1 and (args.ssp is not None or args.calls is not None):
        raise InvalidInput(
            f"{'--ssp' if args.ssp is not None else '--calls'} judges one result or log at a time; "
            f"{len(results)} results were given: judge them one by one"
        )
    args.result = results[0] if results else None
    if args.ssp is not None:
        return _judge_ssp(args)

    signal = torque_signal(args)
    if args.calls is not None:
        return _judge_calls(args, signal)
    if args.result is None:
        raise InvalidInput("judge needs a result file, a kit's folder, or --calls LOG")
    folders = [path for path in results if path.is_dir()]
    if folders and len(results) > 1:
        raise InvalidInput(
            f"{folders[0]} is a folder, judged as a scenario kit on its own: give a kit's folder alone, "
            "or result files only"
        )
    if folders:
        return _judge_kit(args, signal)
    if signal is None:
        raise InvalidInput(
            "judging a result file needs the run's torque: give --torque N.m or "
            "--torque-file F.csv (or judge a scenario kit's folder)"
        )
    return _judge_results(args, signal, results)


def _judge_kit(args, signal) -> int:
    """`judge KIT`: every NAME_out.csv beside a scenario kit's NAME.json, each its own run."""
    from ..judging._judge import judge_kit
    from ..judging._judgement import format_kit, write_json

    kit_files = [path for path in args.result.iterdir() if path.is_file()]
    check_outputs(
        {"--json": args.json},
        {
            "the result": args.result,
            "--torque-file": args.torque_file,
            "--fmu": args.fmu,
            **{f"the kit's {path.name}": path for path in kit_files},
        },
    )
    if signal is not None:
        raise InvalidInput(
            f"{args.result} is a folder, judged as a scenario kit whose NAME.json "
            "files define the runs: leave out --torque and --torque-file"
        )
    kit = judge_kit(args.result, tolerance=args.tol, mapping=args.mapping, fmu_path=args.fmu)
    print(format_kit(kit))
    judged = {name: judgement for name, judgement in kit.items() if judgement is not None}
    if args.plot:
        _plot({name: (judged[name], args.plot / f"{name}.png") for name in judged})
    if args.json:
        print(f"wrote {write_json(kit, args.json)}")
    return 0 if all(judgement.passed for judgement in judged.values()) else 1


def _judge_results(args, signal, results: list[Path]) -> int:
    """`judge RESULT [RESULT ...]`: results of one run, against one reference (JudgedRun). A
    result that cannot be judged gets its one line and the others are judged; the exit status is
    the worst: 2 for such a result, else 1 for a fail, else 0.
    """
    from ..judging._judge import JudgedRun
    from ..judging._judgement import Judgement, format_judgement, write_json
    from ..judging._result_file import ResultFileError

    several = len(results) > 1
    check_outputs(
        {"--json": args.json, **({} if several else {"--plot": args.plot})},
        {
            **{f"the result {path}" if several else "the result": path for path in results},
            "--torque-file": args.torque_file,
            "--fmu": args.fmu,
        },
    )
    figures = _figure_paths(args.plot, results) if args.plot else {}
    run = JudgedRun(signal, start_time=args.start_time, tolerance=args.tol, **signal_options(args))
    verdicts: list[Judgement | dict] = []
    for number, path in enumerate(results):
        try:
            judgement = run.judge(path, args.mapping)
        except ResultFileError as error:
            if not several:
                raise
            print(f"pendulum-fmu judge: error: {error}", file=sys.stderr, flush=True)
            verdicts.append({"result": str(path), "error": str(error)})
            continue
        print(("\n" if number else "") + format_judgement(judgement), flush=True)
        verdicts.append(judgement)
    judged = [judgement for judgement in verdicts if isinstance(judgement, Judgement)]
    if several:
        print(f"\n{sum(j.passed for j in judged)} of {len(results)} results pass" + _not_judged(results, judged))
    _plot(
        {
            path.name: (judgement, figures[path])
            for path, judgement in zip(results, verdicts, strict=True)
            if isinstance(judgement, Judgement) and path in figures
        }
    )
    if args.json:
        print(f"wrote {write_json(verdicts if several else judged[0], args.json)}")
    if len(judged) < len(results):
        return 2
    return 0 if all(judgement.passed for judgement in judged) else 1


def _figure_paths(plot: Path, results: list[Path]) -> dict[Path, Path]:
    """Where --plot draws each result: the file itself for one, else FOLDER/NAME.png for each,
    the folder's name refused when two results would share a figure.
    """
    if len(results) == 1:
        return {results[0]: plot}
    figures: dict[Path, Path] = {}
    for path in results:
        figure = plot / f"{path.stem}.png"
        drawn = next((other for other, taken in figures.items() if taken == figure), None)
        if drawn is not None:
            raise InvalidInput(
                f"--plot {plot}: {drawn} and {path} would both be drawn as {figure}; "
                "give results with different names, or judge them in two calls"
            )
        figures[path] = figure
    return figures


def _plot(figures: dict) -> None:
    """Draw each judgement ({title: (judgement, path)}); matplotlib is loaded only here."""
    if not figures:
        return
    from ..figures._plot import plot_judgement

    for title, (judgement, path) in figures.items():
        print(f"wrote {plot_judgement(judgement, path, title)}")


def _not_judged(results: list[Path], judged: list) -> str:
    """The summary line's tail: how many results could not be judged, if any."""
    missing = len(results) - len(judged)
    return f"; {missing} could not be judged (each error line says why)" if missing else ""


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
