"""The progress bar of long work (a sweep's cases, the reference's simulated time), on stderr.

On a terminal a tqdm bar redrawn in place; elsewhere (a log) a plain line every few seconds, and
the last count, from the fifth second on, so that work shorter than that writes nothing.
"""

from __future__ import annotations

import sys

# Off a terminal: a line this often (s), from this long after the start on.
LOG_INTERVAL = 5.0


class _Lines:
    """tqdm's output for a log: each redraw a line of its own, where a terminal's is redrawn in
    place (tqdm starts it with a carriage return).
    """

    def __init__(self, stream):
        self.stream = stream

    def write(self, text: str) -> None:
        text = text.strip("\r\n ")
        if text:
            self.stream.write(text + "\n")

    def flush(self) -> None:
        self.stream.flush()


def progress_bar(label: str, counts: str, total: float, done: float = 0, enabled: bool = True, postfix: str = ""):
    """A tqdm bar on stderr, `done` of `total` already.

    Parameters
    ----------
    label : str
        What progresses, heading the line: ``sweep``, ``reference``.
    counts : str
        tqdm's format of the counts after the bar, e.g. ``{n_fmt}/{total_fmt} cases{postfix}``.
    total, done : float
        The whole, and how much of it is done before the bar starts.
    enabled : bool, optional
        False: a bar that shows nothing.
    postfix : str, optional
        The bar's first postfix (set_postfix_str changes it).

    Returns
    -------
    tqdm.tqdm
        The bar; close it (a ``with`` block).
    """
    from tqdm import tqdm

    # miniters=1: every update counts and only the interval thins them out, so tqdm's monitor
    # thread never redraws a bar on its own.
    if sys.stderr.isatty():
        return tqdm(
            total=total,
            initial=done,
            disable=not enabled,
            file=sys.stderr,
            miniters=1,
            mininterval=0.2,
            ascii=" #",
            postfix=postfix,
            bar_format=f"{label} [{{bar:30}}] {counts}",
        )
    return tqdm(
        total=total,
        initial=done,
        disable=not enabled,
        file=_Lines(sys.stderr),
        miniters=1,
        mininterval=LOG_INTERVAL,
        delay=LOG_INTERVAL,
        leave=False,
        postfix=postfix,
        bar_format=f"{label}: {counts}",
    )
