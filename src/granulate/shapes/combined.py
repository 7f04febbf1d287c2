"""Union and Difference of shapes of one dimension, and the grid estimate of their measure."""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from granulate.errors import InputError
from granulate.input_errors import checked_arguments
from granulate.shapes.base import Shape, _points


@checked_arguments
@dataclass(frozen=True)
class Union(Shape):
    """Points in any of the shapes (all of one dimension)."""

    shapes: tuple[Shape, ...]

    def __post_init__(self) -> None:
        _same_dimension(self.shapes, "Union")

    @property
    def dimension(self) -> int:  # type: ignore[override]
        return self.shapes[0].dimension

    def contains(self, points: ArrayLike) -> NDArray[np.bool_]:
        p = _points(points)
        inside = np.zeros(len(p), dtype=bool)
        for shape in self.shapes:
            inside |= shape.contains(p)
        return inside

    def bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        boxes = [s.bounds() for s in self.shapes]
        return np.min([b[0] for b in boxes], axis=0), np.max([b[1] for b in boxes], axis=0)

    @functools.cached_property
    def measure(self) -> float:
        """Area (volume) [m^2; m^3], estimated on a grid (see grid_measure)."""
        return grid_measure(self)

    def signed_distance(self, points: ArrayLike) -> NDArray[np.float64]:
        p = _points(points)
        return np.min([shape.signed_distance(p) for shape in self.shapes], axis=0)


@checked_arguments
@dataclass(frozen=True)
class Difference(Shape):
    """Points of ``base`` not in ``removed`` (notches, holes)."""

    base: Shape
    removed: Shape

    def __post_init__(self) -> None:
        _same_dimension((self.base, self.removed), "Difference")

    @property
    def dimension(self) -> int:  # type: ignore[override]
        return self.base.dimension

    def contains(self, points: ArrayLike) -> NDArray[np.bool_]:
        p = _points(points)
        return self.base.contains(p) & ~self.removed.contains(p)

    def bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        return self.base.bounds()

    @functools.cached_property
    def measure(self) -> float:
        """Area (volume) [m^2; m^3], estimated on a grid (see grid_measure)."""
        return grid_measure(self)

    def signed_distance(self, points: ArrayLike) -> NDArray[np.float64]:
        p = _points(points)
        return np.maximum(self.base.signed_distance(p), -self.removed.signed_distance(p))


def grid_measure(shape: Shape) -> float:
    """The area (volume) of a shape without a formula (a union, a difference), counted on a
    grid over its bounds: 1024 x 1024 cells in 2D, 128^3 in 3D, and the cells the boundary
    crosses (by signed distance) sampled again 8 x 8 (4 x 4 x 4) times finer. Measured
    relative errors: 7e-5 (an L of two rectangles), 1.7e-6 (a disc less a disc), 1.2e-5 (a
    sphere less a sphere), 5e-6 (two overlapping spheres); 0.2-0.5 s in 2D, about 1 s in 3D."""
    lower, upper = (np.asarray(b, dtype=float)[: shape.dimension] for b in shape.bounds())
    cells = 1024 if shape.dimension == 2 else 128
    size = (upper - lower) / cells
    d = shape.dimension
    axes = [lower[k] + (np.arange(cells) + 0.5) * size[k] for k in range(d)]
    centres = np.zeros((cells**d, 3))
    centres[:, :d] = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, d)
    near = np.abs(shape.signed_distance(centres)) < 0.5 * float(np.linalg.norm(size))
    inside = float(np.count_nonzero(shape.contains(centres[~near])))
    fine = 8 if d == 2 else 4
    offsets = (np.arange(fine) + 0.5) / fine - 0.5
    sub = np.zeros((fine**d, 3))
    sub[:, :d] = np.stack(np.meshgrid(*[offsets] * d, indexing="ij"), axis=-1).reshape(-1, d) * size
    boundary = centres[near]
    for chunk in np.array_split(boundary, max(1, len(boundary) // 20_000)):
        points = (chunk[:, None, :] + sub[None, :, :]).reshape(-1, 3)
        inside += np.count_nonzero(shape.contains(points)) / len(sub)
    return float(inside * np.prod(size))


def _same_dimension(shapes: tuple[Shape, ...], name: str) -> None:
    if not shapes:
        raise InputError(f"{name} needs at least one shape")
    dimensions = {s.dimension for s in shapes}
    if len(dimensions) != 1:
        raise InputError(f"{name} mixes 2D and 3D shapes")
