"""pendulum-fmu: build, simulate and compare the torque-driven pendulum FMU.

The command line only parses and calls: each command's function below turns its arguments
into one call of the package's API and prints what came back. A user's error (a
PendulumFmuError) is one line and exit 2; anything else is a bug of ours, one line too, with the
traceback on --debug.
"""

from __future__ import annotations

import argparse
import contextlib
import errno
import os
import signal
import sys
import threading
import warnings
import zipfile
from pathlib import Path

import numpy as np

from . import __version__
from .build import CHECKOUT_FMUS, FMI_VERSIONS, PLATFORMS, BuildError, PlatformSkipped, check_platforms
from .errors import InvalidInput, PendulumFmuError
from .stop_signals import STOPPING_SIGNALS, Stopped, restore_signals, stop_on_signals
from .sweep import DEFAULT_MAX_CASES
from .torque_schedule import DEFAULT_MAX_STEPS


def _assignment(text: str) -> tuple[str, str]:
    name, equals, value = text.partition("=")
    if not equals or not name or not value:
        raise argparse.ArgumentTypeError(f"expected name=value, got {text!r}")
    return name.strip(), value.strip()


def _output_path(text: str) -> Path:
    # An empty path would be the current folder: most likely an unset shell variable ("$OUT").
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path; give a file or folder name (is a shell "
                                         "variable unset?)")
    return Path(text)


def _output_location(text: str) -> str:
    """A folder's path or an fsspec URL, not empty."""
    _output_path(text)
    return text


def _float(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text} must be at least 1")
    return value


def _parameters(assignments) -> dict[str, float]:
    parameters = {}
    for name, value in assignments or ():
        try:
            parameters[name] = float(value)
        except ValueError:
            raise InvalidInput(f"--set {name}={value}: {value!r} is not a number") from None
    return parameters


def _torque_signal(args):
    return args.torque_file if args.torque_file is not None else args.torque


def _add_signal_arguments(parser, required: bool = True) -> None:
    group = parser.add_mutually_exclusive_group(required=required)
    group.add_argument("--torque", type=_float, help="constant torque in N.m")
    group.add_argument("--torque-file", type=Path,
                       help="CSV with columns time,torque in fmpy's convention: linear between "
                            "rows, a jump where a time repeats, held outside; each step holds the "
                            "value just after its start unless --ramp (docs/signals.md)")
    parser.add_argument("--stop-time", type=_float, default=None,
                        help="end of the simulation in s (default: 3, or the CSV's last time)")
    parser.add_argument("--step-size", type=_float, default=1e-3,
                        help="communication step in s (default: %(default)s)")
    parser.add_argument("--set", dest="assignments", type=_assignment, action="append",
                        metavar="NAME=VALUE",
                        help="parameter: mass, length, inertia, gravity, damping (repeatable)")
    parser.add_argument("--theta0", type=_float, default=0.0, help="initial angle in rad")
    parser.add_argument("--omega0", type=_float, default=0.0, help="initial rate in rad/s")
    parser.add_argument("--max-steps", type=_positive_int, default=None,
                        help=f"refuse runs longer than this many steps (default: {DEFAULT_MAX_STEPS:,})")
    _add_fmu_argument(parser)


def _add_fmu_argument(parser) -> None:
    parser.add_argument("--fmu", type=Path, default=None,
                        help="the FMU to run, whose own parameters and defaults apply (default: "
                             "the packaged FMU, or dist/Pendulum.fmu in a source checkout)")


def _platforms(text: str) -> tuple[str, ...]:
    platforms = tuple(name.strip() for name in text.split(",") if name.strip())
    try:
        check_platforms(platforms)
    except BuildError as error:
        raise argparse.ArgumentTypeError(str(error)) from None
    return platforms


# --- the commands: each parses its arguments into one call and prints what came back ----------

def cmd_build(args) -> int:
    from .build import build_fmu

    output = args.output or CHECKOUT_FMUS[args.fmi_version]
    path = build_fmu(output, platforms=args.platforms, fmi_version=args.fmi_version, linux_glibc=args.linux_glibc)
    with zipfile.ZipFile(path) as fmu:
        binaries = [name for name in fmu.namelist() if name.startswith("binaries/")]
    print(f"wrote {path} ({', '.join(binaries)})")
    return 0


def cmd_cross_check(args) -> int:
    from .cross_check import write_cross_check

    for folder in write_cross_check(args.output_dir, args.fmu):
        print(f"wrote {folder}")
    return 0


