"""ReferenceShape: a particle shape discretised once (or read from a mesh: granulate.meshes)
and placed as many particles, which share its bonds in memory."""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from granulate.errors import InputError
from granulate.meshes import read_mesh
from granulate.shapes.base import Shape
from granulate.shapes.discretize import conforming, grid, grid_surface, lattice, outer_layer


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
        return self.outer_layer_unkept()

    def outer_layer_unkept(self) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
        """outer_layer_of, computed anew unless the shape holds it already, and not kept: for
        a shape only compared with others (shape_sharing)."""
        if "outer_layer_of" in self.__dict__:
            return self.outer_layer_of
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
