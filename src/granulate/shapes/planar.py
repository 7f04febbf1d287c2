"""2D shapes: Rectangle, Disc, Ellipse, Polygon (any simple polygon, concave allowed),
RegularPolygon, Star, Drum2D (PeriDEM's drum)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from granulate.errors import InputError
from granulate.input_errors import checked_arguments
from granulate.shapes.base import Shape, _box_distance, _ellipsoid_distance, _points, _vector

#: The most vertices of a polygon built from a count (RegularPolygon, Star): every contains()
#: and signed_distance() call visits each edge.
MOST_VERTICES = 100_000


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
