"""Distributions of particle sizes (bounding radii [m]) for packings: fixed, uniform, normal,
log-normal, and sieve fractions (a grading curve given as mass fractions between sieve sizes).
Each draws sizes with ``sample(rng, count)``; granulate.packing.pack uses them through its grains.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from granulate.errors import InputError
from granulate.input_errors import checked_arguments


class SizeDistribution(ABC):
    """Distribution of particle sizes (bounding radii [m])."""

    @abstractmethod
    def sample(self, rng: np.random.Generator, count: int) -> NDArray[np.float64]:
        """``count`` sizes drawn with ``rng`` [m]."""

    def _bounded(self, draw, low: float, high: float, rng, count: int) -> NDArray[np.float64]:
        """Draws kept within [low, high] by redrawing the rest (a truncated distribution)."""
        out = np.empty(0)
        for _ in range(1000):
            values = draw(rng, 2 * (count - len(out)) + 16)
            out = np.concatenate([out, values[(values >= low) & (values <= high)]])
            if len(out) >= count:
                return out[:count]
        raise InputError(f"{self!r}: almost no sizes fall within [{low}, {high}]; widen the bounds")


@checked_arguments
@dataclass(frozen=True)
class Fixed(SizeDistribution):
    """Every particle has bounding radius ``radius`` [m]."""

    radius: float

    def __post_init__(self) -> None:
        if not (self.radius > 0 and np.isfinite(self.radius)):
            raise InputError(f"Fixed radius must be positive, got {self.radius}")

    def sample(self, rng: np.random.Generator, count: int) -> NDArray[np.float64]:
        return np.full(count, float(self.radius))


@checked_arguments
@dataclass(frozen=True)
class Uniform(SizeDistribution):
    """Radius uniform in [low, high] [m]."""

    low: float
    high: float

    def __post_init__(self) -> None:
        if not (0 < self.low <= self.high and np.isfinite(self.high)):
            raise InputError(f"Uniform sizes need 0 < low <= high, got {self.low}, {self.high}")

    def sample(self, rng: np.random.Generator, count: int) -> NDArray[np.float64]:
        return rng.uniform(self.low, self.high, count)


@checked_arguments
@dataclass(frozen=True)
class Normal(SizeDistribution):
    """Radius normal with ``mean`` and ``std`` [m], truncated to [low, high] (default: mean -/+
    3 std, and above zero)."""

    mean: float
    std: float
    low: float | None = None
    high: float | None = None

    def __post_init__(self) -> None:
        if not (self.mean > 0 and self.std >= 0):
            raise InputError(
                f"Normal sizes need mean > 0 and std >= 0, got {self.mean}, {self.std}"
            )

    def sample(self, rng: np.random.Generator, count: int) -> NDArray[np.float64]:
        low = self.low if self.low is not None else max(self.mean - 3 * self.std, 1e-3 * self.mean)
        high = self.high if self.high is not None else self.mean + 3 * self.std
        if self.std == 0:
            return np.full(count, float(self.mean))
        return self._bounded(lambda r, n: r.normal(self.mean, self.std, n), low, high, rng, count)


@checked_arguments
@dataclass(frozen=True)
class LogNormal(SizeDistribution):
    """Radius log-normal: ln r normal about ln ``median`` with ``sigma``, truncated to [low,
    high] [m] (default: median e^-/+3 sigma)."""

    median: float
    sigma: float
    low: float | None = None
    high: float | None = None

    def __post_init__(self) -> None:
        if not (self.median > 0 and self.sigma >= 0):
            raise InputError(
                f"LogNormal sizes need median > 0 and sigma >= 0, got {self.median}, {self.sigma}"
            )

    def sample(self, rng: np.random.Generator, count: int) -> NDArray[np.float64]:
        low = self.low if self.low is not None else self.median * np.exp(-3 * self.sigma)
        high = self.high if self.high is not None else self.median * np.exp(3 * self.sigma)
        draw = lambda r, n: self.median * np.exp(r.normal(0.0, self.sigma, n))  # noqa: E731
        return self._bounded(draw, low, high, rng, count)


@checked_arguments
@dataclass(frozen=True)
class Sieve(SizeDistribution):
    """A grading curve: ``passing[k]`` is the mass fraction of grains finer than sieve opening
    ``diameters[k]`` [m] (increasing, from 0 to 1). Within a sieve interval the mass is spread
    uniformly in log size; radii are half the diameters. Grains of one shape have mass ~ r^d,
    so the number of grains per interval is the mass fraction / r^d (``dimension``)."""

    diameters: tuple[float, ...]
    passing: tuple[float, ...]
    dimension: int = 3

    def __post_init__(self) -> None:
        d = np.asarray(self.diameters, dtype=float)
        p = np.asarray(self.passing, dtype=float)
        if len(d) < 2 or d.shape != p.shape:
            raise InputError("Sieve needs at least two (diameter, passing) pairs of equal length")
        if np.any(d <= 0) or np.any(np.diff(d) <= 0):
            raise InputError("Sieve diameters must be positive and increasing")
        if np.any(np.diff(p) < 0) or not (np.isclose(p[0], 0) and np.isclose(p[-1], 1)):
            raise InputError("Sieve passing fractions must rise from 0 to 1")
        if self.dimension not in (2, 3):
            raise InputError(f"Sieve dimension must be 2 or 3, got {self.dimension}")

    def sample(self, rng: np.random.Generator, count: int) -> NDArray[np.float64]:
        d = np.log(np.asarray(self.diameters, dtype=float))
        mass = np.diff(np.asarray(self.passing, dtype=float))
        # Number per interval: mass / mean of r^d over the interval (log-uniform).
        k = self.dimension
        mean_power = (np.exp(k * d[1:]) - np.exp(k * d[:-1])) / (k * (d[1:] - d[:-1]))
        number = mass / mean_power
        interval = rng.choice(len(mass), size=count, p=number / number.sum())
        # Within an interval, number density ~ r^-d on a log-uniform mass: inverse CDF of r^-k.
        u = rng.uniform(0, 1, count)
        low, high = np.exp(-k * d[interval]), np.exp(-k * d[interval + 1])
        return 0.5 * (low + u * (high - low)) ** (-1.0 / k)
