"""The signals that stop the program, SIGINT and SIGTERM, and what each does.

While the program starts (entry.py) a signal ends it at once, since nothing is being written
yet. While a command runs (cli.main) it raises Stopped where the program is, so that every file
being written is cleaned up on the way out, and cli.main prints one line.
"""

import signal

# The signals that stop the program, and the word its one line says for each.
STOPPING_SIGNALS = {signal.SIGINT: "interrupted", signal.SIGTERM: "terminated"}


class Stopped(BaseException):
    """SIGINT or SIGTERM, raised where the program is, so that every file being written is
    cleaned up on the way out (a BaseException, so no `except Exception` swallows it)."""

    def __init__(self, signal_number: int):
        super().__init__(signal_number)
        self.signal_number = signal_number


def stop_on_signals() -> dict:
    """Make SIGINT and SIGTERM raise Stopped once; further ones are ignored so the cleanup that
    follows (closing the cluster, removing temporaries) runs to its end. Returns the old handlers."""

    def stop(number, frame):
        for name in STOPPING_SIGNALS:
            signal.signal(name, signal.SIG_IGN)
        raise Stopped(number)

    return {name: signal.signal(name, stop) for name in STOPPING_SIGNALS}
