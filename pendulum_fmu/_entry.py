"""The pendulum-fmu program.

Signals are handled from its first line, before the imports that take a noticeable time (numpy,
fmpy, dask), so that a Ctrl-C or SIGTERM at any moment ends in one line: while starting, here;
while a command runs, by cli.main, which cleans up what the command was writing.
"""

import os
import signal
import sys

from ._stop_signals import STOPPING_SIGNALS


def _while_starting(number, frame):
    # No command has started, so nothing is being written: leave at once.
    os.write(2, f"pendulum-fmu: {STOPPING_SIGNALS[number]} while starting; nothing was written\n".encode())
    os._exit(128 + number)


def run() -> None:
    """The pendulum-fmu program: the command line, with its stopping signals handled from the start."""
    for number in STOPPING_SIGNALS:
        signal.signal(number, _while_starting)
    from .cli import main  # sets the command's own handlers while it runs

    code = main()
    # Every file is in place: a signal while the interpreter shuts down changes nothing.
    for number in STOPPING_SIGNALS:
        signal.signal(number, signal.SIG_IGN)
    sys.exit(code)
