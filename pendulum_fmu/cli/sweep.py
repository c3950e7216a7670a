"""pendulum-fmu sweep: a parameter study as a grid, on dask."""

from __future__ import annotations

import argparse
import signal
import sys
from pathlib import Path

from .._errors import InvalidInput
from .._stop_signals import STOPPING_SIGNALS, Stopped
from ..signals._time_grid import BREAK_EVEN_STEPS, DEFAULT_MAX_CASES, RUN_IN
from ._arguments import add_fmu_argument, assignment, float_number, output_location, positive_int


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


def add_parser(commands) -> argparse.ArgumentParser:
    """Declare `sweep` and its options, each with its help, among the parser's commands."""
    sweep = commands.add_parser(
        "sweep",
        help="parameter study as a grid, on dask",
        description="Run every combination of the given values on dask: a local cluster, or an existing scheduler.",
    )
    sweep.add_argument("--torque", type=float_number, nargs="+", required=True, help="torques in N.m")
    sweep.add_argument(
        "--gravity", type=float_number, nargs="+", default=[9.81], help="gravities in m/s2 (default: 9.81)"
    )
    sweep.add_argument(
        "--set",
        dest="assignments",
        type=assignment,
        action="append",
        metavar="NAME=V1,V2",
        help="more values of a parameter or theta0/omega0",
    )
    sweep.add_argument(
        "--stop-time", type=float_number, default=3.0, help="end of every case in s (default: %(default)s)"
    )
    sweep.add_argument(
        "--step-size", type=float_number, default=1e-3, help="communication step in s (default: %(default)s)"
    )
    sweep.add_argument(
        "--output-dir",
        type=output_location,
        required=True,
        help="local folder or fsspec URL (s3://..., a shared file system) every "
        "worker can write to: trajectories/ and cases/ (a file per chunk), "
        "sweep.png",
    )
    sweep.add_argument(
        "--outputs",
        help="outputs of the FMU the trajectories keep, comma-separated, or none for only the cases table "
        "(default: all of them; the default FMU's are theta,omega,alpha)",
    )
    sweep.add_argument(
        "--output-interval",
        type=float_number,
        default=None,
        help="keep a point every so many s, a whole number of steps (default: every step)",
    )
    sweep.add_argument(
        "--format",
        choices=("parquet", "csv"),
        default="parquet",
        help="file format of the tables (default: %(default)s; csv for small studies)",
    )
    sweep.add_argument(
        "--no-figure",
        dest="figure",
        action="store_false",
        help="write no sweep.png (a small study then takes about half as long)",
    )
    again = sweep.add_mutually_exclusive_group()
    again.add_argument(
        "--resume", action="store_true", help="run only the chunks a previous run of the same study did not write"
    )
    again.add_argument(
        "--overwrite",
        action="store_true",
        help="replace the study --output-dir holds, once the new one is whole "
        "(without --resume or --overwrite, a folder holding a study is refused)",
    )
    _add_cluster_arguments(sweep)
    sweep.add_argument(
        "--max-cases",
        type=positive_int,
        default=DEFAULT_MAX_CASES,
        help=f"refuse studies of more cases than this (default: {DEFAULT_MAX_CASES:,})",
    )
    add_fmu_argument(sweep)
    sweep.set_defaults(run=run)
    return sweep


