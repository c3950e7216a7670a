"""Communication points, and the size limits a run is checked against before anything is allocated.

A grid point is start + k*h, never a running sum; an event within event_tolerance of a point is
that point (docs/signals.md). step_count refuses a run too long for its limit or for the memory
the machine has left, naming what to change.
"""

from __future__ import annotations

import math
import numbers
from fractions import Fraction

import numpy as np

from .._errors import InvalidInput

# Events closer than this to a communication point are that point: a billionth of a step, or 64
# ulp of the time where times are so large that a grid point's own rounding is bigger.
EVENT_TOLERANCE_STEPS = 1e-9


EVENT_TOLERANCE_ULPS = 64


# A run longer than this is refused unless asked for (max_steps, --max-steps): at 1 ms it is
# close to 3 hours of simulated time, and a typo in a time (epoch seconds, 1e-8 s steps) is
# likelier than a run that long.
DEFAULT_MAX_STEPS = 10_000_000


# A study larger than this is refused unless asked for (run_sweep's max_cases, --max-cases): at a
# millisecond a case it is a quarter of an hour on 1,000 cores, and a grid multiplied out by a
# stray value list is likelier than a study that large. Here beside the other size limit, so that
# the command line's help reads it without loading the sweep.
DEFAULT_MAX_CASES = 1_000_000

# Where run_sweep runs a study (sweep/here.py): chosen by its size, the calling process, a dask
# cluster. A study of fewer steps (cases times steps per case) than BREAK_EVEN_STEPS still to run
# takes less time in the calling process than on a local cluster of two workers, whose start is
# then more than its workers save. Measured by `python -m benchmarks.small_studies` (studies in
# the process and on a cluster at two sizes, where the two lines cross): 25, 40, 105, 248 and 322
# million steps in five runs on the loaded 2-core VM; the lowest, rounded down, for a quieter
# machine, whose two workers gain more. Here beside the other size limits, for the same reason.
RUN_IN = ("auto", "process", "cluster")
BREAK_EVEN_STEPS = 20_000_000


# Runs needing less memory than this are not checked against what the machine has left: reading
# it (/proc/meminfo) costs more than such a run, which no machine that runs Python lacks.
MEMORY_CHECKED_FROM = 2**26  # bytes (64 MiB: about 700,000 steps)


# Memory one step takes in simulate(): the schedule's three doubles, the result's five and the
# four recorded outputs.
BYTES_PER_STEP = 8 * (3 + 5 + 4)


# Grid steps per window where a long run is walked a window at a time (schedule_windows,
# reference_windows, simulate --output, the judge). The judge holds about 600 bytes a step of its
# window (the result's rows, the reference, the run's own integration from each state, a variant
# at a time, the series' workspace): judging a 1,000,001-row result peaked at 208 MB in windows of
# 131,072 steps, 173 MB in 65,536 and 150 MB in 32,768, in the same 4.2 to 4.4 s, each window's
# fixed cost (the oracle's work estimate on its own grid, a restart of the series, numpy's
# calls) lost in its steps. 65,536 leaves a 256 MB budget a margin.
WINDOW_STEPS = 1 << 16


def event_tolerance(time, step_size: float):
    """How close an event must be to a communication point to be that point (s)."""
    if isinstance(time, float):  # math.ulp is np.spacing for a scalar, without numpy's overhead
        return max(EVENT_TOLERANCE_STEPS * step_size, EVENT_TOLERANCE_ULPS * math.ulp(abs(time)))
    return np.maximum(
        EVENT_TOLERANCE_STEPS * step_size, EVENT_TOLERANCE_ULPS * np.spacing(np.abs(np.asarray(time, dtype=float)))
    )