def _check_outputs(outputs: dict, inputs: dict) -> None:
    """Refuse before the run an output (option -> path) that cannot be written, that another
    output names too, or that is a file the command reads (option -> path): writing it would
    destroy the input."""
    from .atomic_files import check_writable
    from .plot import check_figure_path

    given = {option: Path(path) for option, path in outputs.items() if path}
    check_writable(*given.values())
    if given.get("--plot"):
        check_figure_path(given["--plot"])
    read = {option: Path(path) for option, path in inputs.items() if path}
    for number, (option, path) in enumerate(given.items()):
        for other, other_path in [*list(given.items())[:number], *read.items()]:
            if _same_file(path, other_path):
                raise InvalidInput(f"{option} {path} names the same file as {other}: writing it would "
                                   f"{'destroy what the command reads' if other in read else 'lose one of the two'}; "
                                   "choose another path")


def _same_file(one: Path, other: Path) -> bool:
    try:
        return one.samefile(other)
    except OSError:  # one of them does not exist yet: the same file only by its name
        return one.resolve() == other.resolve()


def cmd_simulate(args) -> int:
    from . import results
    from .simulate import simulate

    _check_outputs({"--output": args.output, "--plot": args.plot},
                   {"--torque-file": args.torque_file, "--fmu": args.fmu})
    run = simulate(_torque_signal(args), stop_time=args.stop_time, step_size=args.step_size,
                   ramp=args.ramp, parameters=_parameters(args.assignments), theta0=args.theta0,
                   omega0=args.omega0, tolerance=args.tolerance, max_steps=args.max_steps,
                   fmu_path=args.fmu)
    last = run[-1]
    print(f"{len(run) - 1} steps to t = {last['time']:g} s: theta = {last['theta']:.12g} rad, "
          f"omega = {last['omega']:.12g} rad/s, alpha = {last['alpha']:.12g} rad/s2; "
          f"max |theta| = {np.max(np.abs(run['theta'])):.6g} rad")
    if args.output:
        results.write_csv(run, args.output)
        print(f"wrote {args.output} ({','.join(results.FIELDS)}; units "
              f"{', '.join(results.UNITS.values())})")
    if args.plot:
        from .plot import case_title, plot_overlay

        title = case_title(_torque_signal(args), _parameters(args.assignments), args.theta0, args.omega0,
                           args.fmu)
        print(f"wrote {plot_overlay({'FMU': run}, args.plot, title)}")
    return 0


def cmd_compare(args) -> int:
    from .compare import compare, format_comparison

    comparison = compare(_torque_signal(args), args.tools, output_dir=args.output_dir,
                         step_size=args.step_size, stop_time=args.stop_time, ramp=args.ramp,
                         parameters=_parameters(args.assignments), theta0=args.theta0,
                         omega0=args.omega0, tolerance=args.tol, mapping=args.mapping,
                         max_steps=args.max_steps, fmu_path=args.fmu)
    print(format_comparison(comparison))
    for path in (comparison.trajectories, comparison.table, comparison.figure):
        print(f"wrote {path}")
    return 0 if comparison.agree else 1


def _sweep_values(assignments) -> dict[str, list[float]]:
    values = {}
    for name, text in assignments or ():
        try:
            values[name] = [float(v) for v in text.split(",")]
        except ValueError:
            raise InvalidInput(f"--set {name}={text}: expected comma-separated numbers") from None
    return values


def _sweep_outputs(text: str) -> tuple[str, ...]:
    return () if text.strip() == "none" else tuple(name.strip() for name in text.split(","))


