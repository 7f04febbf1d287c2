"""Nodes for a shape: lattice (uniform, clipped to the shape), grid (cell centres of a
Rectangle or Box, with its boundary offsets), conforming (rings or shells following a disc's,
sphere's, ellipse's or ellipsoid's surface), and the outer layer's normals and depths."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from granulate import resources
from granulate.errors import InputError
from granulate.shapes.base import Shape, rotation_matrix
from granulate.shapes.planar import Disc, Ellipse, Rectangle
from granulate.shapes.solid import Box, Ellipsoid, Sphere


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


MEDIAL_GRADIENT = 0.3
"""|grad phi| below which a node lies on the medial axis between nearly opposite faces and
takes no normal (outer_layer): faces 145 degrees or more apart."""


def outer_layer(
    shape: Shape, positions: NDArray[np.float64], mesh_size: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Where contact finds the surface above a lattice's or conforming discretisation's outer
    nodes (see ReferenceShape.surface): for each node less than one mesh size h deep, the unit
    outward normal n = grad phi / |grad phi| of the shape's signed distance phi (central
    differences over h/1000) and its depth -phi; zero for the nodes deeper in. A rotated
    lattice's outer nodes lie from 0 to h below its faces; contact puts each one's surface point
    at x + depth n, on the shape's true surface. On a corner's bisector the differences straddle
    the kink of phi and |grad phi| is the cosine of half the angle between the faces' normals
    (0.87 at a hexagon's corner, 0.71 at a square's, 0.5 at a triangle's): the node takes the
    bisector as its normal. Where |grad phi| < MEDIAL_GRADIENT the faces nearly oppose each
    other (the medial axis of a part thinner than 2 h) and the node gets none. Corner nodes had
    been left without a normal: a 1 mm hexagon at h = 0.2 mm lost two of its six corners'
    surface points, and discs settled in a pile came to rest with nodes 0.25 h from the
    hexagons' corner nodes.

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
    unit = length > MEDIAL_GRADIENT
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
