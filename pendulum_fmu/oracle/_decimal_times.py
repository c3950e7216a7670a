"""Exact times as integers: the decimals written, on a common denominator 10**digits.

The oracle's times are fractions of decimals (a CSV's rows, the grid's start, step and stop). On
one denominator numpy compares and subtracts them exactly, a whole window at once, as Fraction
does one time at a time: in int64 where they fit, else as Python's integers (an object array,
still far quicker than fractions).
"""

from __future__ import annotations

from collections.abc import Iterable
from fractions import Fraction
from functools import cache

import numpy as np

# Exact int64 times, with room for their differences: |t| * 10**digits below this.
LIMIT = 2**62


@cache
def _digits_of(denominator: int) -> int | None:
    """The fewest decimal digits whose power of ten the denominator divides, or None (a third)."""
    twos = fives = 0
    while denominator % 2 == 0:
        denominator, twos = denominator // 2, twos + 1
    while denominator % 5 == 0:
        denominator, fives = denominator // 5, fives + 1
    return max(twos, fives) if denominator == 1 else None


def common_digits(denominators: Iterable[int]) -> int | None:
    """The digits of a common decimal denominator of all the fractions' denominators, or None."""
    digits = 0
    for denominator in set(denominators):
        own = _digits_of(denominator)
        if own is None:
            return None
        digits = max(digits, own)
    return digits


def scaled(times: Iterable[Fraction], digits: int) -> np.ndarray:
    """Each time times 10**digits (an integer: a decimal of at most digits digits), in int64
    where all are below LIMIT, else as Python's integers.
    """
    power = 10**digits
    values = [t.numerator * (power // t.denominator) for t in times]
    return np.array(values, dtype=np.int64 if max(map(abs, values), default=0) < LIMIT else object)


def scaled_steps(start: Fraction, step: Fraction, count: int, digits: int) -> np.ndarray:
    """The times start + k * step for k < count, times 10**digits, as scaled() gives them."""
    power = 10**digits
    first, stride = start.numerator * (power // start.denominator), step.numerator * (power // step.denominator)
    largest = max(abs(first), abs(first + max(count - 1, 0) * stride))
    steps = np.arange(count, dtype=np.int64 if largest < LIMIT else object)
    return first + steps * stride