def cmd_sweep(args) -> int:
    from .sweep import Study, run_sweep, sweep_grid

    study = Study(sweep_grid(args.torque, args.gravity, _sweep_values(args.assignments)),
                  stop_time=args.stop_time, step_size=args.step_size,
                  outputs=_sweep_outputs(args.outputs), output_interval=args.output_interval,
                  format=args.format, fmu_path=args.fmu)
    try:
        result = run_sweep(study, output_dir=args.output_dir, resume=args.resume,
                           overwrite=args.overwrite, scheduler=args.scheduler,
                           workers=args.workers, connect_timeout=args.connect_timeout,
                           max_cases=args.max_cases)
    except Stopped as stopped:
        what = STOPPING_SIGNALS[stopped.signal_number]
        if args.overwrite:
            print(f"pendulum-fmu sweep: {what}; {args.output_dir} holds what it held before (the "
                  "new study was not finished and is not kept): run the same command again to "
                  "start over", file=sys.stderr)
        elif "://" not in args.output_dir and not any(Path(args.output_dir).glob("*")):
            print(f"pendulum-fmu sweep: {what} before anything was written: run the same command "
                  "again to start", file=sys.stderr)
        else:
            print(f"pendulum-fmu sweep: {what}; the chunks that finished are kept in "
                  f"{args.output_dir}: run the same command with --resume to run the rest",
                  file=sys.stderr)
        return 128 + stopped.signal_number
    resumed = result.chunks_run < result.chunks
    print(f"{result.cases} cases in {result.seconds:.1f} s"
          + (f" ({result.chunks_run} of {result.chunks} chunks run; the others were "
             "written by an earlier run)" if resumed else ""))
    for path in (result.trajectories, result.cases_table, result.figure):
        if path is not None:  # no trajectories with --outputs none
            print(f"wrote {path}")
    if result.failed:
        # The other cases ran and are written; a script still learns that some did not.
        print(f"pendulum-fmu sweep: {result.failed} of {result.cases} cases failed: their "
              "status and message are in the cases table", file=sys.stderr)
        return 1
    return 0


def cmd_demo(args) -> int:
    from .demo import run_demo

    return 0 if run_demo(args.output_dir, workers=args.workers, overwrite=args.overwrite) else 1


def cmd_judge(args) -> int:
    from .judge import format_judgement, format_kit, judge, judge_kit, write_json
    from .plot import plot_judgement

    signal = _torque_signal(args)
    is_kit = args.result.is_dir()
    kit_files = [path for path in args.result.iterdir() if path.is_file()] if is_kit else []
    _check_outputs({"--json": args.json, **({} if is_kit else {"--plot": args.plot})},
                   {"the result": args.result, "--torque-file": args.torque_file, "--fmu": args.fmu,
                    **{f"the kit's {path.name}": path for path in kit_files}})
    if is_kit:
        if signal is not None:
            raise InvalidInput(f"{args.result} is a folder, judged as a scenario kit whose NAME.json "
                               "files define the runs: leave out --torque and --torque-file")
        verdicts = judge_kit(args.result, tolerance=args.tol, mapping=args.mapping, fmu_path=args.fmu)
        print(format_kit(verdicts))
        judged = {name: judgement for name, judgement in verdicts.items() if judgement is not None}
        figures = {name: args.plot / f"{name}.png" for name in judged} if args.plot else {}
    else:
        if signal is None:
            raise InvalidInput("judging a result file needs the run's torque: give --torque N.m or "
                               "--torque-file F.csv (or judge a scenario kit's folder)")
        verdicts = judge(args.result, signal, start_time=args.start_time, stop_time=args.stop_time,
                         step_size=args.step_size, ramp=args.ramp,
                         parameters=_parameters(args.assignments), theta0=args.theta0,
                         omega0=args.omega0, tolerance=args.tol, mapping=args.mapping,
                         fmu_path=args.fmu, max_steps=args.max_steps)
        print(format_judgement(verdicts))
        judged = {args.result.name: verdicts}
        figures = {args.result.name: args.plot} if args.plot else {}
    for title, path in figures.items():
        print(f"wrote {plot_judgement(judged[title], path, title)}")
    if args.json:
        print(f"wrote {write_json(verdicts, args.json)}")
    return 0 if all(judgement.passed for judgement in judged.values()) else 1


def cmd_scenarios(args) -> int:
    from .scenarios import write_scenarios

    for path in write_scenarios(args.output_dir, args.fmu, overwrite=args.overwrite):
        print(f"wrote {path}")
    return 0


# --- the parser: one function per command ---------------------------------------------------

def _add_build(commands) -> argparse.ArgumentParser:
    build = commands.add_parser("build", help="build the FMU (same as python build_fmu.py)",
                                description="Build the FMU from fmu_src/ and modelDescription.xml "
                                            "(a source checkout or the unpacked sdist).")
    build.add_argument("--output", type=_output_path, default=None,
                       help=f"where to write the FMU (default: {CHECKOUT_FMUS[2]}, or {CHECKOUT_FMUS[3]} "
                            "for FMI 3.0)")
    build.add_argument("--fmi-version", type=int, choices=FMI_VERSIONS, default=2,
                       help="FMI standard of the FMU (default: %(default)s)")
    build.add_argument("--platforms", type=_platforms, default=None,
                       help=f"comma-separated, among {', '.join(PLATFORMS)} (default: every one "
                            "whose compiler is installed; the others are skipped with a note)")
    build.add_argument("--linux-glibc", default=None, metavar="VERSION",
                       help="build the Linux binaries with zig (pip install ziglang) to load on this glibc "
                            "and every later one, such as 2.17, manylinux2014's (default: with gcc, for "
                            "this machine's glibc)")
    build.set_defaults(run=cmd_build)
    return build


