"""Shapes: bodies to discretize, containers to pack, regions to select nodes with.

Every shape answers ``contains(points)`` and ``signed_distance(points)`` (negative inside,
positive outside, zero on the surface [m]) for an (n, 3) array of points (2D shapes ignore z),
knows its bounding box (``bounds()``), its ``bounding_radius`` about its origin point and its
exact ``measure`` (area in 2D, volume in 3D).

2D: Rectangle, Disc, Ellipse, Polygon (any simple polygon, concave allowed), RegularPolygon,
Star, Drum2D (PeriDEM's drum). 3D: Box, Sphere, Ellipsoid, Cylinder, and closed triangle
surfaces (``granulate.meshes.SurfaceMesh``, from STL/OBJ/PLY). Union and Difference combine
shapes of one dimension.

``lattice(shape, h)`` fills a shape with nodes of a uniform lattice of spacing h, each carrying
the volume h^d of its cell; ``conforming(shape, h)`` puts nodes on rings (shells) that follow a
disc's, sphere's, ellipse's or ellipsoid's surface, so its boundary is smooth rather than a
staircase.
"""

from __future__ import annotations

import functools
from abc import ABC, abstractmethod
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from granulate import resources
from granulate.errors import InputError
from granulate.input_errors import checked_arguments


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

    @abstractmethod
    def signed_distance(self, points: ArrayLike) -> NDArray[np.float64]:
        """Distance of each of the (n, 3) points to the surface [m]: negative inside.

        Exact for every primitive; for Union and Difference it is the usual min/max
        combination (exact outside a union, a bound elsewhere; the sign is always right).
        """

    @property
    def origin(self) -> NDArray[np.float64]:
        """The shape's reference point (its centre; for polygons the centroid) [m], 3 numbers.
        A reference shape is discretised about it, and rotated and scaled about it."""
        lower, upper = self.bounds()
        return 0.5 * (lower + upper)

    @property
    def bounding_radius(self) -> float:
        """Radius of a sphere (circle) about ``origin`` that holds the shape [m]."""
        lower, upper = self.bounds()
        d = self.dimension
        return float(0.5 * np.linalg.norm((upper - lower)[:d]))


@checked_arguments
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

    def signed_distance(self, points: ArrayLike) -> NDArray[np.float64]:
        return _box_distance(_points(points)[:, :2], self.lower, self.upper)


def _box_distance(
    p: NDArray[np.float64], lower: ArrayLike, upper: ArrayLike
) -> NDArray[np.float64]:
    """Signed distance to an axis-aligned box (any dimension)."""
    lo, hi = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    q = np.abs(p - 0.5 * (lo + hi)) - 0.5 * (hi - lo)
    outside = np.linalg.norm(np.maximum(q, 0.0), axis=1)
    return outside + np.minimum(q.max(axis=1), 0.0)


@checked_arguments
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

    def signed_distance(self, points: ArrayLike) -> NDArray[np.float64]:
        p = _points(points)
        return np.linalg.norm(p[:, :2] - np.asarray(self.center), axis=1) - self.radius

    @property
    def origin(self) -> NDArray[np.float64]:
        return np.array([*self.center, 0.0])

    @property
    def bounding_radius(self) -> float:
        return float(self.radius)


@checked_arguments
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

    def signed_distance(self, points: ArrayLike) -> NDArray[np.float64]:
        p = _points(points)
        distance = _distance_to_segments(p[:, :2], np.asarray(self.vertices, dtype=float))
        return np.where(self.contains(p), -distance, distance)

    @property
    def origin(self) -> NDArray[np.float64]:
        """The centroid of the polygon's area."""
        v = np.asarray(self.vertices, dtype=float)
        x, y = v[:, 0], v[:, 1]
        cross = x * np.roll(y, -1) - np.roll(x, -1) * y
        area = 0.5 * np.sum(cross)
        cx = np.sum((x + np.roll(x, -1)) * cross) / (6 * area)
        cy = np.sum((y + np.roll(y, -1)) * cross) / (6 * area)
        return np.array([cx, cy, 0.0])

    @property
    def bounding_radius(self) -> float:
        v = np.asarray(self.vertices, dtype=float)
        return float(np.max(np.linalg.norm(v - self.origin[:2], axis=1)))


