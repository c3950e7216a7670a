"""The points a figure of a long run draws: a few thousand of its millions, every extreme kept."""

from __future__ import annotations

import numpy as np


def drawn_points(
    time: np.ndarray, *series: np.ndarray, columns: int = 2000, span: tuple[float, float] | None = None
) -> np.ndarray:
    """The indices of the points a figure of a long run draws: in each of `columns` equal spans
    of time (more than a figure's columns of pixels), the first and last point and where each
    series is least and greatest, so that no extreme is lost; every point of a short run.

    Parameters
    ----------
    time : numpy.ndarray
        The times, increasing.
    *series : numpy.ndarray
        The values drawn against them.
    columns : int, optional
        The spans of time.
    span : (float, float), optional
        The first span's start and the last one's end (s; default: the first and last time): a
        stretch of a longer run, whose points are drawn again with the others, takes the run's
        spans, so that an extreme kept of each stretch is the extreme of its span.

    Returns
    -------
    numpy.ndarray
        Increasing indices, at most 2 + 2 * len(series) per span.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.linspace(0.0, 1.0, 1_000_001)
    >>> kept = drawn_points(t, np.sin(40 * t), columns=100)
    >>> len(kept) <= 400, bool(np.sin(40 * t)[kept].max() == np.sin(40 * t).max())
    (True, True)
    """
    count = len(time)
    if count <= 2 * columns * (len(series) + 1):
        return np.arange(count)
    start, stop = (float(time[0]), float(time[-1])) if span is None else span
    width = (stop - start) or 1.0
    column = np.clip(((time - start) * (columns / width)).astype(np.int64), 0, columns - 1)
    starts = np.flatnonzero(np.r_[True, np.diff(column) != 0])
    sizes = np.diff(np.r_[starts, count])
    kept = [starts, starts + sizes - 1]
    for values in series:
        for extreme in (np.minimum, np.maximum):
            reached = np.flatnonzero(values == np.repeat(extreme.reduceat(values, starts), sizes))
            kept.append(reached[np.r_[True, np.diff(column[reached]) != 0]])  # one per span
    return np.unique(np.concatenate(kept))