def _add_cross_check(commands) -> argparse.ArgumentParser:
    cross_check = commands.add_parser(
        "cross-check", help="reference results in the FMI cross-check layout",
        description="Write fmus/2.0/cs/<platform>/pendulum_fmu/<version>/Pendulum/ (the FMU, "
                    "_in.csv, _ref.csv, _ref.opt, ReadMe.md) for a step-wise torque, one folder "
                    "per platform the FMU has a binary for.")
    cross_check.add_argument("--output-dir", type=_output_path, required=True,
                             help="the cross-check repository's root")
    _add_fmu_argument(cross_check)
    cross_check.set_defaults(run=cmd_cross_check)
    return cross_check


def _add_simulate(commands) -> argparse.ArgumentParser:
    simulate = commands.add_parser("simulate", help="simulate the FMU under a torque signal",
                                   description="Simulate the FMU through fmpy; the torque is held "
                                               "over each communication step unless --ramp.")
    _add_signal_arguments(simulate)
    simulate.add_argument("--ramp", action="store_true",
                          help="ramp the torque linearly over each step (input derivatives)")
    simulate.add_argument("--tolerance", type=_float, default=None,
                          help="relative tolerance of the FMU's integrator (default: 1e-10)")
    simulate.add_argument("--output", type=_output_path, help="write time,torque,theta,omega,alpha CSV")
    simulate.add_argument("--plot", type=_output_path, help="write a PNG of theta and omega")
    simulate.set_defaults(run=cmd_simulate)
    return simulate


def _add_compare(commands) -> argparse.ArgumentParser:
    compare = commands.add_parser("compare", help="run one torque signal through several tools",
                                  description="Run one torque signal through the FMU and OpenSim "
                                              "and judge each against the independent scipy "
                                              "reference, which reads the signal itself: write "
                                              "trajectories, a table of max and RMS differences "
                                              "(and of the torque each tool received against the "
                                              "signal) and a figure. Exits 1 when a tool differs "
                                              "by more than --tol or received another torque.")
    _add_signal_arguments(compare)
    compare.add_argument("--ramp", action="store_true",
                         help="ramp the torque along the CSV's piecewise-linear signal in every "
                              "tool that can (the FMU, the reference); OpenSim cannot and says so")
    compare.add_argument("--tools", default="fmu,reference,opensim",
                         help="comma-separated, each once: fmu, reference, opensim, mujoco, drake, "
                              "pybullet (NAME:default for the engine's own defaults), or "
                              "LABEL=path/to/Their.fmu for any FMI 2.0/3.0 FMU; the reference always "
                              "runs as the judge (default: %(default)s)")
    compare.add_argument("--map", dest="mapping", default=None, metavar="OURS=THEIRS[*FACTOR],...",
                         help="for LABEL=FMU tools: their variable names for torque, theta, omega, "
                              "alpha and the parameters, with a factor where they use other units, "
                              "e.g. torque=u,theta=phi*0.0174532925 (docs/engines.md)")
    compare.add_argument("--output-dir", type=_output_path, required=True,
                         help="folder for trajectories.csv, differences.csv and comparison.png")
    compare.add_argument("--tol", type=_float, default=1e-9,
                         help="largest allowed |dtheta| (rad) or |domega| (rad/s), positive and "
                              "finite (default: %(default)s)")
    compare.set_defaults(run=cmd_compare)
    return compare


