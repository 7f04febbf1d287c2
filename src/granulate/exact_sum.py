"""Sums of floats kept exactly, so that a sum split among ranks (or threads, or in any order)
rounds to the same bits as the whole.

A float64 x is M 2^(e - 53) with M an integer below 2^53 in size (np.frexp). Every finite float
is so a whole multiple of 2^-1127 (e >= -1073), and the sum of any of them is one integer N
times 2^-1127: exact as a Python int, however many terms and in whatever order they were added.
ExactSum holds N; adding two is adding their Ns (a rank's partial sums travel as one int), and
``value`` rounds N 2^-1127 to the nearest float once (Python's int division rounds correctly, to
even on a tie): the correctly rounded sum of every term, as math.fsum gives it.

The terms are added in NumPy: the mantissas are split into two halves of 26 and 27 bits and each
half summed per exponent by np.bincount, whose float64 sums of integers stay exact while they
are below 2^53 (chunks of 2^25 terms); the few exponents present are then put together in Python
ints. About 35 ns a term (math.fsum: 46 ns). A sum of few terms costs the dozen NumPy calls,
about 60 us; ``ExactSum.each`` makes several sums (a history row's dozen) in one pass.

A non-finite term (inf, nan) makes the sum non-finite as float addition would: inf, -inf or nan,
whatever the order.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

_SCALE = 1127  # every finite float is a whole multiple of 2^-_SCALE
_LOW_BITS = 26
_CHUNK = 2**25  # terms per bincount: 2^25 halves below 2^27 sum below 2^52


@dataclass(frozen=True)
class ExactSum:
    """The exact sum of some floats: ``scaled`` = sum * 2^1127 (an int), or ``special``, the
    non-finite value (inf, -inf, nan) any non-finite term makes it, else 0.0."""

    scaled: int = 0
    special: float = 0.0

    @classmethod
    def of(cls, terms: ArrayLike) -> ExactSum:
        """The exact sum of every element of `terms` (any shape, taken as float64)."""
        return cls._of_flat(np.asarray(terms, dtype=np.float64).ravel())

    @classmethod
    def each(cls, arrays: Sequence[ArrayLike]) -> list[ExactSum]:
        """[ExactSum.of(a) for a in arrays], in one NumPy pass over all their terms (each
        array's sum binned apart) while they are finite and at most a chunk."""
        flat = [np.asarray(a, dtype=np.float64).ravel() for a in arrays]
        x = np.concatenate([np.zeros(0), *flat])
        if len(x) > _CHUNK or not np.isfinite(x).all():
            return [cls._of_flat(terms) for terms in flat]
        rows = np.repeat(np.arange(len(flat)), [len(terms) for terms in flat])
        return [cls(scaled) for scaled in _scaled_sums(x, rows, len(flat))]

    @classmethod
    def _of_flat(cls, x: np.ndarray) -> ExactSum:
        """ExactSum.of a flat float64 array."""
        finite = np.isfinite(x)
        if not finite.all():
            with np.errstate(invalid="ignore"):  # inf - inf: nan, as float addition gives
                return cls(0, float(np.sum(x[~finite])))
        scaled = 0
        for start in range(0, len(x), _CHUNK):
            scaled += _scaled_sums(x[start : start + _CHUNK], 0, 1)[0]
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


def _scaled_sums(x: np.ndarray, rows: np.ndarray | int, count: int) -> list[int]:
    """For each of `count` rows, the sum of the terms of x in it (`rows`: each term's row,
    0 <= row < count, or one row for all) times 2^1127, exactly, for finite x of at most
    _CHUNK terms."""
    fraction, exponent = np.frexp(x)  # x = fraction 2^exponent, 1/2 <= |fraction| < 1
    mantissa = np.ldexp(fraction, 53).astype(np.int64)  # exact: |mantissa| < 2^53
    shift = exponent.astype(np.int64) - 53 + _SCALE  # x = mantissa 2^(shift - 1127), shift >= 1
    high = mantissa >> _LOW_BITS  # floor: mantissa = high 2^26 + low, 0 <= low < 2^26
    low = mantissa - (high << _LOW_BITS)
    first = int(shift.min()) if len(x) else 0
    bins = int(shift.max()) - first + 1 if len(x) else 1
    key = rows * bins + (shift - first)  # the row's bin of each exponent present
    highs = np.bincount(key, weights=high.astype(np.float64), minlength=count * bins)
    lows = np.bincount(key, weights=low.astype(np.float64), minlength=count * bins)
    scaled = [0] * count
    for k in np.flatnonzero((highs != 0) | (lows != 0)):
        row, s = divmod(int(k), bins)
        scaled[row] += ((int(highs[k]) << _LOW_BITS) + int(lows[k])) << (first + s)
    return scaled