def _add_cluster_arguments(sweep: argparse.ArgumentParser) -> None:
    """The options that choose the cluster and how the client reaches it (TLS's as dask names them)."""
    sweep.add_argument("--scheduler", help="address of a running dask.distributed scheduler (tls://... to secure it)")
    sweep.add_argument(
        "--connect-timeout",
        type=float_number,
        default=10.0,
        help="seconds --scheduler has to answer dask's handshake, all told (default: %(default)s)",
    )
    for option, what in (
        ("--tls-ca-file", "the CA certificate that signed the scheduler's and workers' certificates"),
        ("--tls-cert", "the client's certificate, signed by that CA (it may hold the key too)"),
        ("--tls-key", "the client's private key"),
    ):
        sweep.add_argument(
            option,
            type=output_location,
            metavar="PEM",
            help=f"{what}, for --scheduler tls://... (default: dask's configuration, distributed.comm.tls.*)",
        )
    sweep.add_argument(
        "--workers", type=int, default=None, help="local cluster workers (default: 2; given, a cluster runs the study)"
    )
    sweep.add_argument(
        "--run-in",
        choices=RUN_IN,
        default="auto",
        help="where the study runs: auto (this process below about "
        f"{BREAK_EVEN_STEPS / 1e6:g} million steps in all, without --scheduler or --workers; else dask), "
        "process, or cluster (a local one without --scheduler) (default: %(default)s)",
    )


def _security(args):
    """The client's security from the --tls-* options; None (dask's configuration's) without them."""
    from ..sweep import tls_files

    if not (args.tls_ca_file or args.tls_cert or args.tls_key):
        return None
    if args.scheduler is None:
        raise InvalidInput(
            "--tls-ca-file, --tls-cert and --tls-key are for --scheduler tls://...; the local "
            "cluster makes certificates of its own"
        )
    if not (args.tls_ca_file and args.tls_cert):
        raise InvalidInput(
            "--tls-ca-file and --tls-cert go together (with --tls-key where the certificate's file "
            "does not hold the key)"
        )
    return tls_files(args.tls_ca_file, args.tls_cert, args.tls_key)


def run(args) -> int:
    """Run `pendulum-fmu sweep` with the parsed arguments; returns the exit status."""
    from ..sweep import Study, run_sweep, sweep_grid

    # Without --outputs, Study's default: all of its FMU's outputs.
    chosen = {} if args.outputs is None else {"outputs": _sweep_outputs(args.outputs)}
    study = Study(
        sweep_grid(args.torque, args.gravity, _sweep_values(args.assignments)),
        stop_time=args.stop_time,
        step_size=args.step_size,
        **chosen,
        output_interval=args.output_interval,
        format=args.format,
        fmu_path=args.fmu,
    )
    try:
        result = run_sweep(
            study,
            output_dir=args.output_dir,
            resume=args.resume,
            overwrite=args.overwrite,
            scheduler=args.scheduler,
            workers=args.workers,
            connect_timeout=args.connect_timeout,
            max_cases=args.max_cases,
            security=_security(args),
            run_in=args.run_in,
            figure=args.figure,
        )
    except Stopped as stopped:
        what = STOPPING_SIGNALS[signal.Signals(stopped.signal_number)]
        if args.overwrite:
            print(
                f"pendulum-fmu sweep: {what}; {args.output_dir} holds what it held before (the "
                "new study was not finished and is not kept): run the same command again to "
                "start over",
                file=sys.stderr,
            )
        elif "://" not in args.output_dir and not any(Path(args.output_dir).glob("*")):
            print(
                f"pendulum-fmu sweep: {what} before anything was written: run the same command again to start",
                file=sys.stderr,
            )
        else:
            print(
                f"pendulum-fmu sweep: {what}; the chunks that finished are kept in "
                f"{args.output_dir}: run the same command with --resume to run the rest",
                file=sys.stderr,
            )
        return 128 + stopped.signal_number
    resumed = result.chunks_run < result.chunks
    print(
        f"{result.cases} cases in {result.seconds:.1f} s"
        + (
            f" ({result.chunks_run} of {result.chunks} chunks run; the others were written by an earlier run)"
            if resumed
            else ""
        )
    )
    for path in (result.trajectories, result.cases_table, result.figure):
        if path is not None:  # no trajectories with --outputs none, no figure with --no-figure
            print(f"wrote {path}")
    if result.failed:
        # The other cases ran and are written; a script still learns that some did not.
        print(
            f"pendulum-fmu sweep: {result.failed} of {result.cases} cases failed: their "
            "status and message are in the cases table",
            file=sys.stderr,
        )
        return 1
    return 0