def nearest(points: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The point of the sorted `points` (two or more) nearest to each t."""
    i = np.clip(np.searchsorted(points, t), 1, len(points) - 1)
    return np.where(np.abs(points[i] - t) < np.abs(points[i - 1] - t), points[i], points[i - 1])


def _check_times(start_time: float, stop_time: float, step_size: float) -> None:
    for name, value in (("start time", start_time), ("stop time", stop_time), ("step size", step_size)):
        if not isinstance(value, numbers.Real):
            raise InvalidInput(f"{name} {value!r} must be a finite number of seconds")
        if not math.isfinite(value):
            raise InvalidInput(f"{name} {value} must be a finite number of seconds")
    if not step_size > 0:
        raise InvalidInput(f"step size {step_size} must be positive")
    if not stop_time > start_time:
        raise InvalidInput(f"stop time {stop_time} must be after start time {start_time}")


def _available_memory() -> int:
    """Bytes the machine can still give: MemAvailable on Linux, psutil's counterpart elsewhere."""
    import psutil  # here, not at the top: only a run this large asks, and every command's start-up imports this module

    return psutil.virtual_memory().available


def step_count(
    start_time: float,
    stop_time: float,
    step_size: float,
    max_steps: int | None = None,
    *,
    check_memory: bool = True,
) -> int:
    """The number of grid steps from start to stop (the last one shorter when stop is off the
    grid). A run over max_steps (default DEFAULT_MAX_STEPS), or one whose arrays would not fit in
    the memory the machine has left, is refused here, before anything is allocated. A run walked
    a window at a time holds no whole-run array: check_memory=False leaves out the second check.
    """
    _check_times(start_time, stop_time, step_size)
    span = stop_time - start_time
    ratio = span / step_size
    if math.isfinite(ratio):
        steps = math.floor(ratio)
        # stop within the event tolerance past a grid point is that point, not a sliver of a step.
        if span - steps * step_size > event_tolerance(stop_time, step_size):
            steps += 1
    else:
        # The span or the count is past the largest double (1e308 s, a 1e-320 s step): count
        # exactly, so the run is refused below in the same words as any run too long.
        steps = math.ceil((Fraction(stop_time) - Fraction(start_time)) / Fraction(step_size))
    steps = max(steps, 1)
    limit = DEFAULT_MAX_STEPS if max_steps is None else max_steps
    if not (isinstance(limit, numbers.Integral) and limit >= 1):
        raise InvalidInput(f"max steps {limit!r} must be a whole number of steps, at least 1")
    what = f"{start_time:g} to {stop_time:g} s in steps of {step_size:g} s is {_count(steps)} steps"
    if steps > limit:
        raise InvalidInput(
            f"{what}, over the limit of {limit:,}: use a coarser step size or a shorter "
            "stop time, or raise the limit (--max-steps) if the run is meant to be that long"
        )
    needed = steps * BYTES_PER_STEP
    if check_memory and needed > MEMORY_CHECKED_FROM:
        available = _available_memory()
        if needed > available:
            raise InvalidInput(
                f"{what}, which needs {_gib(needed)} and the machine has "
                f"{available / 2**30:.1f} GiB free: use a coarser step size or a "
                "shorter stop time"
            )
    return steps


def _count(steps: int) -> str:
    """A step count as a line can hold it: every digit up to 2**53, then 'about 1.23e+628'. Past
    2**53 the count came from a float quotient, whose trailing digits are rounding, and past 1e308
    no float holds it, so it is rounded here in integers.
    """
    if steps <= 2**53:
        return f"{steps:,}"
    exponent = len(str(steps)) - 1
    mantissa = round(Fraction(steps, 10 ** (exponent - 2)))  # three digits, 100 to 1000
    if mantissa == 1000:
        mantissa, exponent = 100, exponent + 1
    return f"about {mantissa / 100:g}e+{exponent}"


def _gib(size: int) -> str:
    return f"{size / 2**30:.1f} GiB" if size < 2**1000 else f"{_count(size >> 30)} GiB"


def communication_points(
    start_time: float, stop_time: float, step_size: float, *, max_steps: int | None = None
) -> np.ndarray:
    """start, start + h, ... up to stop. A grid point is start + k*h, never a running sum, so no
    rounding accumulates over a long run. max_steps: see step_count.
    """
    steps = step_count(start_time, stop_time, step_size, max_steps)
    return grid_points(start_time, stop_time, step_size, steps, np.arange(steps + 1))


def grid_points(start_time: float, stop_time: float, step_size: float, steps: int, k: np.ndarray) -> np.ndarray:
    """The grid points of the indices k (sorted, 0 to steps) of a run of `steps` steps, as
    communication_points gives them: each computed on its own, so that a window of the run, or a
    few points anywhere in it, are the whole grid's bit for bit.
    """
    points = start_time + step_size * np.asarray(k, dtype=float)
    # The last point is stop, unless stop is within the event tolerance of start + steps * h.
    if len(points) and k[-1] == steps and abs(points[-1] - stop_time) > event_tolerance(stop_time, step_size):
        points[-1] = stop_time
    return points
