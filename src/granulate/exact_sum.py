"""Sums of floats kept exactly, so that a sum split among ranks (or threads, or in any order)
rounds to the same bits as the whole.

A float64 x is M 2^(e - 53) with M an integer below 2^53 in size (np.frexp). Every finite float
is so a whole multiple of 2^-1127 (e >= -1073), and the sum of any of them is one integer N
times 2^-1127: exact as a Python int, however many terms and in whatever order they were added.
ExactSum holds N; adding two is adding their Ns (a rank's partial sums travel as one int), and
``value`` rounds N 2^-1127 to the nearest float once (Python's int division rounds correctly, to
even on a tie): the correctly rounded sum of every term, as math.fsum gives it.

The terms are binned by the core (granulate._core.exact_sum_bins, cpp/src/exact_sum.cpp): each
mantissa is split into two halves of 26 and 27 bits and each half summed per array and exponent
in 64-bit integers, exact for up to 2^35 terms (a chunk); the few exponents present are then put
together in Python ints. About 2 ns a term (math.fsum: 46 ns), and one call for several sums
(``ExactSum.each``: a history row's dozen).

A non-finite term (inf, nan) makes the sum non-finite as float addition would: inf, -inf or nan,
whatever the order.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from granulate import _core

_SCALE = 1127  # every finite float is a whole multiple of 2^-_SCALE
_LOW_BITS = 26  # the core splits each mantissa into high 2^26 + low
_CHUNK = 2**35  # terms per call: 2^35 halves below 2^27 in size sum below 2^62


@dataclass(frozen=True)
class ExactSum:
    """The exact sum of some floats: ``scaled`` = sum * 2^1127 (an int), or ``special``, the
    non-finite value (inf, -inf, nan) any non-finite term makes it, else 0.0."""

    scaled: int = 0
    special: float = 0.0

    @classmethod
    def of(cls, terms: ArrayLike) -> ExactSum:
        """The exact sum of every element of `terms` (any shape, taken as float64)."""
        return cls._of_flat(_flat(terms))

    @classmethod
    def each(cls, arrays: Sequence[ArrayLike]) -> list[ExactSum]:
        """[ExactSum.of(a) for a in arrays], in one call of the core (each array's sum binned
        apart) while they are finite and at most a chunk."""
        flat = [_flat(a) for a in arrays]
        bins = None if any(len(t) > _CHUNK for t in flat) else _core.exact_sum_bins(flat)
        if bins is None:  # a term is not finite, or an array is too long for one call
            return [cls._of_flat(terms) for terms in flat]
        return [cls(scaled) for scaled in _added(bins, len(flat))]

    @classmethod
    def _of_flat(cls, x: np.ndarray) -> ExactSum:
        """ExactSum.of a flat contiguous float64 array."""
        scaled = 0
        for start in range(0, len(x), _CHUNK):
            bins = _core.exact_sum_bins([x[start : start + _CHUNK]])
            if bins is None:  # a term is inf or nan: so is the sum, as float addition gives
                with np.errstate(invalid="ignore"):  # inf - inf: nan
                    return cls(0, float(np.sum(x[~np.isfinite(x)])))
            scaled += _added(bins, 1)[0]
        return cls(scaled)

    def __add__(self, other: ExactSum) -> ExactSum:
        return ExactSum(self.scaled + other.scaled, self.special + other.special)

    @property
    def value(self) -> float:
        """The sum rounded to the nearest float (ties to even)."""
        if self.special != 0.0:  # nan too
            return self.special
        try:
            return self.scaled / (1 << _SCALE)
        except OverflowError:  # beyond the largest float, as float addition overflows
            return math.inf if self.scaled > 0 else -math.inf


def _flat(terms: ArrayLike) -> np.ndarray:
    """`terms` as a flat contiguous float64 array (a view when they are one already)."""
    return np.ascontiguousarray(terms, dtype=np.float64).ravel()


def _added(bins: tuple[np.ndarray, ...], count: int) -> list[int]:
    """For each of `count` arrays the sum of its terms times 2^1127, exactly, from the core's
    bins (exact_sum_bins: each bin's array, exponent S and sums of the mantissas' halves, a
    term being (high 2^26 + low) 2^(S - 1127))."""
    scaled = [0] * count
    for array, exponent, high, low in zip(*(column.tolist() for column in bins), strict=True):
        scaled[array] += ((high << _LOW_BITS) + low) << exponent
    return scaled
