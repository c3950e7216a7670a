"""Exact times as integers: the decimals written, on a common denominator 10**digits.

The oracle's times are fractions of decimals (a CSV's rows, the grid's start, step and stop). On
one denominator numpy compares and subtracts them exactly, a whole window at once, as Fraction
does one time at a time: in int64 where they fit, else as Python's integers (an object array,
still far quicker than fractions). A CSV's time cells are read straight to such integers
(ticks), a chunk at a time, with no Fraction made per row.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from fractions import Fraction
from functools import cache
from typing import Any

import numpy as np

# Exact int64 times, with room for their differences: |t| * 10**digits below this.
LIMIT = 2**62
# Decimal digits whose powers of ten int64 holds.
_POWERS = 10 ** np.arange(19, dtype=np.int64)
# A time cell of digits and at most one point, no exponent: pyarrow's to parse, whole arrays at once.
_PLAIN = r"^-?[0-9]*\.?[0-9]*$"


@cache
def decimal_digits(denominator: int) -> int | None:
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
        own = decimal_digits(denominator)
        if own is None:
            return None
        digits = max(digits, own)
    return digits


def _integers(values: Sequence[int]) -> np.ndarray:
    """Python integers in int64 where all are below LIMIT, else as an object array."""
    fits = max(map(abs, values), default=0) < LIMIT
    return np.array(values, dtype=np.int64 if fits else object)


def scaled(times: Iterable[Fraction], digits: int) -> np.ndarray:
    """Each time times 10**digits (an integer: a decimal of at most digits digits), in int64
    where all are below LIMIT, else as Python's integers.
    """
    power = 10**digits
    return _integers([t.numerator * (power // t.denominator) for t in times])


def scaled_steps(start: Fraction, step: Fraction, count: int, digits: int) -> np.ndarray:
    """The times start + k * step for k < count, times 10**digits, as scaled() gives them."""
    power = 10**digits
    first, stride = start.numerator * (power // start.denominator), step.numerator * (power // step.denominator)
    largest = max(abs(first), abs(first + max(count - 1, 0) * stride))
    steps = np.arange(count, dtype=np.int64 if largest < LIMIT else object)
    return first + steps * stride


def rescaled(ticks: np.ndarray, shift: int) -> np.ndarray:
    """Times 10**digits (ticks) as times 10**(digits + shift), shift >= 0, as scaled() holds them."""
    if shift == 0:
        return ticks
    if ticks.dtype != object and shift < len(_POWERS):
        largest = int(np.abs(ticks).max(initial=0))
        if largest * 10**shift < LIMIT:
            return ticks * _POWERS[shift]
    return np.array([int(n) * 10**shift for n in ticks.tolist()], dtype=object)


def _on_common_digits(mantissas: np.ndarray, digits: np.ndarray) -> tuple[int, np.ndarray]:
    """Decimals mantissa / 10**digit on their largest digits: (that, the integers)."""
    common = int(digits.max(initial=0))
    shift = common - digits
    if mantissas.dtype != object and int(shift.max(initial=0)) < len(_POWERS):
        # Below LIMIT as doubles too, with room for their rounding: then exactly below it.
        if np.all(np.abs(mantissas.astype(float)) * _POWERS[shift].astype(float) < LIMIT / 2):
            return common, mantissas * _POWERS[shift]
    return common, _integers([int(m) * 10 ** int(s) for m, s in zip(mantissas.tolist(), shift.tolist(), strict=True)])


def _parts(cell: str) -> tuple[int, int]:
    """A decimal cell, as Fraction reads it, as (mantissa, digits): mantissa / 10**digits."""
    cell = cell.strip()
    whole, point, fraction = cell.partition(".")
    if not ("e" in cell or "E" in cell):
        return int(whole + fraction), len(fraction) if point else 0
    value = Fraction(cell)
    digits = decimal_digits(value.denominator)
    assert digits is not None, "a decimal's denominator divides a power of ten"
    return value.numerator * (10**digits // value.denominator), digits


def ticks_of_cells(cells: Sequence[str]) -> tuple[int, np.ndarray]:
    """Decimal time cells, as Fraction reads each (spaces around, an exponent): (digits, each
    time times 10**digits), digits the most any cell needs.
    """
    parts = [_parts(cell) for cell in cells]
    return _on_common_digits(
        _integers([mantissa for mantissa, _ in parts]), np.array([digits for _, digits in parts], dtype=np.int64)
    )


def ticks_of_arrow(cells: Any) -> tuple[int, np.ndarray]:
    """ticks_of_cells of a pyarrow array of strings: in C where every cell is digits with at most
    one point and its mantissa fits in int64, else cell by cell.
    """
    import pyarrow as pa
    import pyarrow.compute as pc

    cells = pc.utf8_trim_whitespace(cells)
    if len(cells) and pc.all(pc.match_substring_regex(cells, _PLAIN)).as_py():
        try:
            mantissas = pc.cast(pc.replace_substring(cells, ".", ""), pa.int64()).to_numpy()
        except pa.ArrowInvalid:  # beyond int64: Python's integers
            pass
        else:
            point = pc.find_substring(cells, ".").to_numpy()
            digits = np.where(point >= 0, pc.utf8_length(cells).to_numpy() - point - 1, 0)
            return _on_common_digits(mantissas, digits)
    return ticks_of_cells(cells.to_pylist())


def doubles_of(ticks: np.ndarray, digits: int) -> np.ndarray:
    """Each time's nearest double, as float(Fraction(tick, 10**digits)) rounds it."""
    if ticks.dtype != object and digits <= 22 and int(np.abs(ticks).max(initial=0)) < 2**53:
        # Both exact as doubles (10**22 is): one IEEE division rounds correctly, as Python's does.
        return ticks / float(10**digits)
    power = 10**digits
    return np.array([n / power for n in ticks.tolist()], dtype=float)


def count_at_most(ticks: np.ndarray, digits: int, t: Fraction, lo: int = 0, hi: int | None = None) -> int:
    """How many of the sorted ticks (times 10**digits) are at most the time t (bisect_right)."""
    return _search(ticks, math.floor(t * 10**digits), "right", lo, hi)


def count_below(ticks: np.ndarray, digits: int, t: Fraction, lo: int = 0, hi: int | None = None) -> int:
    """How many of the sorted ticks (times 10**digits) are below the time t (bisect_left)."""
    return _search(ticks, math.ceil(t * 10**digits), "left", lo, hi)


def _search(ticks: np.ndarray, key: int, side, lo: int, hi: int | None) -> int:
    hi = len(ticks) if hi is None else hi
    if ticks.dtype != object:  # every tick is within LIMIT: so is the key, in the same order
        key = min(max(key, -LIMIT), LIMIT)
    return lo + int(np.searchsorted(ticks[lo:hi], key, side))