def _add_sweep(commands) -> argparse.ArgumentParser:
    sweep = commands.add_parser("sweep", help="parameter study as a grid, on dask",
                                description="Run every combination of the given values on dask: a "
                                            "local cluster, or an existing scheduler.")
    sweep.add_argument("--torque", type=_float, nargs="+", required=True, help="torques in N.m")
    sweep.add_argument("--gravity", type=_float, nargs="+", default=[9.81],
                       help="gravities in m/s2 (default: 9.81)")
    sweep.add_argument("--set", dest="assignments", type=_assignment, action="append",
                       metavar="NAME=V1,V2", help="more values of a parameter or theta0/omega0")
    sweep.add_argument("--stop-time", type=_float, default=3.0,
                       help="end of every case in s (default: %(default)s)")
    sweep.add_argument("--step-size", type=_float, default=1e-3,
                       help="communication step in s (default: %(default)s)")
    sweep.add_argument("--output-dir", type=_output_location, required=True,
                       help="local folder or fsspec URL (s3://..., a shared file system) every "
                            "worker can write to: trajectories/ and cases/ (a file per chunk), "
                            "sweep.png")
    sweep.add_argument("--outputs", default="theta,omega,alpha",
                       help="outputs the trajectories keep, comma-separated, or none for only "
                            "the cases table (default: %(default)s)")
    sweep.add_argument("--output-interval", type=_float, default=None,
                       help="keep a point every so many s, a whole number of steps (default: "
                            "every step)")
    sweep.add_argument("--format", choices=("parquet", "csv"), default="parquet",
                       help="file format of the tables (default: %(default)s; csv for small studies)")
    again = sweep.add_mutually_exclusive_group()
    again.add_argument("--resume", action="store_true",
                       help="run only the chunks a previous run of the same study did not write")
    again.add_argument("--overwrite", action="store_true",
                       help="replace the study --output-dir holds, once the new one is whole "
                            "(without --resume or --overwrite, a folder holding a study is refused)")
    sweep.add_argument("--scheduler", help="address of a running dask.distributed scheduler")
    sweep.add_argument("--connect-timeout", type=_float, default=10.0,
                       help="seconds --scheduler has to answer dask's handshake, all told "
                            "(default: %(default)s)")
    sweep.add_argument("--workers", type=int, default=None, help="local cluster workers (default: 2)")
    sweep.add_argument("--max-cases", type=_positive_int, default=DEFAULT_MAX_CASES,
                       help=f"refuse studies of more cases than this (default: {DEFAULT_MAX_CASES:,})")
    _add_fmu_argument(sweep)
    sweep.set_defaults(run=cmd_sweep)
    return sweep


def _add_demo(commands) -> argparse.ArgumentParser:
    demo = commands.add_parser("demo", help="the OpenSim tutorial end to end",
                               description="Gravity off and on against the reference (and "
                                           "OpenSim when installed), the overlay and the "
                                           "parameter study; prints the error table and writes "
                                           "the figures.")
    demo.add_argument("--output-dir", type=_output_path, default=Path("demo"),
                      help="folder for the figures and tables (default: %(default)s)")
    demo.add_argument("--workers", type=int, default=None, help="local dask workers (default: 2)")
    demo.add_argument("--overwrite", action="store_true",
                      help="replace the outputs of a previous demo --output-dir holds (without it, "
                           "such a folder is refused)")
    demo.set_defaults(run=cmd_demo)
    return demo


def _add_judge(commands) -> argparse.ArgumentParser:
    judge = commands.add_parser(
        "judge", help="judge a result file from any tool, and name the mistake",
        description="Compare a result file from any tool (a CSV with time and theta, optionally "
                    "omega and alpha) with the independent reference at its own times: pass when "
                    "max |dtheta| <= --tol (exit 0), else fail (exit 1) with the mistake that "
                    "explains the difference (input one step late or early, interpolated, held, "
                    "time grid drift, state not restored, integration error, or unexplained). "
                    "Given a scenario kit's folder, judges every NAME_out.csv in it.")
    judge.add_argument("result", type=Path,
                       help="the result CSV, or a folder written by pendulum-fmu scenarios holding "
                            "NAME_out.csv files")
    _add_signal_arguments(judge, required=False)
    judge.add_argument("--start-time", type=_float, default=0.0,
                       help="start of the run in s (default: %(default)s)")
    judge.add_argument("--ramp", action="store_true",
                       help="the run ramped the torque along the CSV's line (input derivatives)")
    judge.add_argument("--tol", type=_float, default=None,
                       help="largest |dtheta| in rad that passes (default: 1e-9, or for a kit each "
                            "scenario's own)")
    judge.add_argument("--map", dest="mapping", default=None, metavar="QUANTITY=COLUMN[*FACTOR],...",
                       help="the result's column names for time, theta, omega and alpha, with a factor "
                            "to SI where it uses other units, e.g. theta=phi*0.0174532925")
    judge.add_argument("--json", type=_output_path, default=None,
                       help="write the verdict, diagnosis, max |dtheta|, worst time and every "
                            "candidate's residual (rad) as JSON")
    judge.add_argument("--plot", type=_output_path, default=None,
                       help="write a PNG of the torque, theta and |dtheta| (for a kit: a folder, one "
                            "NAME.png per scenario)")
    judge.set_defaults(run=cmd_judge)
    return judge


