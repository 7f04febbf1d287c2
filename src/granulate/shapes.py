"""Shapes: bodies to discretize and regions to select nodes with.

Every shape answers ``contains(points)`` for an (n, 3) array of points (2D shapes ignore z),
knows its bounding box (``bounds()``) and its exact ``measure`` (area in 2D, volume in 3D).
``lattice(shape, h)`` fills a shape with nodes of a uniform lattice of spacing h, each carrying
the volume h^d of its cell.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from granulate.errors import InputError


def _points(points: ArrayLike) -> NDArray[np.float64]:
    array = np.asarray(points, dtype=np.float64)
    if array.ndim != 2 or array.shape[1] != 3:
        raise InputError(f"points must be an (n, 3) array, got shape {array.shape}")
    return array


def _vector(value: ArrayLike, size: int, name: str) -> NDArray[np.float64]:
    array = np.asarray(value, dtype=np.float64).reshape(-1)
    if array.shape != (size,) or not np.all(np.isfinite(array)):
        raise InputError(f"{name} must be {size} finite numbers, got {value!r}")
    return array


class Shape(ABC):
    """Base class: a closed set in 2D (the plane z = 0) or 3D."""

    dimension: int

    @abstractmethod
    def contains(self, points: ArrayLike) -> NDArray[np.bool_]:
        """Boolean mask of the (n, 3) points inside or on the shape."""

    @abstractmethod
    def bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Axis-aligned bounding box (lower, upper), each 3 numbers [m]."""

    @property
    @abstractmethod
    def measure(self) -> float:
        """Exact area (2D) or volume (3D) [m^2 or m^3]."""


@dataclass(frozen=True)
class Rectangle(Shape):
    """Axis-aligned rectangle [lower, upper] in the x-y plane [m]."""

    lower: tuple[float, float]
    upper: tuple[float, float]
    dimension: int = field(default=2, init=False)

    def __post_init__(self) -> None:
        lo, hi = (
            _vector(self.lower, 2, "Rectangle lower"),
            _vector(self.upper, 2, "Rectangle upper"),
        )
        if np.any(hi <= lo):
            raise InputError(
                f"Rectangle upper {self.upper} must exceed lower {self.lower} in x and y"
            )

    def contains(self, points: ArrayLike) -> NDArray[np.bool_]:
        p = _points(points)
        lo, hi = np.asarray(self.lower), np.asarray(self.upper)
        return np.all((p[:, :2] >= lo) & (p[:, :2] <= hi), axis=1)

    def bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        return np.array([*self.lower, 0.0]), np.array([*self.upper, 0.0])

    @property
    def measure(self) -> float:
        return float(np.prod(np.subtract(self.upper, self.lower)))


@dataclass(frozen=True)
class Disc(Shape):
    """Disc of a centre (x, y) and radius [m]."""

    center: tuple[float, float]
    radius: float
    dimension: int = field(default=2, init=False)

    def __post_init__(self) -> None:
        _vector(self.center, 2, "Disc center")
        if not self.radius > 0:
            raise InputError(f"Disc radius must be positive, got {self.radius}")

    def contains(self, points: ArrayLike) -> NDArray[np.bool_]:
        p = _points(points)
        return np.sum((p[:, :2] - np.asarray(self.center)) ** 2, axis=1) <= self.radius**2

    def bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        c = np.asarray(self.center, dtype=float)
        return np.array([*(c - self.radius), 0.0]), np.array([*(c + self.radius), 0.0])

    @property
    def measure(self) -> float:
        return float(np.pi * self.radius**2)


