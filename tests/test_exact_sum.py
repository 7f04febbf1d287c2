"""ExactSum: the correctly rounded sum of any floats, the same bits however they are split,
ordered or merged (granulate.exact_sum)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from granulate.exact_sum import ExactSum


def _wide(rng: np.random.Generator, n: int) -> np.ndarray:
    """Floats of both signs over 600 binary orders of magnitude, subnormals and cancelling
    pairs among them: sums that naive addition gets wrong in many bits."""
    x = rng.standard_normal(n) * np.exp2(rng.integers(-300, 300, n))
    x[: n // 10] = rng.standard_normal(n // 10) * 5e-324 * 2**20  # subnormal
    x[n // 10 : n // 5] = -x[n // 5 : n // 5 + n // 10]  # cancel others exactly
    return x


@pytest.mark.parametrize("seed", range(5))
def test_is_the_correctly_rounded_sum(seed: int) -> None:
    rng = np.random.default_rng(seed)
    x = _wide(rng, 5_000)
    assert ExactSum.of(x).value == math.fsum(x)
    energies = rng.random(10_000) * 1e-6  # like node kinetic energies
    assert ExactSum.of(energies).value == math.fsum(energies)


@pytest.mark.parametrize("seed", range(5))
def test_several_sums_at_once_are_each_arrays_sum(seed: int) -> None:
    """ExactSum.each (a history row's sums in one pass) gives each array's exact sum, as
    ExactSum.of does: arrays of different lengths and binary orders, empty ones, one whose
    terms cancel to zero; with a non-finite term in one array, that array's inf and the
    others' sums."""
    rng = np.random.default_rng(seed)
    lengths, orders = 10 * rng.integers(1, 30, 6), rng.integers(-20, 20, 6)
    arrays = [_wide(rng, int(n)) * 2.0 ** int(k) for n, k in zip(lengths, orders, strict=True)]
    arrays += [np.zeros(0), np.array([1e-300, 1e300, -1e300, -1e-300])]
    sums = ExactSum.each(arrays)
    assert sums == [ExactSum.of(x) for x in arrays]
    assert [s.value for s in sums] == [math.fsum(x) for x in arrays]
    assert sums[-1] == ExactSum() and sum(s != ExactSum() for s in sums) >= 5
    with_inf = ExactSum.each([arrays[0], np.array([1.0, np.inf])])
    assert with_inf[0] == sums[0] and with_inf[1].value == math.inf


@pytest.mark.parametrize("seed", range(5))
def test_parts_in_any_order_give_the_same_bits(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for x in (_wide(rng, 4_000), rng.random(4_000)):
        whole = ExactSum.of(x).value
        shuffled = rng.permutation(x)
        pieces = np.split(shuffled, np.sort(rng.integers(0, len(x), 6)))
        parts = [ExactSum.of(piece) for piece in pieces]
        assert sum(reversed(parts), ExactSum()).value == whole
        assert sum(parts, ExactSum()).value == whole
        assert sum(x[::-1].tolist()) != whole or sum(x.tolist()) != whole  # order matters


def test_chunks_are_joined_exactly(monkeypatch: pytest.MonkeyPatch) -> None:
    import granulate.exact_sum as exact

    rng = np.random.default_rng(7)
    x = _wide(rng, 1_000)
    monkeypatch.setattr(exact, "_CHUNK", 7)
    assert ExactSum.of(x).value == math.fsum(x)
    assert ExactSum.each([x, x[:3]]) == [ExactSum.of(x), ExactSum.of(x[:3])]


def test_many_terms_of_one_exponent_with_the_widest_mantissas() -> None:
    """A million terms in one exponent's bin, each with every mantissa bit set (2 - 2^-52 and
    its negative, and the largest subnormal): the core's 64-bit half sums stay exact."""
    widest, subnormal = np.nextafter(2.0, 0.0), np.nextafter(np.finfo(np.float64).tiny, 0.0)
    for term in (widest, -widest, subnormal):
        x = np.full(1_000_000, term)
        assert ExactSum.of(x).scaled == 1_000_000 * ExactSum.of([term]).scaled
        assert ExactSum.of(x).value == math.fsum(x)
    assert ExactSum.of(np.r_[np.full(999_999, widest), -widest]).value == 999_998 * widest


def test_extremes() -> None:
    largest = np.finfo(np.float64).max
    assert ExactSum.of([]).value == 0.0
    assert ExactSum.of([5e-324, 5e-324]).value == 1e-323
    assert ExactSum.of([largest, -largest, 1.0]).value == 1.0
    assert ExactSum.of([1e308, 1e308]).value == math.inf  # as float addition overflows
    assert ExactSum.of([-1e308, -1e308]).value == -math.inf
    assert ExactSum.of([1.0, math.inf]).value == math.inf
    assert math.isnan(ExactSum.of([math.inf, 1.0, -math.inf]).value)
    assert math.isnan((ExactSum.of([math.inf]) + ExactSum.of([-math.inf])).value)
    assert math.isnan((ExactSum.of([1.0]) + ExactSum.of([math.nan])).value)
    assert ExactSum.of(np.ones((3, 4))).value == 12.0


@settings(max_examples=300, deadline=None, derandomize=True)
@given(
    st.lists(st.floats(allow_nan=False, allow_infinity=False), max_size=60),
    st.integers(min_value=0, max_value=60),
)
def test_any_floats_split_anywhere_sum_as_fsum(terms: list[float], cut: int) -> None:
    """Hypothesis' floats (subnormals, the largest, signed zeros), cut in two anywhere: the
    parts added give math.fsum's bits, or infinity where the exact sum is beyond the largest
    float (fsum raises there)."""
    parts = ExactSum.of(terms[:cut]) + ExactSum.of(terms[cut:])
    try:
        expected = math.fsum(terms)
    except OverflowError:
        assert math.isinf(parts.value)
        return
    assert parts.value == expected
    assert ExactSum.of(terms).value == expected