def _add_scenarios(commands) -> argparse.ArgumentParser:
    scenarios = commands.add_parser(
        "scenarios", help="write a kit of scenarios for testing a master with this FMU",
        description="Write the FMU (carrying the kit as FMI-LS-REF related files) and, per scenario, "
                    "its torque (NAME_in.csv), settings (NAME.json) and reference (NAME_ref.csv), "
                    "with a ReadMe.md: run each in your master, write NAME_out.csv beside it, then "
                    "pendulum-fmu judge FOLDER.")
    scenarios.add_argument("--output-dir", type=_output_path, required=True, help="the kit's folder")
    scenarios.add_argument("--overwrite", action="store_true",
                           help="replace the kit --output-dir holds, once the new one is whole; "
                                "results (NAME_out.csv) are kept (without it, a folder holding a "
                                "kit is refused)")
    _add_fmu_argument(scenarios)
    scenarios.set_defaults(run=cmd_scenarios)
    return scenarios


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="pendulum-fmu",
        description="A torque-driven pendulum as an FMI 2.0 (or 3.0) FMU: build it, "
                    "simulate it, and compare it with scipy and OpenSim.")
    parser.add_argument("--version", action="version", version=f"pendulum-fmu {__version__}")
    parser.add_argument("--debug", action="store_true", default=False,
                        help="show the Python traceback of an error instead of one line")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for add in (_add_build, _add_cross_check, _add_simulate, _add_compare, _add_sweep, _add_demo,
                _add_judge, _add_scenarios):
        # Also after the command's name; SUPPRESS keeps it from hiding one given before it.
        add(commands).add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                                   help="show the Python traceback of an error instead of one line")
    return parser


class _UntilTheReaderIsGone:
    """stdout that drops what is printed once its reader is gone (piped into `head`, which
    closed the pipe; a full /dev/full), so that the command still writes its files: what it
    prints only reports them."""

    def __init__(self, stream):
        self._stream = stream
        self._gone = False

    def _guarded(self, write, *arguments):
        if self._gone:
            return None
        try:
            return write(*arguments)
        except OSError as error:
            if not isinstance(error, BrokenPipeError) and error.errno != errno.ENOSPC:
                raise
            self._gone = True
            # What is still buffered goes nowhere too, also when Python flushes it at exit.
            with contextlib.suppress(OSError, ValueError):
                os.dup2(os.open(os.devnull, os.O_WRONLY), self._stream.fileno())
            return None

    def write(self, text: str) -> int:
        self._guarded(self._stream.write, text)
        return len(text)

    def flush(self) -> None:
        self._guarded(self._stream.flush)

    def __getattr__(self, name):
        return getattr(self._stream, name)


def main(argv=None) -> int:
    """Run one command line; returns the exit status (0, 1 when a comparison or a sweep found
    what it reports, 2 for a user's error, 3 for a bug of ours, 128 + n on signal n)."""
    args = build_parser().parse_args(argv)
    command = f"pendulum-fmu {args.command}"
    shown = warnings.showwarning

    def one_line(message, category, *where, **more):
        if issubclass(category, PlatformSkipped):
            print(f"{command}: {message}", file=sys.stderr)
        else:
            shown(message, category, *where, **more)

    # Signal handlers can only be set from the main thread; elsewhere Ctrl-C stays Python's.
    previous = stop_on_signals() if threading.current_thread() is threading.main_thread() else {}
    stdout, sys.stdout = sys.stdout, _UntilTheReaderIsGone(sys.stdout)
    try:
        with warnings.catch_warnings():
            warnings.showwarning = one_line
            return args.run(args)
    except (Stopped, KeyboardInterrupt) as stopped:
        if args.debug:
            raise
        number = getattr(stopped, "signal_number", signal.SIGINT)
        print(f"{command}: {STOPPING_SIGNALS[number]}; no output file was left half written", file=sys.stderr)
        return 128 + number
    except PendulumFmuError as error:
        if args.debug:
            raise
        print(f"{command}: error: {error}", file=sys.stderr)
        return 2
    except Exception as error:  # a bug of ours: still one line, the traceback on request
        if args.debug:
            raise
        print(f"{command}: internal error: {type(error).__name__}: {error} (run again with --debug "
              "for the traceback, and report it)", file=sys.stderr)
        return 3
    finally:
        sys.stdout = stdout
        if previous:
            restore_signals(previous)