@dataclass(frozen=True)
class Polygon(Shape):
    """Simple polygon (convex or concave) from its vertices in order [m]."""

    vertices: tuple[tuple[float, float], ...]
    dimension: int = field(default=2, init=False)

    def __post_init__(self) -> None:
        v = np.asarray(self.vertices, dtype=float)
        if v.ndim != 2 or v.shape[1] != 2 or len(v) < 3 or not np.all(np.isfinite(v)):
            raise InputError("Polygon needs at least 3 finite (x, y) vertices")
        if abs(self.measure) == 0:
            raise InputError("Polygon has zero area (collinear vertices?)")

    def contains(self, points: ArrayLike) -> NDArray[np.bool_]:
        p = _points(points)[:, :2]
        v = np.asarray(self.vertices, dtype=float)
        inside = np.zeros(len(p), dtype=bool)
        for (x0, y0), (x1, y1) in zip(v, np.roll(v, -1, axis=0), strict=True):
            crosses = (y0 > p[:, 1]) != (y1 > p[:, 1])
            with np.errstate(divide="ignore", invalid="ignore"):
                x_cross = x0 + (p[:, 1] - y0) * (x1 - x0) / (y1 - y0)
            inside ^= crosses & (p[:, 0] < x_cross)
        return inside

    def bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        v = np.asarray(self.vertices, dtype=float)
        return np.array([*v.min(axis=0), 0.0]), np.array([*v.max(axis=0), 0.0])

    @property
    def measure(self) -> float:
        v = np.asarray(self.vertices, dtype=float)
        x, y = v[:, 0], v[:, 1]
        return float(abs(0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)))


@dataclass(frozen=True)
class Box(Shape):
    """Axis-aligned box [lower, upper] in 3D [m]."""

    lower: tuple[float, float, float]
    upper: tuple[float, float, float]
    dimension: int = field(default=3, init=False)

    def __post_init__(self) -> None:
        lo, hi = _vector(self.lower, 3, "Box lower"), _vector(self.upper, 3, "Box upper")
        if np.any(hi <= lo):
            raise InputError(f"Box upper {self.upper} must exceed lower {self.lower} in x, y and z")

    def contains(self, points: ArrayLike) -> NDArray[np.bool_]:
        p = _points(points)
        return np.all((p >= np.asarray(self.lower)) & (p <= np.asarray(self.upper)), axis=1)

    def bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        return np.asarray(self.lower, dtype=float), np.asarray(self.upper, dtype=float)

    @property
    def measure(self) -> float:
        return float(np.prod(np.subtract(self.upper, self.lower)))


@dataclass(frozen=True)
class Sphere(Shape):
    """Sphere of a centre (x, y, z) and radius [m]."""

    center: tuple[float, float, float]
    radius: float
    dimension: int = field(default=3, init=False)

    def __post_init__(self) -> None:
        _vector(self.center, 3, "Sphere center")
        if not self.radius > 0:
            raise InputError(f"Sphere radius must be positive, got {self.radius}")

    def contains(self, points: ArrayLike) -> NDArray[np.bool_]:
        p = _points(points)
        return np.sum((p - np.asarray(self.center)) ** 2, axis=1) <= self.radius**2

    def bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        c = np.asarray(self.center, dtype=float)
        return c - self.radius, c + self.radius

    @property
    def measure(self) -> float:
        return float(4.0 / 3.0 * np.pi * self.radius**3)


