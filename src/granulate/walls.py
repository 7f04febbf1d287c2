"""Rigid walls: surfaces that particles cannot cross, fixed or moved by a time function.

A wall is one or more surfaces moving together (``Wall(surfaces, motion=...)``). Surfaces:

===========================  ===================================================================
``Plane(point, normal)``     a half-space boundary; particles on the side the normal points to
``BoxContainer(lo, hi)``     particles inside an axis-aligned box
``BoxObstacle(lo, hi)``      particles outside a box
``CircleContainer(c, r)``    particles inside a circle (2D) or cylinder (3D, ``axis``)
``CircleObstacle(c, r)``     particles outside a circle or cylinder (posts, rollers)
``PolygonContainer(v)``      particles inside a 2D polygon (concave allowed)
``PolygonObstacle(v)``       particles outside a 2D polygon (lifters, blades)
``TriangleMesh(v, t)``       a 3D triangle surface (``TriangleMesh.from_file`` reads STL/OBJ/PLY);
                             particles inside a closed mesh with outward normals (``inside``) or
                             outside it
===========================  ===================================================================

``container(shape)`` and ``obstacle(shape)`` make the surface of a shape from granulate.shapes:
Rectangle and Box become boxes, Disc a circle, every polygon (RegularPolygon, Star, Drum2D, ...)
a polygon, an Ellipse a polygon of ``segments`` sides, a SurfaceMesh a triangle mesh.

Motions: ``Translation(direction, function)`` moves the wall by function(t) metres along the
direction; ``Rotation(angle, center, axis)`` turns it by angle(t) radians about the axis
through ``center`` (``Rotation.steady(omega, center)`` for a constant angular velocity). The
force and torque (about ``center``, or the origin) that the particles exert on each wall are
recorded in history.csv.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from granulate import _core
from granulate.contact import Contact
from granulate.errors import InputError
from granulate.functions import Constant, Linear, TimeFunction
from granulate.input_errors import checked_arguments
from granulate.meshes import SurfaceMesh, read_file
from granulate.shapes import Box, Disc, Ellipse, Polygon, Rectangle, Shape


def _vec3(
    value: ArrayLike, name: str, dimension: int, axis: bool = False
) -> tuple[float, float, float]:
    """A point or direction of a wall as three numbers: 3 given in 3D; 2, or 3 with z = 0, in
    2D (an axis may be z itself)."""
    array = np.asarray(value, dtype=float).reshape(-1)
    if array.shape not in ((2,), (3,)) or not np.all(np.isfinite(array)):
        raise InputError(f"{name} must be 2 or 3 finite numbers, got {value!r}")
    if dimension == 3 and len(array) != 3:
        raise InputError(f"{name} {array.tolist()} needs 3 components in a 3D simulation")
    z_axis = axis and len(array) == 3 and not np.any(array[:2])
    if dimension == 2 and len(array) == 3 and array[2] != 0 and not z_axis:
        raise InputError(f"{name} {array.tolist()} has a z component in a 2D simulation")
    return (float(array[0]), float(array[1]), float(array[2]) if len(array) == 3 else 0.0)


class Surface:
    """Base class of wall surfaces."""

    def core(self, dimension: int) -> _core.WallSurface:
        raise TypeError(f"{type(self).__name__} is not a concrete surface")


@checked_arguments
@dataclass(frozen=True)
class Plane(Surface):
    point: ArrayLike
    normal: ArrayLike

    def core(self, dimension: int) -> _core.WallSurface:
        s = _core.WallSurface()
        s.kind = _core.WallSurfaceKind.plane
        s.point, s.normal = (
            _vec3(self.point, "plane point", dimension),
            _vec3(self.normal, "plane normal", dimension),
        )
        return s


@dataclass(frozen=True)
class _Box(Surface):
    lower: ArrayLike
    upper: ArrayLike
    inside: bool = field(default=True, init=False)

    def core(self, dimension: int) -> _core.WallSurface:
        s = _core.WallSurface()
        s.kind = (
            _core.WallSurfaceKind.box_inside if self.inside else _core.WallSurfaceKind.box_outside
        )
        s.lower, s.upper = (
            _vec3(self.lower, "box lower", dimension),
            _vec3(self.upper, "box upper", dimension),
        )
        return s


@checked_arguments
@dataclass(frozen=True)
class BoxContainer(_Box):
    """Particles inside the box [lower, upper]."""


@checked_arguments
@dataclass(frozen=True)
class BoxObstacle(_Box):
    """Particles outside the box [lower, upper]."""

    inside: bool = field(default=False, init=False)


@dataclass(frozen=True)
class _Circle(Surface):
    center: ArrayLike
    radius: float
    axis: ArrayLike = (0.0, 0.0, 1.0)
    inside: bool = field(default=True, init=False)

    def core(self, dimension: int) -> _core.WallSurface:
        s = _core.WallSurface()
        s.kind = (
            _core.WallSurfaceKind.circle_inside
            if self.inside
            else _core.WallSurfaceKind.circle_outside
        )
        s.point, s.normal = (
            _vec3(self.center, "circle center", dimension),
            _vec3(self.axis, "cylinder axis", dimension, axis=True),
        )
        s.radius = float(self.radius)
        return s


@checked_arguments
@dataclass(frozen=True)
class CircleContainer(_Circle):
    """Particles inside a circle (2D) or an infinite cylinder along ``axis`` (3D)."""


@checked_arguments
@dataclass(frozen=True)
class CircleObstacle(_Circle):
    """Particles outside a circle (2D) or an infinite cylinder along ``axis`` (3D)."""

    inside: bool = field(default=False, init=False)


@dataclass(frozen=True)
class _Polygon(Surface):
    vertices: ArrayLike
    inside: bool = field(default=True, init=False)

    def core(self, dimension: int) -> _core.WallSurface:
        v = np.asarray(self.vertices, dtype=float)
        if v.ndim != 2 or v.shape[1] != 2 or len(v) < 3 or not np.all(np.isfinite(v)):
            raise InputError("a polygon wall needs at least 3 finite (x, y) vertices")
        s = _core.WallSurface()
        s.kind = _core.WallSurfaceKind.polygon
        s.vertices = [(float(x), float(y)) for x, y in v]
        s.inside = self.inside
        return s


@checked_arguments
@dataclass(frozen=True)
class PolygonContainer(_Polygon):
    """Particles inside a 2D polygon."""


@checked_arguments
@dataclass(frozen=True)
class PolygonObstacle(_Polygon):
    """Particles outside a 2D polygon."""

    inside: bool = field(default=False, init=False)


@checked_arguments
@dataclass(frozen=True, eq=False)
class TriangleMesh(Surface):
    """A triangle surface (3D). ``vertices`` (n, 3) [m], ``triangles`` (m, 3) vertex indices.

    With ``inside=True`` the particles are inside a closed surface whose triangles face outwards
    (right-hand rule, as STL files are written); with ``inside=False`` they are outside it.
    """

    vertices: ArrayLike
    triangles: ArrayLike
    inside: bool = True

    @staticmethod
    def from_file(path: str | Path, *, inside: bool = True, scale: float = 1.0) -> TriangleMesh:
        """Read the triangles of an STL, OBJ, PLY (or any meshio-readable) file; coordinates are
        multiplied by ``scale`` (e.g. 1e-3 for a file in millimetres)."""
        mesh = read_file(path)
        triangles = [block.data for block in mesh.cells if block.type == "triangle"]
        if not triangles:
            raise InputError(f"wall mesh {path} has no triangles")
        return TriangleMesh(
            np.asarray(mesh.points, dtype=float) * scale, np.concatenate(triangles), inside
        )

    def core(self, dimension: int) -> _core.WallSurface:
        vertices = np.asarray(self.vertices, dtype=float)
        triangles = np.asarray(self.triangles)
        if vertices.ndim != 2 or vertices.shape[1] != 3 or not np.all(np.isfinite(vertices)):
            raise InputError("triangle mesh vertices must be an (n, 3) array of finite numbers")
        if triangles.ndim != 2 or triangles.shape[1] != 3 or len(triangles) == 0:
            raise InputError(
                "triangle mesh triangles must be a non-empty (m, 3) array of vertex indices"
            )
        if triangles.min() < 0 or triangles.max() >= len(vertices):
            raise InputError("a triangle refers to a vertex that does not exist")
        s = _core.WallSurface()
        s.kind = _core.WallSurfaceKind.triangles
        s.mesh_vertices = [tuple(map(float, v)) for v in vertices]
        s.mesh_triangles = [tuple(map(int, t)) for t in triangles]
        s.inside = self.inside
        return s


@checked_arguments
@dataclass(frozen=True)
class Translation:
    """x = X + function(t) * direction (direction normalised)."""

    direction: ArrayLike
    function: TimeFunction


@checked_arguments
@dataclass(frozen=True)
class Rotation:
    """Rotation by angle(t) [rad] about ``axis`` through ``center`` (z in 2D)."""

    angle: TimeFunction
    center: ArrayLike = (0.0, 0.0, 0.0)
    axis: ArrayLike = (0.0, 0.0, 1.0)

    @staticmethod
    def steady(
        angular_velocity: float,
        center: ArrayLike = (0.0, 0.0, 0.0),
        axis: ArrayLike = (0.0, 0.0, 1.0),
    ) -> Rotation:
        """Constant angular velocity omega [rad/s]."""
        return Rotation(Linear(angular_velocity), center, axis)


@checked_arguments
@dataclass(frozen=True)
class Wall:
    """Surfaces moving together, with an optional motion and contact parameters.

    ``contact`` defaults to the simulation's contact settings; ``center`` is the torque
    reference point (the rotation centre for rotating walls); ``area``, the wall's nominal
    area [m^2; m in 2D, per unit thickness], makes history.csv record its stress
    ``<name>_stress``, the particles' resultant force on it over that area [Pa].
    """

    surfaces: tuple[Surface, ...]
    motion: Translation | Rotation | None = None
    name: str | None = None
    contact: Contact | None = None
    center: ArrayLike = (0.0, 0.0, 0.0)
    area: float | None = None

    def __post_init__(self) -> None:
        # One surface makes a wall of one surface (Wall(Plane(...)) raised a TypeError).
        surfaces = (self.surfaces,) if isinstance(self.surfaces, Surface) else self.surfaces
        if not (
            isinstance(surfaces, tuple | list) and all(isinstance(s, Surface) for s in surfaces)
        ):
            raise InputError(
                "Wall surfaces must be a surface (Plane, BoxContainer, CircleContainer, ...) or "
                f"a tuple of them, got {self.surfaces!r}"
            )
        object.__setattr__(self, "surfaces", tuple(surfaces))

    def core(self, name: str, dimension: int) -> _core.Wall:
        try:
            return self._core(name, dimension)
        except InputError as error:
            raise InputError(f"wall {name!r}: {error}") from None

    def _core(self, name: str, dimension: int) -> _core.Wall:
        wall = _core.Wall()
        wall.name = name
        if not self.surfaces:
            raise InputError("it has no surface")
        if self.area is not None:  # a number: checked_arguments
            if not (np.isfinite(self.area) and self.area > 0):
                raise InputError(f"area must be positive [m^2; m in 2D], got {self.area!r}")
        wall.surfaces = [s.core(dimension) for s in self.surfaces]
        wall.center = _vec3(self.center, "wall center", dimension)
        if isinstance(self.motion, Translation):
            wall.motion = _core.WallMotion.translation
            wall.direction = _vec3(self.motion.direction, "translation direction", dimension)
            wall.set_function(*self.motion.function.core())
        elif isinstance(self.motion, Rotation):
            wall.motion = _core.WallMotion.rotation
            wall.center = _vec3(self.motion.center, "rotation center", dimension)
            wall.axis = _vec3(self.motion.axis, "rotation axis", dimension, axis=True)
            wall.set_function(*self.motion.angle.core())
        elif self.motion is None:
            wall.set_function(*Constant(0.0).core())
        else:
            raise InputError(
                f"wall motion must be a Translation or a Rotation, got {self.motion!r}"
            )
        return wall


def _shape_surface(shape: Shape, inside: bool, segments: int) -> Surface:
    if isinstance(shape, Rectangle):
        lower, upper = (*shape.lower, 0.0), (*shape.upper, 0.0)
        return BoxContainer(lower, upper) if inside else BoxObstacle(lower, upper)
    if isinstance(shape, Box):
        return (
            BoxContainer(shape.lower, shape.upper)
            if inside
            else BoxObstacle(shape.lower, shape.upper)
        )
    if isinstance(shape, Disc):
        return (CircleContainer if inside else CircleObstacle)(shape.center, shape.radius)
    if isinstance(shape, Polygon):
        return (PolygonContainer if inside else PolygonObstacle)(shape.vertices)
    if isinstance(shape, Ellipse):
        if segments < 8:
            raise InputError(f"an ellipse wall needs at least 8 segments, got {segments}")
        t = 2 * np.pi * np.arange(segments) / segments
        a, b = shape.semi_axes
        c, s = np.cos(shape.angle), np.sin(shape.angle)
        x, y = a * np.cos(t), b * np.sin(t)
        vertices = np.column_stack([c * x - s * y, s * x + c * y]) + np.asarray(shape.center)
        return (PolygonContainer if inside else PolygonObstacle)(vertices)
    if isinstance(shape, SurfaceMesh):
        return TriangleMesh(shape.vertices, shape.triangles, inside)
    raise InputError(
        f"a {type(shape).__name__} cannot be a wall; use a Rectangle, Box, Disc, polygon, "
        "Ellipse or SurfaceMesh (a sphere or cylinder: a triangle surface, or CircleContainer "
        "with an axis for an infinite cylinder)"
    )


def container(shape: Shape, *, segments: int = 128) -> Surface:
    """A wall surface keeping particles inside ``shape`` (see the module docstring)."""
    return _shape_surface(shape, True, segments)


def obstacle(shape: Shape, *, segments: int = 128) -> Surface:
    """A wall surface keeping particles outside ``shape`` (posts, lifters, blades)."""
    return _shape_surface(shape, False, segments)
