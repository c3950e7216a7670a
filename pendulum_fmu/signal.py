"""Torque signals and the step-wise schedule a master feeds the FMU.

A signal is a constant, a callable of time, or a CSV file in fmpy's convention: columns
``time,torque``, linear between rows, jumping where a time repeats. A schedule is what one
simulation applies: communication points ``time[0..N]`` and for each step k the torque at its
start, ``torque[k]``, and its rate ``torque_rate[k]`` (zero when the torque is held).
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Union

import numpy as np

TorqueSignal = Union[float, int, Callable[[float], float], str, Path, "TorqueTable"]

# Communication points closer than this (relative to the step) are one point.
_MERGE_FRACTION = 1e-9


class TorqueFileError(ValueError):
    """A torque CSV that cannot be read; the message names the file, row and problem."""


@dataclass(frozen=True)
class TorqueTable:
    """Rows of a torque CSV: piecewise linear, with a jump where a time repeats."""

    time: np.ndarray
    torque: np.ndarray

    def value_after(self, t: float) -> float:
        """The torque just after t: at a jump, the value after it."""
        return self._value(t, "right")

    def value_before(self, t: float) -> float:
        """The torque just before t: at a jump, the value before it."""
        return self._value(t, "left")

    def _value(self, t: float, side: str) -> float:
        i = np.searchsorted(self.time, t, side=side)
        if i == 0:
            return float(self.torque[0])
        if i == len(self.time):
            return float(self.torque[-1])
        t0, t1 = self.time[i - 1], self.time[i]
        u0, u1 = self.torque[i - 1], self.torque[i]
        return float(u0 + (u1 - u0) * (t - t0) / (t1 - t0))

    def jumps(self) -> np.ndarray:
        """Times where the torque jumps (a repeated time row)."""
        return self.time[1:][np.diff(self.time) == 0]


@dataclass(frozen=True)
class TorqueSchedule:
    time: np.ndarray
    torque: np.ndarray
    torque_rate: np.ndarray

    @property
    def step_size(self) -> np.ndarray:
        return np.diff(self.time)


def read_torque_csv(path: str | Path) -> TorqueTable:
    """Read a ``time,torque`` CSV; a bad file raises TorqueFileError naming file, row and problem."""
    path = Path(path)
    try:
        with open(path, newline="") as file:
            rows = list(csv.reader(file))
    except OSError as error:
        raise TorqueFileError(f"{path}: cannot read: {error.strerror}") from None
    if not rows:
        raise TorqueFileError(f"{path}: the file is empty; expected a header 'time,torque'")
    header = [name.strip() for name in rows[0]]
    for column in ("time", "torque"):
        if column not in header:
            raise TorqueFileError(f"{path}:1: missing column {column!r} (header is {','.join(header)})")
    time_col, torque_col = header.index("time"), header.index("torque")
    times, torques = [], []
    for number, row in enumerate(rows[1:], start=2):
        if not any(cell.strip() for cell in row):
            continue
        values = []
        for column, name in ((time_col, "time"), (torque_col, "torque")):
            cell = row[column].strip() if column < len(row) else ""
            try:
                value = float(cell)
            except ValueError:
                raise TorqueFileError(f"{path}:{number}: {name} {cell!r} is not a number") from None
            if not math.isfinite(value):
                raise TorqueFileError(f"{path}:{number}: {name} is {cell}; values must be finite")
            values.append(value)
        if times and values[0] < times[-1]:
            raise TorqueFileError(
                f"{path}:{number}: time {values[0]:g} goes backwards (previous row: {times[-1]:g})")
        if len(times) >= 2 and values[0] == times[-1] == times[-2]:
            raise TorqueFileError(f"{path}:{number}: time {values[0]:g} appears three times; a step "
                                  "is two rows with the same time")
        times.append(values[0])
        torques.append(values[1])
    if not times:
        raise TorqueFileError(f"{path}: no data rows after the header")
    return TorqueTable(np.array(times), np.array(torques))


def write_torque_csv(path: str | Path, schedule: TorqueSchedule) -> Path:
    """Write a schedule in fmpy's convention: a row where each run of equal steps starts and
    ends, so a held torque reads as steps and a ramp as a line."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    end = schedule.torque + schedule.torque_rate * schedule.step_size
    points = []
    for t0, t1, u0, u1 in zip(schedule.time[:-1], schedule.time[1:], schedule.torque, end):
        if not points or points[-1] != (t0, u0):
            points.append((t0, u0))
        points.append((t1, u1))
    # A point inside a run of constant torque adds nothing.
    rows = [p for i, p in enumerate(points)
            if i in (0, len(points) - 1) or not points[i - 1][1] == p[1] == points[i + 1][1]]
    with open(path, "w", newline="") as file:
        writer = csv.writer(file)
        writer.writerow(["time", "torque"])
        writer.writerows((repr(float(t)), repr(float(u))) for t, u in rows)
    return path


def communication_points(start_time: float, stop_time: float, step_size: float,
                         extra: np.ndarray | None = None) -> np.ndarray:
    """start, start+h, ... up to stop (a shorter last step if needed), plus the extra points."""
    if not (step_size > 0 and math.isfinite(step_size)):
        raise ValueError(f"step size {step_size} must be positive and finite")
    if not stop_time > start_time:
        raise ValueError(f"stop time {stop_time} must be after start time {start_time}")
    n = int(math.floor((stop_time - start_time) / step_size + 1e-9))
    points = start_time + step_size * np.arange(n + 1)
    if extra is not None and len(extra):
        inside = extra[(extra > start_time) & (extra < stop_time)]
        points = np.union1d(points, inside)
    points = np.append(points[points < stop_time], stop_time)
    keep = np.concatenate([[True], np.diff(points) > _MERGE_FRACTION * step_size])
    keep[-1] = True
    points = points[keep]
    if len(points) > 2 and points[-1] - points[-2] <= _MERGE_FRACTION * step_size:
        points = np.delete(points, -2)
    return points


def schedule(torque: TorqueSignal, *, start_time: float = 0.0, stop_time: float | None = None,
             step_size: float = 1e-3, ramp: bool = False) -> TorqueSchedule:
    """The schedule of a signal: a constant, a callable of time, or a torque CSV (path or table).

    The torque of each step is the signal at the step's start (a CSV's value after a jump). With
    ramp=True it instead moves linearly over the step to the signal's value at the step's end.
    Jumps in a CSV become communication points, so no step straddles one. stop_time defaults to
    3 s, or to a CSV's last time.
    """
    if isinstance(torque, (str, Path)):
        torque = read_torque_csv(torque)
    if isinstance(torque, TorqueTable):
        table = torque
        stop = float(table.time[-1]) if stop_time is None else stop_time
        time = communication_points(start_time, stop, step_size, table.jumps())
        start_values = np.array([table.value_after(t) for t in time[:-1]])
        end_values = np.array([table.value_before(t) for t in time[1:]])
    else:
        time = communication_points(start_time, 3.0 if stop_time is None else stop_time, step_size)
        if callable(torque):
            samples = np.array([float(torque(float(t))) for t in time])
        else:
            samples = np.full(len(time), float(torque))
        if not np.all(np.isfinite(samples)):
            bad = time[~np.isfinite(samples)][0]
            raise ValueError(f"the torque is {samples[~np.isfinite(samples)][0]} at t = {bad}; it must be finite")
        start_values, end_values = samples[:-1], samples[1:]
    rate = (end_values - start_values) / np.diff(time) if ramp else np.zeros(len(time) - 1)
    return TorqueSchedule(time=time, torque=start_values, torque_rate=rate)