def _distance_to_segments(
    p: NDArray[np.float64], vertices: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Distance of 2D points (n, 2) to the closed polyline through ``vertices`` (m, 2)."""
    a = vertices
    b = np.roll(vertices, -1, axis=0)
    best = np.full(len(p), np.inf)
    for start, end in zip(a, b, strict=True):
        edge = end - start
        t = np.clip(((p - start) @ edge) / (edge @ edge), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(p - (start + t[:, None] * edge), axis=1))
    return best


def _regular_vertices(
    center: ArrayLike, radius: float, sides: int, angle: float
) -> tuple[tuple[float, float], ...]:
    c = np.asarray(center, dtype=float)
    phi = angle + 2 * np.pi * np.arange(sides) / sides
    return tuple((float(c[0] + radius * np.cos(f)), float(c[1] + radius * np.sin(f))) for f in phi)


class _CentredPolygon(Polygon):
    """A polygon generated from a few parameters about a centre: it keeps them (for repr and
    YAML round trips), and its origin is the centre; ``_extent`` names the parameter that is
    its bounding radius."""

    _extent = "radius"

    def _keep(self, **parameters: object) -> None:
        for name, value in parameters.items():
            object.__setattr__(self, name, value)
        object.__setattr__(self, "_parameters", tuple(parameters))

    def __repr__(self) -> str:
        values = ", ".join(f"{name}={getattr(self, name)!r}" for name in self._parameters)  # type: ignore[attr-defined]
        return f"{type(self).__name__}({values})"

    @property
    def origin(self) -> NDArray[np.float64]:
        return np.array([*self.center, 0.0])  # type: ignore[attr-defined]

    @property
    def bounding_radius(self) -> float:
        return float(getattr(self, self._extent))


@checked_arguments
class RegularPolygon(_CentredPolygon):
    """Regular polygon with ``sides`` vertices on a circle of ``radius`` (circumradius) about
    ``center`` [m], the first vertex at ``angle`` [rad] from the x axis (PeriDEM's triangle,
    square and hexagon are 3, 4 and 6 sides with the first vertex on the axis)."""

    def __init__(
        self, center: tuple[float, float], radius: float, sides: int, angle: float = 0.0
    ) -> None:
        _vector(center, 2, "RegularPolygon center")
        if not (isinstance(sides, int | np.integer) and 3 <= sides <= MOST_VERTICES):
            raise InputError(
                f"RegularPolygon needs an integer number of sides from 3 to {MOST_VERTICES:,}, "
                f"got {sides!r} (a Disc is a polygon of very many sides)"
            )
        if not (radius > 0 and np.isfinite(radius)):
            raise InputError(f"RegularPolygon radius must be positive, got {radius}")
        super().__init__(_regular_vertices(center, radius, int(sides), angle))
        self._keep(
            center=tuple(float(c) for c in center),
            radius=float(radius),
            sides=int(sides),
            angle=float(angle),
        )


@checked_arguments
class Star(_CentredPolygon):
    """Star with ``points`` tips on a circle of ``outer_radius`` and the notches between them on
    ``inner_radius`` about ``center`` [m]; the first tip at ``angle`` [rad]."""

    _extent = "outer_radius"

    def __init__(
        self,
        center: tuple[float, float],
        outer_radius: float,
        inner_radius: float,
        points: int = 5,
        angle: float = 0.0,
    ) -> None:
        _vector(center, 2, "Star center")
        if not (isinstance(points, int | np.integer) and 3 <= points <= MOST_VERTICES // 2):
            raise InputError(
                f"Star needs an integer number of points from 3 to {MOST_VERTICES // 2:,}, got "
                f"{points!r}"
            )
        if not (0 < inner_radius < outer_radius and np.isfinite(outer_radius)):
            raise InputError(
                f"Star needs 0 < inner_radius < outer_radius, got {inner_radius}, {outer_radius}"
            )
        tips = _regular_vertices(center, outer_radius, int(points), angle)
        notches = _regular_vertices(center, inner_radius, int(points), angle + np.pi / points)
        super().__init__(tuple(v for pair in zip(tips, notches, strict=True) for v in pair))
        self._keep(
            center=tuple(float(c) for c in center),
            outer_radius=float(outer_radius),
            inner_radius=float(inner_radius),
            points=int(points),
            angle=float(angle),
        )


@checked_arguments
class Drum2D(_CentredPolygon):
    """PeriDEM's drum: a hexagon of circumradius ``radius`` about ``center`` [m] whose two
    vertices on the axis (at ``angle`` [rad] from x) are pulled in to ``neck_half_width``. The
    vertices are c + w a, c + r R(60 deg) a, then that point - r a, c - w a, and their mirror
    images (Jha et al. 2021, PeriDEM's drum2d)."""

    def __init__(
        self, center: tuple[float, float], radius: float, neck_half_width: float, angle: float = 0.0
    ) -> None:
        c = _vector(center, 2, "Drum2D center")
        if not (0 < neck_half_width < radius and np.isfinite(radius)):
            raise InputError(
                f"Drum2D needs 0 < neck_half_width < radius, got {neck_half_width}, {radius}"
            )
        a = np.array([np.cos(angle), np.sin(angle)])
        up = np.array([-a[1], a[0]])
        half = np.sqrt(3.0) / 2
        vertices = [
            c + neck_half_width * a,
            c + radius * (0.5 * a + half * up),
            c + radius * (-0.5 * a + half * up),
            c - neck_half_width * a,
            c + radius * (-0.5 * a - half * up),
            c + radius * (0.5 * a - half * up),
        ]
        super().__init__(tuple((float(v[0]), float(v[1])) for v in vertices))
        self._keep(
            center=(float(c[0]), float(c[1])),
            radius=float(radius),
            neck_half_width=float(neck_half_width),
            angle=float(angle),
        )


def _ellipsoid_distance(q: NDArray[np.float64], axes: NDArray[np.float64]) -> NDArray[np.float64]:
    """Signed distance of points q (n, d), in the frame of the ellipsoid's axes, to the
    ellipsoid sum (x_k / a_k)^2 = 1. The closest point is x_k = a_k^2 q_k / (a_k^2 + t) with t
    the root of sum (a_k q_k / (a_k^2 + t))^2 = 1 in (-min a_k^2, inf), found by bisection (the
    function decreases there). Coordinates are nudged off zero by 1e-12 a_k, which keeps the
    root in that interval and moves the distance by at most as much."""
    p = np.maximum(np.abs(q), 1e-12 * axes)
    a2 = axes**2
    low = np.full(len(p), -np.min(a2) * (1 - 1e-15))
    high = np.full(len(p), float(np.max(axes) * np.max(np.linalg.norm(p, axis=1)) + np.max(a2)))
    for _ in range(200):
        middle = 0.5 * (low + high)
        value = np.sum((axes * p / (a2 + middle[:, None])) ** 2, axis=1) - 1
        positive = value > 0
        low = np.where(positive, middle, low)
        high = np.where(positive, high, middle)
    t = 0.5 * (low + high)
    closest = a2 * p / (a2 + t[:, None])
    distance = np.linalg.norm(p - closest, axis=1)
    inside = np.sum((q / axes) ** 2, axis=1) <= 1
    return np.where(inside, -distance, distance)


@checked_arguments
@dataclass(frozen=True)
class Ellipse(Shape):
    """Ellipse of a centre (x, y), semi-axes (a, b) [m] and the angle [rad] of its a axis."""

    center: tuple[float, float]
    semi_axes: tuple[float, float]
    angle: float = 0.0
    dimension: int = field(default=2, init=False)

    def __post_init__(self) -> None:
        _vector(self.center, 2, "Ellipse center")
        axes = _vector(self.semi_axes, 2, "Ellipse semi_axes")
        if np.any(axes <= 0):
            raise InputError(f"Ellipse semi_axes must be positive, got {self.semi_axes}")

    def _local(self, points: ArrayLike) -> NDArray[np.float64]:
        p = _points(points)[:, :2] - np.asarray(self.center)
        c, s = np.cos(self.angle), np.sin(self.angle)
        return np.column_stack([c * p[:, 0] + s * p[:, 1], -s * p[:, 0] + c * p[:, 1]])

    def contains(self, points: ArrayLike) -> NDArray[np.bool_]:
        q = self._local(points)
        return np.sum((q / np.asarray(self.semi_axes)) ** 2, axis=1) <= 1

    def signed_distance(self, points: ArrayLike) -> NDArray[np.float64]:
        return _ellipsoid_distance(self._local(points), np.asarray(self.semi_axes, dtype=float))

    def bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        a, b = self.semi_axes
        c, s = np.cos(self.angle), np.sin(self.angle)
        half = np.array([np.hypot(a * c, b * s), np.hypot(a * s, b * c)])
        center = np.asarray(self.center, dtype=float)
        return np.array([*(center - half), 0.0]), np.array([*(center + half), 0.0])

    @property
    def measure(self) -> float:
        return float(np.pi * self.semi_axes[0] * self.semi_axes[1])

    @property
    def origin(self) -> NDArray[np.float64]:
        return np.array([*self.center, 0.0])

    @property
    def bounding_radius(self) -> float:
        return float(max(self.semi_axes))


@checked_arguments
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

    def signed_distance(self, points: ArrayLike) -> NDArray[np.float64]:
        return _box_distance(_points(points), self.lower, self.upper)


@checked_arguments
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

    def signed_distance(self, points: ArrayLike) -> NDArray[np.float64]:
        return np.linalg.norm(_points(points) - np.asarray(self.center), axis=1) - self.radius

    @property
    def origin(self) -> NDArray[np.float64]:
        return np.asarray(self.center, dtype=float)

    @property
    def bounding_radius(self) -> float:
        return float(self.radius)


@checked_arguments
@dataclass(frozen=True)
class Ellipsoid(Shape):
    """Ellipsoid of a centre, semi-axes (a, b, c) [m] and a rotation of its axes (a rotation
    vector [rad] or a 3 x 3 matrix; see ``rotation_matrix``)."""

    center: tuple[float, float, float]
    semi_axes: tuple[float, float, float]
    rotation: ArrayLike | None = None
    dimension: int = field(default=3, init=False)

    def __post_init__(self) -> None:
        _vector(self.center, 3, "Ellipsoid center")
        axes = _vector(self.semi_axes, 3, "Ellipsoid semi_axes")
        if np.any(axes <= 0):
            raise InputError(f"Ellipsoid semi_axes must be positive, got {self.semi_axes}")
        if self.rotation is not None and np.ndim(self.rotation) == 0:
            raise InputError("Ellipsoid rotation is a rotation vector or a 3x3 matrix")
        rotation_matrix(self.rotation, 3)

    def _local(self, points: ArrayLike) -> NDArray[np.float64]:
        return (_points(points) - np.asarray(self.center)) @ rotation_matrix(self.rotation, 3)

    def contains(self, points: ArrayLike) -> NDArray[np.bool_]:
        return np.sum((self._local(points) / np.asarray(self.semi_axes)) ** 2, axis=1) <= 1

    def signed_distance(self, points: ArrayLike) -> NDArray[np.float64]:
        return _ellipsoid_distance(self._local(points), np.asarray(self.semi_axes, dtype=float))

    def bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        matrix = rotation_matrix(self.rotation, 3)
        half = np.sqrt((matrix**2) @ np.asarray(self.semi_axes, dtype=float) ** 2)
        center = np.asarray(self.center, dtype=float)
        return center - half, center + half

    @property
    def measure(self) -> float:
        return float(4.0 / 3.0 * np.pi * np.prod(self.semi_axes))

    @property
    def origin(self) -> NDArray[np.float64]:
        return np.asarray(self.center, dtype=float)

    @property
    def bounding_radius(self) -> float:
        return float(max(self.semi_axes))


@checked_arguments
@dataclass(frozen=True)
class Cylinder(Shape):
    """Solid cylinder of a centre (mid-point of its axis), unit ``axis`` direction, radius and
    length [m]."""

    center: tuple[float, float, float]
    radius: float
    length: float
    axis: tuple[float, float, float] = (0.0, 0.0, 1.0)
    dimension: int = field(default=3, init=False)

    def __post_init__(self) -> None:
        _vector(self.center, 3, "Cylinder center")
        axis = _vector(self.axis, 3, "Cylinder axis")
        if not np.linalg.norm(axis) > 0:
            raise InputError("Cylinder axis must be a non-zero vector")
        if not (self.radius > 0 and self.length > 0):
            raise InputError(
                f"Cylinder radius and length must be positive, got {self.radius}, {self.length}"
            )

    def _axial_radial(self, points: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        axis = np.asarray(self.axis, dtype=float)
        axis = axis / np.linalg.norm(axis)
        p = _points(points) - np.asarray(self.center)
        axial = p @ axis
        radial = np.linalg.norm(p - axial[:, None] * axis, axis=1)
        return axial, radial

    def contains(self, points: ArrayLike) -> NDArray[np.bool_]:
        axial, radial = self._axial_radial(points)
        return (np.abs(axial) <= 0.5 * self.length) & (radial <= self.radius)

    def signed_distance(self, points: ArrayLike) -> NDArray[np.float64]:
        axial, radial = self._axial_radial(points)
        q = np.column_stack([radial - self.radius, np.abs(axial) - 0.5 * self.length])
        return np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(q.max(axis=1), 0.0)

    def bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        axis = np.asarray(self.axis, dtype=float)
        axis = axis / np.linalg.norm(axis)
        half = 0.5 * self.length * np.abs(axis) + self.radius * np.sqrt(
            np.clip(1 - axis**2, 0.0, 1.0)
        )
        center = np.asarray(self.center, dtype=float)
        return center - half, center + half

    @property
    def measure(self) -> float:
        return float(np.pi * self.radius**2 * self.length)

    @property
    def origin(self) -> NDArray[np.float64]:
        return np.asarray(self.center, dtype=float)

    @property
    def bounding_radius(self) -> float:
        return float(np.hypot(self.radius, 0.5 * self.length))


#: The most vertices of a polygon built from a count (RegularPolygon, Star): every contains()
#: and signed_distance() call visits each edge.
MOST_VERTICES = 100_000


def _require_nodes(nodes: float, mesh_size: float, kind: str) -> None:
    """InputError before a discretisation of about `nodes` nodes (or candidate points) is
    generated, when the simulation of those nodes would not fit in memory."""
    resources.require_memory(
        resources.BYTES_PER_NODE * nodes,
        f"a {kind} of about {nodes:.3g} nodes (mesh size {mesh_size:.4g} m)",
        "use a larger mesh size",
    )


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
    # The nodes are at most the cells (the measure would do better, but a union's costs a
    # count on a grid).
    _require_nodes(float(np.prod(counts.astype(float))), mesh_size, "lattice")
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


def grid(shape: Shape, mesh_size: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Nodes at the vertices of a uniform grid over a Rectangle or Box, boundary included, with
    the nodal volumes of bilinear (trilinear) finite elements: each cell gives 1/2^d of its
    measure to each of its corners (a corner node of the rectangle carries h^2/4, an edge node
    h^2/2). The grid has n_k = round(L_k / h) cells along axis k, of size L_k / n_k. This is
    PeriDEM's built-in uniform mesh (``CreateMesh: {Flag: true, Info: uniform}``).

    Returns (positions (n, 3) [m], volumes (n,) [m^d]).
    """
    if not isinstance(shape, Rectangle | Box):
        raise InputError(
            f"grid discretization is available for Rectangle and Box, not {type(shape).__name__}; "
            "use the lattice, or import a mesh"
        )
    if not (mesh_size > 0 and np.isfinite(mesh_size)):
        raise InputError(f"mesh size must be positive, got {mesh_size}")
    d = shape.dimension
    lower = np.asarray(shape.lower, dtype=float)[:d]
    upper = np.asarray(shape.upper, dtype=float)[:d]
    cells = np.maximum(1, np.round((upper - lower) / mesh_size).astype(np.int64))
    nodes = float(np.prod((cells + 1).astype(float)))
    _require_nodes(nodes, mesh_size, "grid")
    axes = [np.linspace(lower[k], upper[k], cells[k] + 1) for k in range(d)]
    spacing = (upper - lower) / cells
    shares = []
    for k in range(d):
        w = np.full(cells[k] + 1, spacing[k])
        w[[0, -1]] *= 0.5
        shares.append(w)
    points = np.zeros((int(np.prod(cells + 1)), 3))
    points[:, :d] = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, d)
    volumes = np.ones(1)
    for w in shares:
        volumes = np.multiply.outer(volumes, w)
    return points, volumes.reshape(-1)


def grid_surface(shape: Rectangle | Box, positions: NDArray[np.float64]) -> NDArray[np.float64]:
    """The surface offsets of ``grid(shape, h)``'s nodes (see ReferenceShape.surface): -1 or +1
    along each axis where a node lies on the lower or upper face, zero inside."""
    d = shape.dimension
    lower = np.asarray(shape.lower, dtype=float)[:d]
    upper = np.asarray(shape.upper, dtype=float)[:d]
    tolerance = 1e-9 * float(np.max(upper - lower))
    offsets = np.zeros((len(positions), 3))
    p = positions[:, :d]
    offsets[:, :d] = (np.abs(p - upper) <= tolerance).astype(float) - (
        np.abs(p - lower) <= tolerance
    ).astype(float)
    return offsets


def outer_layer(
    shape: Shape, positions: NDArray[np.float64], mesh_size: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Where contact finds the surface above a lattice's or conforming discretisation's outer
    nodes (see ReferenceShape.surface): for each node less than one mesh size h deep, the unit
    outward normal n = grad phi of the shape's signed distance phi (central differences over
    h/1000) and its depth -phi; zero for the nodes deeper in (and for the rare node where the
    gradient is not a unit vector: on the medial axis of a thin part). A rotated lattice's
    outer nodes lie from 0 to h below its faces; contact puts each one's surface point at
    x + depth n, on the shape's true surface.

    Returns (offsets (n, 3), depths (n,) [m])."""
    d = shape.dimension
    depths = -shape.signed_distance(positions)
    near = np.flatnonzero(depths < mesh_size)
    step = 1e-3 * mesh_size
    gradient = np.zeros((len(near), 3))
    for k in range(d):
        shift = np.zeros(3)
        shift[k] = step
        p = positions[near]
        gradient[:, k] = (shape.signed_distance(p + shift) - shape.signed_distance(p - shift)) / (
            2 * step
        )
    length = np.linalg.norm(gradient, axis=1)
    unit = np.abs(length - 1) < 0.05
    offsets = np.zeros((len(positions), 3))
    offsets[near[unit]] = gradient[unit] / length[unit, None]
    layer = np.zeros(len(positions))
    layer[near[unit]] = np.clip(depths[near[unit]], 0.0, mesh_size)
    return offsets, layer


def conforming(shape: Shape, mesh_size: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Nodes on rings (2D) or shells (3D) that follow the surface of a Disc, Ellipse, Sphere or
    Ellipsoid, so the particle's surface is smooth instead of a lattice staircase (this matters
    for oblique contacts: a staircase passes tangential impulse even without friction).

    m = round(R / h) rings of radius (k + 1/2) R / m, k = 0 .. m-1, each with
    round(2 pi r / h) nodes at equal angles (shells: round(4 pi r^2 / h^2) nodes on a Fibonacci
    lattice); each node carries an equal share of its ring's (shell's) exact area (volume), so
    the volumes sum to the exact measure. Ellipses and ellipsoids are the unit disc or sphere
    stretched by their semi-axes (an affine map keeps the shares equal). The outermost nodes lie
    h/2 inside the surface, as a lattice's do.

    Returns (positions (n, 3) [m], volumes (n,) [m^d]).
    """
    if not (mesh_size > 0 and np.isfinite(mesh_size)):
        raise InputError(f"mesh size must be positive, got {mesh_size}")
    nodes = (
        shape.measure / mesh_size**shape.dimension
        if isinstance(shape, Disc | Ellipse | Sphere | Ellipsoid)
        else 0.0
    )
    _require_nodes(nodes, mesh_size, "conforming discretisation")
    if isinstance(shape, Disc | Ellipse):
        axes = (
            np.array([shape.radius, shape.radius])
            if isinstance(shape, Disc)
            else np.asarray(shape.semi_axes, dtype=float)
        )
        angle = shape.angle if isinstance(shape, Ellipse) else 0.0
        rings = _rings(float(axes.max()) / mesh_size, 2)
        local = np.array([[x * axes[0], y * axes[1], 0.0] for x, y, _ in rings[0]])
        c, s = np.cos(angle), np.sin(angle)
        turn = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        positions = local @ turn.T + shape.origin
        volumes = rings[1] * float(np.prod(axes))
    elif isinstance(shape, Sphere | Ellipsoid):
        axes = (
            np.full(3, shape.radius)
            if isinstance(shape, Sphere)
            else np.asarray(shape.semi_axes, dtype=float)
        )
        rotation = rotation_matrix(shape.rotation if isinstance(shape, Ellipsoid) else None, 3)
        rings = _rings(float(axes.max()) / mesh_size, 3)
        positions = (rings[0] * axes) @ rotation.T + shape.origin
        volumes = rings[1] * float(np.prod(axes))
    else:
        raise InputError(
            f"conforming discretization is available for Disc, Ellipse, Sphere and Ellipsoid, "
            f"not {type(shape).__name__}; use the lattice, or import a mesh"
        )
    return np.ascontiguousarray(positions), volumes


def _rings(resolution: float, dimension: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Nodes of the unit disc (sphere) on m = round(resolution) rings (shells) and their
    volumes (summing to pi, or 4 pi / 3)."""
    m = max(1, round(resolution))
    spacing = 1.0 / m
    points: list[NDArray[np.float64]] = []
    volumes: list[NDArray[np.float64]] = []
    for k in range(m):
        radius = (k + 0.5) * spacing
        inner, outer = k * spacing, (k + 1) * spacing
        if dimension == 2:
            count = max(3, round(2 * np.pi * radius / spacing))
            phi = 0.5 * k + 2 * np.pi * np.arange(count) / count
            ring = np.column_stack([np.cos(phi), np.sin(phi), np.zeros(count)])
            share = np.pi * (outer**2 - inner**2) / count
        else:
            count = max(4, round(4 * np.pi * radius**2 / spacing**2))
            # Fibonacci lattice: nearly equal areas, no poles; turned per shell to stagger.
            index = np.arange(count) + 0.5
            z = 1 - 2 * index / count
            phi = np.pi * (3 - np.sqrt(5)) * index + 0.5 * k
            rho = np.sqrt(1 - z * z)
            ring = np.column_stack([rho * np.cos(phi), rho * np.sin(phi), z])
            share = 4.0 / 3.0 * np.pi * (outer**3 - inner**3) / count
        points.append(radius * ring)
        volumes.append(np.full(count, share))
    return np.concatenate(points), np.concatenate(volumes)


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


@dataclass(frozen=True, eq=False)
class ReferenceShape:
    """A particle shape discretised once, to be placed as many particles (translated, rotated,
    scaled); all of them share one set of bonds in memory.

    Positions are in the shape's local frame: rotation and scale act about its origin (0, 0, 0).
    Use ``ReferenceShape.from_shape(shape, mesh_size)`` (lattice or conforming rings),
    ``from_mesh(path)`` (gmsh, VTU, CSV) or ``from_nodes``.
    """

    positions: NDArray[np.float64]  # (n, 3) [m]
    volumes: NDArray[np.float64]  # (n,) [m^d]
    mesh_size: float  # [m]
    dimension: int
    #: (n, 3) the offsets o of the nodes on the surface (a mesh's or grid's boundary vertices;
    #: n . o = 1 for each face normal n at the node, zero inside), or None where no node lies on
    #: it (a lattice's or conforming discretisation's outer nodes lie below it: see
    #: outer_layer_of; a mesh without elements does not tell). Contact centres the spheres of
    #: these nodes at x - rho o (rho: their contact radius), so that they reach the surface.
    surface: NDArray[np.float64] | None = None
    #: The shape a lattice or conforming discretisation was made from (and the shift of its
    #: origin), for the surface law's outer layer (outer_layer_of).
    source: Shape | None = None
    source_shift: tuple[float, float, float] = (0.0, 0.0, 0.0)

    @functools.cached_property
    def outer_layer_of(self) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
        """The surface law's view of a lattice's or conforming discretisation's outer layer
        (see outer_layer): the unit normals (n, 3) and depths (n,) [m] of its nodes less than h
        deep; None for a mesh or grid (their boundary vertices carry ``surface``). Computed on
        first use: the node-sphere law does not need it."""
        if self.source is None:
            return None
        shifted = self.positions + np.asarray(self.source_shift)
        return outer_layer(self.source, shifted, self.mesh_size)

    @staticmethod
    def from_shape(
        shape: Shape,
        mesh_size: float,
        *,
        discretization: str = "lattice",
        jitter: float = 0.0,
        seed: int = 0,
        centered: bool = False,
    ) -> ReferenceShape:
        """Discretize a shape: ``discretization`` "lattice" (any shape; optional jitter),
        "conforming" (rings or shells following the surface: Disc, Ellipse, Sphere, Ellipsoid)
        or "grid" (grid vertices with finite-element volumes: Rectangle, Box).
        ``centered``: move the shape's ``origin`` (centre or centroid) to (0, 0, 0), so that
        rotations and scales act about it."""
        surface, source = None, None
        if discretization == "lattice":
            positions, volumes = lattice(shape, mesh_size, jitter=jitter, seed=seed)
            source = shape
        elif discretization in ("conforming", "grid"):
            if jitter:
                raise InputError("jitter applies to the lattice discretization only")
            make = conforming if discretization == "conforming" else grid
            positions, volumes = make(shape, mesh_size)
            if discretization == "grid":
                surface = grid_surface(shape, positions)
            else:
                source = shape
        else:
            raise InputError(
                f"unknown discretization {discretization!r}; choose 'lattice', 'conforming' or "
                "'grid'"
            )
        shift = (0.0, 0.0, 0.0)
        if centered:
            positions = positions - shape.origin
            shift = tuple(float(c) for c in shape.origin)
        return ReferenceShape(
            positions, volumes, float(mesh_size), shape.dimension, surface, source, shift
        )

    @staticmethod
    def from_mesh(
        path: str,
        *,
        dimension: int | None = None,
        mesh_size: float | None = None,
        center: ArrayLike | None = None,
    ) -> ReferenceShape:
        """Nodes of a mesh made elsewhere: gmsh .msh (v2 or v4; triangles, quads, tetrahedra,
        hexahedra), .vtu (with a point field 'volume' or elements) or a CSV of points with
        volumes. Nodal volume = equal share of each element's measure (see granulate.meshes).
        ``mesh_size`` defaults to the median edge length; ``center`` [m] is moved to the origin
        of the local frame (e.g. the centre of a particle meshed off the origin)."""
        from granulate.meshes import read_mesh

        mesh = read_mesh(path, dimension=dimension)
        positions = mesh.positions
        if center is not None:
            c = np.zeros(3)
            given = np.asarray(center, dtype=float).reshape(-1)
            c[: len(given)] = given
            positions = positions - c
        h = mesh.mesh_size if mesh_size is None else float(mesh_size)
        if not (h > 0 and np.isfinite(h)):
            raise InputError(f"mesh size must be positive, got {mesh_size}")
        return ReferenceShape(
            np.ascontiguousarray(positions), mesh.volumes, h, mesh.dimension, mesh.surface
        )

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
