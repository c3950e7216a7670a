"""stdout for a command whose reader may leave before it ends."""

from __future__ import annotations

import contextlib
import errno
import os


class UntilTheReaderIsGone:
    """stdout that drops what is printed once its reader is gone.

    The reader is gone when the output was piped into `head`, which closed the pipe, or into a
    full /dev/full; the command still writes its files: what it prints only reports them.
    """

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
        """Write text, or nothing once the reader is gone; the length of text either way."""
        self._guarded(self._stream.write, text)
        return len(text)

    def flush(self) -> None:
        """Flush, or nothing once the reader is gone."""
        self._guarded(self._stream.flush)

    def __getattr__(self, name):
        return getattr(self._stream, name)
