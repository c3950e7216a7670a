"""The points a figure of a long run draws: a few thousand of its millions, every extreme kept."""

from __future__ import annotations

import numpy as np


def drawn_points(time: np.ndarray, *series: np.ndarray, columns: int = 2000) -> np.ndarray:
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
    span = float(time[-1] - time[0])
    column = np.minimum(((time - time[0]) * (columns / span)).astype(np.int64), columns - 1)
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

    The spans of time start where the run does, each `width` long; when the run outgrows
    2 * columns of them, width doubles, and each new span is two old ones, whose extremes the
    rows kept already hold. So between columns and 2 * columns spans keep their first, last,
    least and greatest rows, exactly those drawn_points would keep for such spans; a short run
    is kept whole, as drawn_points keeps it.

    Parameters
    ----------
    names : sequence of str
        The fields drawn against time.
    columns : int, optional
        As drawn_points's.

    Examples
    --------
    >>> import numpy as np
    >>> rows = np.zeros(1_000_001, dtype=[("time", "f8"), ("theta", "f8")])
    >>> rows["time"] = np.linspace(0.0, 1.0, len(rows)); rows["theta"] = np.sin(40 * rows["time"])
    >>> drawn = DrawnRows(["theta"], columns=100)
    >>> for block in np.array_split(rows, 7):
    ...     drawn.add(block)
    >>> len(drawn.rows) <= 800, bool(drawn.rows["theta"].max() == rows["theta"].max())
    (True, True)
    """

    def __init__(self, names, columns: int = 2000):
        self.names, self.columns = tuple(names), columns
        self.rows: np.ndarray | None = None
        self.width = 0.0  # s; 0 while the run is short enough to keep whole

    def add(self, block: np.ndarray) -> None:
        """Take the next rows of the run in."""
        rows = block.copy() if self.rows is None else np.concatenate([self.rows, block])
        if len(rows) > 4 * self.columns * (len(self.names) + 1):
            time = rows["time"]
            if not self.width:
                self.width = float(time[-1] - time[0]) / self.columns or 1.0
                self.origin = float(time[0])
            column = np.floor((time - self.origin) / self.width).astype(np.int64)
            while column[-1] >= 2 * self.columns:
                # A power of two: column // 2 is exactly the column of each time at twice the width.
                self.width, column = 2 * self.width, column // 2
            rows = rows[_extremes(column, [rows[name] for name in self.names])]
        self.rows = rows
