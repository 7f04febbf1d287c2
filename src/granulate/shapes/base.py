"""The Shape interface (contains, signed_distance, bounds, measure, origin, bounding_radius),
the distance helpers the 2D and 3D shapes share, and rotation_matrix."""

from __future__ import annotations

from abc import ABC, abstractmethod

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


def _box_distance(
    p: NDArray[np.float64], lower: ArrayLike, upper: ArrayLike
) -> NDArray[np.float64]:
    """Signed distance to an axis-aligned box (any dimension)."""
    lo, hi = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    q = np.abs(p - 0.5 * (lo + hi)) - 0.5 * (hi - lo)
    outside = np.linalg.norm(np.maximum(q, 0.0), axis=1)
    return outside + np.minimum(q.max(axis=1), 0.0)


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
