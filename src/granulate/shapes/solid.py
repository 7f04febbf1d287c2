"""3D shapes: Box, Sphere, Ellipsoid, Cylinder (closed triangle surfaces are
granulate.meshes.SurfaceMesh)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from granulate.errors import InputError
from granulate.input_errors import checked_arguments
from granulate.shapes.base import (
    Shape,
    _box_distance,
    _ellipsoid_distance,
    _points,
    _vector,
    rotation_matrix,
)


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
