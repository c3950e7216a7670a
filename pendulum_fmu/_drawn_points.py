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
    return _extremes(column, series)


def _extremes(column: np.ndarray, series) -> np.ndarray:
    """The indices of the first and last point of each run of equal, increasing column numbers,
    and of where each series is least and greatest in it.
    """
    count = len(column)
    starts = np.flatnonzero(np.r_[True, np.diff(column) != 0])
    sizes = np.diff(np.r_[starts, count])
    kept = [starts, starts + sizes - 1]
    for values in series:
        for extreme in (np.minimum, np.maximum):
            reached = np.flatnonzero(values == np.repeat(extreme.reduceat(values, starts), sizes))
            kept.append(reached[np.r_[True, np.diff(column[reached]) != 0]])  # one per span
    return np.unique(np.concatenate(kept))


class DrawnRows:
    """drawn_points of a run that comes a block of rows at a time, too long to hold: the rows
    kept, few whatever the run's length, with every extreme of theirs.

    Each block keeps the rows drawn_points keeps of it in the run's columns of time (span: the
    run's first and last time, known before it runs); where those outgrow twice what one pass of
    drawn_points keeps, they are thinned by drawn_points again. An extreme of a column is an
    extreme of the block that holds it, so every column keeps its first, last, least and greatest
    rows, exactly those drawn_points keeps of the whole run; a short run is kept whole.

    Parameters
    ----------
    names : sequence of str
        The fields whose extremes are kept; the block's other fields come with their rows.
    span : (float, float)
        The run's first and last time (s).
    columns : int, optional
        As drawn_points's.

    Examples
    --------
    >>> import numpy as np
    >>> rows = np.zeros(1_000_001, dtype=[("time", "f8"), ("theta", "f8")])
    >>> rows["time"] = np.linspace(0.0, 1.0, len(rows)); rows["theta"] = np.sin(40 * rows["time"])
    >>> drawn = DrawnRows(["theta"], (0.0, 1.0), columns=100)
    >>> for block in np.array_split(rows, 7):
    ...     drawn.add(block)
    >>> len(drawn.rows) <= 400, bool(drawn.rows["theta"].max() == rows["theta"].max())
    (True, True)
    """

    def __init__(self, names, span: tuple[float, float], columns: int = 2000):
        self.names, self.span, self.columns = tuple(names), span, columns
        self._parts: list[np.ndarray] = []
        self._count = 0

    def _thinned(self, rows: np.ndarray) -> np.ndarray:
        series = [rows[name] for name in self.names]
        return rows[drawn_points(rows["time"], *series, columns=self.columns, span=self.span)]

    def add(self, block: np.ndarray) -> None:
        """Take the next rows of the run in."""
        kept = self._thinned(block)
        self._parts.append(kept)
        self._count += len(kept)
        if self._count > 4 * self.columns * (len(self.names) + 1):
            self._parts = [self.rows]
            self._count = len(self._parts[0])

    @property
    def rows(self) -> np.ndarray:
        """The rows kept so far (a structured array of the blocks' fields)."""
        if not self._parts:
            return np.empty(0)
        return self._thinned(np.concatenate(self._parts) if len(self._parts) > 1 else self._parts[0])
