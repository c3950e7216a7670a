"""Side-by-side timing: contenders take turns, so a noisy machine slows them alike."""

from __future__ import annotations

import gc
import statistics
import time
from collections.abc import Callable

# A contender runs once and returns its wall-clock seconds for the part that is compared.
Contender = Callable[[], float]


def timed(function: Callable[[], object]) -> tuple[float, object]:
    """(seconds, result) of one call, with the garbage collector held off as timeit does, so a
    collection triggered by one contender's garbage is not charged to the other.
    """
    enabled = gc.isenabled()
    gc.disable()
    try:
        start = time.perf_counter()
        result = function()
        return time.perf_counter() - start, result
    finally:
        if enabled:
            gc.enable()


def interleaved(contenders: dict[str, Contender], repetitions: int) -> dict[str, list[float]]:
    """Seconds of each contender per repetition. Every repetition runs all of them, in an order
    rotated each time so no one always goes first (cold caches) or last.
    """
    names = list(contenders)
    seconds: dict[str, list[float]] = {name: [] for name in names}
    for repetition in range(repetitions):
        shift = repetition % len(names)
        for name in names[shift:] + names[:shift]:
            seconds[name].append(contenders[name]())
    return seconds


def median(values: list[float]) -> float:
    return statistics.median(values)
