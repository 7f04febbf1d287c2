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

The package's modules: base (Shape, rotation_matrix), planar (2D), solid (3D), combined (Union,
Difference), discretize (lattice, grid, conforming, outer_layer). ReferenceShape, a shape
discretised once for many particles, is granulate.reference_shapes' (it reads meshes, which
build on Shape); ``granulate.shapes.ReferenceShape`` still finds it.
"""

from __future__ import annotations

from typing import Any

from granulate.shapes.base import Shape, rotation_matrix
from granulate.shapes.combined import Difference, Union, grid_measure
from granulate.shapes.discretize import conforming, grid, grid_surface, lattice, outer_layer
from granulate.shapes.planar import (
    MOST_VERTICES,
    Disc,
    Drum2D,
    Ellipse,
    Polygon,
    Rectangle,
    RegularPolygon,
    Star,
)
from granulate.shapes.solid import Box, Cylinder, Ellipsoid, Sphere

__all__ = [
    "MOST_VERTICES",
    "Box",
    "Cylinder",
    "Difference",
    "Disc",
    "Drum2D",
    "Ellipse",
    "Ellipsoid",
    "Polygon",
    "Rectangle",
    "ReferenceShape",
    "RegularPolygon",
    "Shape",
    "Sphere",
    "Star",
    "Union",
    "conforming",
    "grid",
    "grid_measure",
    "grid_surface",
    "lattice",
    "outer_layer",
    "rotation_matrix",
]


def __getattr__(name: str) -> Any:
    """``granulate.shapes.ReferenceShape``: found in granulate.reference_shapes when first asked
    for (an import here would run in a circle: reference shapes read meshes, meshes use Shape)."""
    if name == "ReferenceShape":
        from granulate.reference_shapes import ReferenceShape

        return ReferenceShape
    raise AttributeError(f"module 'granulate.shapes' has no attribute {name!r}")
