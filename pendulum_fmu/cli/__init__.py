"""pendulum-fmu: build, simulate and compare the torque-driven pendulum FMU.

One module per command, each with its ``add_parser(commands)``, which declares the command's
options, and its ``run(args)``, which turns them into one call of the package's API and prints
what came back. A command imports what it runs only when it runs, so that ``pendulum-fmu
simulate`` loads neither the sweep nor matplotlib. A user's error (a PendulumFmuError) is one line
and exit 2; anything else is a bug of ours, one line too, with the traceback on --debug.

May import: every folder of the package, the basics and the top's own names (__version__): it is
the top floor, which nothing of the package imports but the program (_entry).
"""

from __future__ import annotations

import argparse
import signal
import sys
import threading
import warnings

from .. import __version__
from .._checkout import is_source_checkout
from .._errors import Clipped, NotComputed, PendulumFmuError, PlatformSkipped, Skipped, UnencryptedScheduler
from .._stop_signals import STOPPING_SIGNALS, Stopped, restore_signals, stop_on_signals
from . import build, compare, cross_check, demo, export, export_ssp, judge, scenarios, simulate, sweep, verify
from ._stdout import UntilTheReaderIsGone

__all__ = ["build_parser", "main"]

# In the order `pendulum-fmu --help` lists them. build is the developer's (python build_fmu.py),
# listed only in a checkout, whose build tool it runs; users take the FMU with export.
COMMANDS = (build, export, cross_check, simulate, compare, sweep, demo, judge, scenarios, export_ssp, verify)


def build_parser() -> argparse.ArgumentParser:
    """The parser of the whole command line: every command's options, each with its help.

    Returns
    -------
    argparse.ArgumentParser
        Its ``parse_args`` gives the arguments with ``run``, the chosen command's function.

    Examples
    --------
    >>> args = build_parser().parse_args(["simulate", "--torque", "20"])
    >>> args.command, args.torque
    ('simulate', 20.0)
    """
    parser = argparse.ArgumentParser(
        prog="pendulum-fmu",
        description="A torque-driven pendulum as an FMI 2.0 (or 3.0) FMU: build it, "
        "simulate it, and compare it with an independent reference and OpenSim.",
    )
    parser.add_argument("--version", action="version", version=f"pendulum-fmu {__version__}")
    parser.add_argument(
        "--debug", action="store_true", default=False, help="show the Python traceback of an error instead of one line"
    )
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for command in COMMANDS:
        if command is build and not is_source_checkout():
            continue
        # Also after the command's name; SUPPRESS keeps it from hiding one given before it.
        command.add_parser(commands).add_argument(
            "--debug",
            action="store_true",
            default=argparse.SUPPRESS,
            help="show the Python traceback of an error instead of one line",
        )
    return parser


def _on_one_line(text) -> str:
    """The text on one line: a line end or another control character in it (a file name's) escaped."""
    return "".join(c if c.isprintable() or c == "\t" else repr(c)[1:-1] for c in str(text))


def main(argv: list[str] | None = None) -> int:
    """Run one command line.

    Parameters
    ----------
    argv : list of str, optional
        The arguments after the program's name (default: ``sys.argv[1:]``).

    Returns
    -------
    int
        The exit status: 0, 1 when a comparison, a judgement or a sweep found what it reports,
        2 for a user's error, 3 for a bug of ours, 128 + n on signal n.

    Raises
    ------
    SystemExit
        From argparse, for ``--help``, ``--version`` or arguments it cannot parse (status 2).

    Examples
    --------
    >>> main(["simulate", "--torque", "20", "--stop-time", "0.01"])  # doctest: +SKIP
    10 steps to t = 0.01 s: theta = ...
    0
    """
    args = build_parser().parse_args(argv)
    command = f"pendulum-fmu {args.command}"
    shown = warnings.showwarning

    def one_line(message, category, *where, **more):
        if issubclass(category, (Clipped, NotComputed, PlatformSkipped, Skipped, UnencryptedScheduler)):
            print(f"{command}: {_on_one_line(message)}", file=sys.stderr)
        else:
            shown(message, category, *where, **more)

    # Signal handlers can only be set from the main thread; elsewhere Ctrl-C stays Python's.
    previous = stop_on_signals() if threading.current_thread() is threading.main_thread() else {}
    stdout, sys.stdout = sys.stdout, UntilTheReaderIsGone(sys.stdout)
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
        print(f"{command}: error: {_on_one_line(error)}", file=sys.stderr)
        return 2
    except Exception as error:  # a bug of ours: still one line, the traceback on request
        if args.debug:
            raise
        print(
            f"{command}: internal error: {type(error).__name__}: {_on_one_line(error)} (run again with --debug "
            "for the traceback, and report it)",
            file=sys.stderr,
        )
        return 3
    finally:
        sys.stdout = stdout
        if previous:
            restore_signals(previous)