def lattice(
    shape: Shape, mesh_size: float, *, jitter: float = 0.0, seed: int = 0
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Nodes of a uniform lattice of spacing h clipped to a shape.

    Nodes sit at the centres of the cells lower + (i + 1/2) h of the bounding box; a node is kept
    when the shape contains it, and carries the cell volume h^d (area in 2D). ``jitter`` moves each
    node by a uniform random offset of at most jitter * h per axis (seeded, reproducible).

    Returns (positions (n, 3) [m], volumes (n,) [m^d]).
    """
    if not (mesh_size > 0 and np.isfinite(mesh_size)):
        raise InputError(f"mesh size must be positive, got {mesh_size}")
    if not 0 <= jitter < 0.5:
        raise InputError(f"jitter must be in [0, 0.5) mesh sizes, got {jitter}")
    lower, upper = shape.bounds()
    d = shape.dimension
    smallest = float(np.min(upper[:d] - lower[:d]))
    if mesh_size > smallest:
        raise InputError(
            f"mesh size {mesh_size} is larger than the shape (its smallest extent is "
            f"{smallest:.4g}); "
            "use a mesh size of at most a tenth of that"
        )
    counts = np.maximum(1, np.round((upper[:d] - lower[:d]) / mesh_size).astype(np.int64))
    # Centre the lattice in the bounding box so that a box of whole cells is filled exactly.
    origin = 0.5 * (lower[:d] + upper[:d]) - 0.5 * counts * mesh_size
    if np.prod(counts.astype(float)) > 2e8:
        raise InputError(
            f"mesh size {mesh_size} gives over 200 million lattice cells; use a larger mesh size"
        )
    axes = [origin[k] + (np.arange(counts[k]) + 0.5) * mesh_size for k in range(d)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, d)
    points = np.zeros((len(grid), 3))
    points[:, :d] = grid
    points = points[shape.contains(points)]
    if len(points) == 0:
        raise InputError(
            f"mesh size {mesh_size} is too coarse: no lattice node falls inside the shape"
        )
    if jitter > 0:
        rng = np.random.default_rng(seed)
        points[:, :d] += rng.uniform(-jitter * mesh_size, jitter * mesh_size, size=(len(points), d))
    volumes = np.full(len(points), mesh_size**d)
    return np.ascontiguousarray(points), volumes


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

    @property
    def measure(self) -> float:
        raise TypeError(
            "the measure of a Union is not known exactly; discretize it and sum volumes"
        )


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

    @property
    def measure(self) -> float:
        raise TypeError(
            "the measure of a Difference is not known exactly; discretize it and sum volumes"
        )


def _same_dimension(shapes: tuple[Shape, ...], name: str) -> None:
    if not shapes:
        raise InputError(f"{name} needs at least one shape")
    dimensions = {s.dimension for s in shapes}
    if len(dimensions) != 1:
        raise InputError(f"{name} mixes 2D and 3D shapes")


@dataclass(frozen=True, eq=False)
class ReferenceShape:
    """A particle shape discretised once, to be placed as many particles (translated, rotated,
    scaled); all of them share one set of bonds in memory.

    Positions are in the shape's local frame: rotation and scale act about its origin.
    Use ``ReferenceShape.from_shape(shape, mesh_size)`` (lattice) or ``from_nodes``.
    """

    positions: NDArray[np.float64]  # (n, 3) [m]
    volumes: NDArray[np.float64]  # (n,) [m^d]
    mesh_size: float  # [m]
    dimension: int

    @staticmethod
    def from_shape(
        shape: Shape, mesh_size: float, *, jitter: float = 0.0, seed: int = 0
    ) -> ReferenceShape:
        positions, volumes = lattice(shape, mesh_size, jitter=jitter, seed=seed)
        return ReferenceShape(positions, volumes, float(mesh_size), shape.dimension)

    @staticmethod
    def from_nodes(
        positions: ArrayLike, volumes: ArrayLike, mesh_size: float, dimension: int
    ) -> ReferenceShape:
        p = np.asarray(positions, dtype=np.float64)
        if p.ndim != 2 or p.shape[1] not in (2, 3):
            raise InputError(f"positions must be an (n, 2) or (n, 3) array, got shape {p.shape}")
        if p.shape[1] == 2:
            p = np.column_stack([p, np.zeros(len(p))])
        v = np.asarray(volumes, dtype=np.float64).reshape(-1)
        if len(v) != len(p):
            raise InputError(f"{len(p)} positions but {len(v)} volumes")
        if dimension not in (2, 3):
            raise InputError(f"dimension must be 2 or 3, got {dimension}")
        return ReferenceShape(np.ascontiguousarray(p), v, float(mesh_size), dimension)

    @property
    def node_count(self) -> int:
        return len(self.volumes)


def rotation_matrix(rotation: float | ArrayLike | None, dimension: int) -> NDArray[np.float64]:
    """3 x 3 rotation: an angle [rad] about z (2D or 3D), a rotation vector (axis times angle,
    3D) or a 3 x 3 matrix (3D, checked to be a rotation)."""
    if rotation is None:
        return np.eye(3)
    array = np.asarray(rotation, dtype=np.float64)
    if array.ndim == 0:
        c, s = np.cos(float(array)), np.sin(float(array))
        return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    if dimension == 2:
        raise InputError("in 2D, rotation is an angle in radians")
    if array.shape == (3,):
        angle = float(np.linalg.norm(array))
        if angle == 0:
            return np.eye(3)
        k = array / angle
        K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
        return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K
    if array.shape == (3, 3):
        if not (np.allclose(array @ array.T, np.eye(3), atol=1e-9) and np.linalg.det(array) > 0):
            raise InputError("rotation matrix must be orthogonal with determinant +1")
        return array
    raise InputError(
        f"rotation must be an angle, a rotation vector or a 3x3 matrix, got {rotation!r}"
    )
