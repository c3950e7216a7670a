"""The signals that stop the program, SIGINT and SIGTERM, and what each does.

While the program starts (_entry.py) a signal ends it at once, since nothing is being written
yet. While a command runs (cli.main) it raises Stopped where the program is, so that every file
being written is cleaned up on the way out, and cli.main prints one line. A few steps that must
not be cut in two (moving a study into place) hold the signals off until they are done.
"""

import contextlib
import signal
import sys
import threading
import time
from collections.abc import Callable
from typing import Any

# The signals that stop the program, and the word its one line says for each.
STOPPING_SIGNALS = {signal.SIGINT: "interrupted", signal.SIGTERM: "terminated"}


class Stopped(BaseException):
    """SIGINT or SIGTERM, raised where the program is, so that every file being written is
    cleaned up on the way out (a BaseException, so no `except Exception` swallows it).
    """

    def __init__(self, signal_number: int):
        super().__init__(signal_number)
        self.signal_number = signal_number


def stop_on_signals() -> dict:
    """Make SIGINT and SIGTERM raise Stopped once; further ones are ignored so the cleanup that
    follows (closing the cluster, removing temporaries) runs to its end. Returns the old handlers.

    Python runs a signal's handler wherever the main thread is. Where that is code whose
    exceptions Python cannot pass on, a garbage collector's callback (dask's client runs one on
    every collection) or a __del__, it prints Stopped as an ignored exception and goes on, so the
    program would finish as if no signal had come. sys.unraisablehook catches that Stopped,
    silently, and the signal is sent again, to land once the main thread is back in the command.
    """

    def stop(number, frame):
        for name in STOPPING_SIGNALS:
            signal.signal(name, signal.SIG_IGN)
        raise Stopped(number)

    # signal.signal below works in the main thread only, so this is the thread to signal again.
    sys.unraisablehook = _DeliverAgain(sys.unraisablehook, stop, threading.get_ident())
    return {name: signal.signal(name, stop) for name in STOPPING_SIGNALS}


class _DeliverAgain:
    """sys.unraisablehook while a command runs: a Stopped that Python could only print is
    signalled again to the main thread; anything else goes to the hook this one replaced.
    """

    def __init__(self, replaced: Callable[[Any], object], stop: Callable[[int, Any], None], main_thread: int):
        self.replaced, self.stop, self.main_thread = replaced, stop, main_thread

    def __call__(self, unraisable: Any) -> None:
        if not isinstance(unraisable.exc_value, Stopped):
            self.replaced(unraisable)
            return
        number = unraisable.exc_value.signal_number
        signal.signal(number, self.stop)
        threading.Thread(target=_signal_main_thread, args=(self.main_thread, number), daemon=True).start()


def restore_signals(previous: dict) -> None:
    """Undo stop_on_signals: the handlers it returned, and Python's own hook for ignored
    exceptions.
    """
    for number, handler in previous.items():
        signal.signal(number, handler)
    hook = sys.unraisablehook
    sys.unraisablehook = hook.replaced if isinstance(hook, _DeliverAgain) else hook


def _signal_main_thread(main_thread: int, number: int) -> None:
    # Later than the hook's return, so that the handler does not run inside the hook itself; to
    # the main thread where the platform can aim a signal, so that it also cuts a wait there short.
    time.sleep(_REDELIVERY_DELAY)
    if hasattr(signal, "pthread_kill"):
        signal.pthread_kill(main_thread, number)
    else:
        signal.raise_signal(number)


_REDELIVERY_DELAY = 0.05  # s


@contextlib.contextmanager
def signals_deferred():
    """Hold SIGINT and SIGTERM off until the block ends, then let the handler they had act on the
    first that came. Python runs signal handlers in the main thread only, so elsewhere nothing
    can cut the block and nothing needs holding.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    came = []
    previous = {number: signal.signal(number, lambda number, frame: came.append(number)) for number in STOPPING_SIGNALS}
    try:
        yield
    finally:
        for number, handler in previous.items():
            # None: a handler set outside Python, which cannot be set back from here.
            signal.signal(number, signal.SIG_DFL if handler is None else handler)
        if came:
            signal.raise_signal(came[0])
