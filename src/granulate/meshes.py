"""Meshes made elsewhere: particle meshes (gmsh .msh v2/v4, VTU, CSV of points with volumes)
and closed triangle surfaces (STL, OBJ, PLY) used as 3D shapes.

Files are read with meshio. A particle mesh becomes nodes with volumes: every element gives each
of its nodes an equal share of its measure (area of triangles and quadrilaterals in 2D, volume of
tetrahedra and hexahedra in 3D), as PeriDEM does. The mesh size h is the median over elements of
the edge of the right-angled element of the same measure, (c |e|)^(1/d) with c = 2 for
triangles, 6 for tetrahedra and 1 for quads and hexahedra (so a lattice cut into elements has its
spacing as h); without elements, the median of V^(1/d).
"""

from __future__ import annotations

import contextlib
import io
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from granulate import resources
from granulate.errors import InputError
from granulate.io.files import existing_file
from granulate.io.table import read_table
from granulate.shapes.base import Shape, _points

#: Element kinds we take volumes from, per dimension, with their node count.
AREA_CELLS = {"triangle": 3, "quad": 4}
VOLUME_CELLS = {"tetra": 4, "hexahedron": 8}
LINEAR_CELLS = {*AREA_CELLS, *VOLUME_CELLS}
#: Names of a nodal-volume field in VTU point data (ours, PeriDEM's).
VOLUME_FIELDS = ("volume", "Volume", "Nodal_Volume", "nodal_volume")


@dataclass(frozen=True)
class NodalMesh:
    """Nodes with volumes read from a file: positions (n, 3) [m], volumes (n,) [m^d], and the
    offsets of the nodes on the boundary (``surface``, (n, 3), see ``boundary_offsets``; None
    when the file has no elements to tell)."""

    positions: NDArray[np.float64]
    volumes: NDArray[np.float64]
    mesh_size: float
    dimension: int
    source: str = field(default="")
    surface: NDArray[np.float64] | None = None


def _require_declared_nodes(file: Path) -> None:
    """InputError before reading a gmsh file whose header declares more nodes than memory can
    hold (meshio would allocate them)."""
    if file.suffix.lower() != ".msh":
        return
    with file.open("rb") as handle:
        head = handle.read(1 << 20).split(b"\n")
    for k, line in enumerate(head[:-1]):
        if line.strip() == b"$Nodes" and k + 1 < len(head):
            fields = head[k + 1].split()
            try:  # v2: the count; v4: blocks, count, min tag, max tag
                declared = int(fields[1] if len(fields) == 4 else fields[0])
            except (ValueError, IndexError):
                return  # meshio reports the malformed header
            resources.require_memory(
                64.0 * declared, f"mesh file {file} ({declared:,} nodes declared)", "check the file"
            )
            return


def read_file(path: str | Path):  # -> meshio.Mesh
    """meshio.read with one clear InputError for a missing, unreadable or malformed file."""
    import meshio

    file = existing_file(path, "mesh file")
    _require_declared_nodes(file)
    try:
        # meshio reports some failures by printing and calling sys.exit: keep both quiet.
        with (
            contextlib.redirect_stdout(io.StringIO()),
            contextlib.redirect_stderr(io.StringIO()),
            warnings.catch_warnings(),
        ):
            warnings.simplefilter("ignore", RuntimeWarning)  # meshio's STL size probe overflows
            return meshio.read(file)
    except (meshio.ReadError, SystemExit) as error:
        raise InputError(
            f"cannot read mesh file {file}: not a readable mesh of a known format "
            f"({error or 'unreadable'})"
        ) from None
    except (ValueError, KeyError, IndexError, UnicodeDecodeError, EOFError) as error:
        raise InputError(
            f"mesh file {file} is malformed or of an unknown format ({error})"
        ) from None


def element_measures(
    kind: str, points: NDArray[np.float64], cells: NDArray[np.int64]
) -> NDArray[np.float64]:
    """Unsigned area (triangle, quad) or volume (tetra, hexahedron) of each element [m^d]."""
    x = points[cells]
    if kind == "triangle":
        return 0.5 * np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1)
    if kind == "quad":  # two triangles through the 0-2 diagonal (exact for planar quads)
        first = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
        second = np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 0])
        return 0.5 * np.linalg.norm(first + second, axis=1)
    if kind == "tetra":
        a, b, c = x[:, 1] - x[:, 0], x[:, 2] - x[:, 0], x[:, 3] - x[:, 0]
        return np.abs(np.einsum("ij,ij->i", a, np.cross(b, c))) / 6.0
    if kind == "hexahedron":
        # Trilinear map: det J has degree <= 2 in each reference coordinate, so 2 x 2 x 2 Gauss
        # points integrate it exactly (faces are the bilinear surfaces neighbours share).
        volume = np.zeros(len(cells))
        g = 1 / np.sqrt(3.0)
        corners = np.array(
            [
                (-1, -1, -1),
                (1, -1, -1),
                (1, 1, -1),
                (-1, 1, -1),
                (-1, -1, 1),
                (1, -1, 1),
                (1, 1, 1),
                (-1, 1, 1),
            ],
            dtype=float,
        )
        for gauss in corners * g:
            # dN_a/dxi_k = corner_a,k / 8 * prod over the other axes (1 + corner_a,m xi_m)
            factors = 1 + corners * gauss
            derivative = np.empty((8, 3))
            for k in range(3):
                others = [m for m in range(3) if m != k]
                derivative[:, k] = corners[:, k] / 8 * factors[:, others[0]] * factors[:, others[1]]
            jacobian = np.einsum("eai,ak->eik", x, derivative)
            volume += np.linalg.det(jacobian)
        return np.abs(volume)
    raise InputError(f"element kind {kind!r} is not supported")


#: The facets of each element kind (local vertex numbers): edges in 2D, faces in 3D.
_FACETS = {
    "triangle": ((0, 1), (1, 2), (2, 0)),
    "quad": ((0, 1), (1, 2), (2, 3), (3, 0)),
    "tetra": ((0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)),
    "hexahedron": (
        (0, 1, 2, 3),
        (4, 5, 6, 7),
        (0, 1, 5, 4),
        (1, 2, 6, 5),
        (2, 3, 7, 6),
        (3, 0, 4, 7),
    ),
}


def boundary_offsets(
    blocks: list[tuple[str, NDArray[np.int64]]], points: NDArray[np.float64], dimension: int
) -> NDArray[np.float64]:
    """Per node (n, 3): zero inside the mesh; on its boundary, the vector o with n_k . o = 1 for
    the outward unit normal n_k of every boundary facet (edge in 2D, face in 3D; a facet of one
    element only) at the node, in the least-squares sense: o = M^+ sum_k n_k with M = sum_k n_k
    n_k^T, directions whose eigenvalue is under 5 % of the largest left out. On a face o is its
    normal; at an edge or corner it reaches every face at once (two faces meeting at an angle a
    give |o| = 1 / sin(a / 2)); on a curved surface, the mean normal. Contact puts a surface
    node's sphere one contact radius rho below its faces, at x - rho o (see granulate.contact)."""
    facets, owners = [], []
    for kind, cells in blocks:
        for local in _FACETS[kind]:
            facets.append(np.sort(cells[:, local], axis=1))
            owners.append(cells)
    offsets = np.zeros((len(points), 3))
    for width in {f.shape[1] for f in facets}:
        same = np.concatenate([f for f in facets if f.shape[1] == width])
        cells = [c for f, c in zip(facets, owners, strict=True) if f.shape[1] == width]
        centroids = np.concatenate([points[c].mean(axis=1) for c in cells])
        _, index, counts = np.unique(same, axis=0, return_index=True, return_counts=True)
        single = index[counts == 1]
        faces, inside = same[single], centroids[single]
        x = points[faces]
        if dimension == 2:
            edge = x[:, 1] - x[:, 0]
            normals = np.column_stack([edge[:, 1], -edge[:, 0], np.zeros(len(edge))])
        else:
            normals = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
        normals /= np.linalg.norm(normals, axis=1)[:, None]
        outward = np.einsum("ij,ij->i", normals, x.mean(axis=1) - inside) > 0
        normals[~outward] *= -1
        moments = np.zeros((len(points), 3, 3))
        sums = np.zeros((len(points), 3))
        for k in range(width):
            np.add.at(moments, faces[:, k], normals[:, :, None] * normals[:, None, :])
            np.add.at(sums, faces[:, k], normals)
        on_surface = np.flatnonzero(np.any(sums != 0, axis=1))
        values, vectors = np.linalg.eigh(moments[on_surface])
        kept = values > 0.05 * values[:, -1:]
        inverse = np.where(kept, 1 / np.where(kept, values, 1), 0)
        local = np.einsum("nji,nj->ni", vectors, sums[on_surface]) * inverse
        offsets[on_surface] += np.einsum("nij,nj->ni", vectors, local)
    return offsets


#: c of the element size (c |e|)^(1/d): the measure of a right-angled element of unit edge.
_SIZE_FACTOR = {"triangle": 2.0, "quad": 1.0, "tetra": 6.0, "hexahedron": 1.0}


def nodal_mesh(mesh, *, dimension: int | None = None, source: str = "mesh") -> NodalMesh:
    """Nodes and nodal volumes of a meshio.Mesh (see the module docstring)."""
    kinds = {block.type for block in mesh.cells}
    higher = sorted(k for k in kinds if k[-1].isdigit() and k.rstrip("0123456789") in LINEAR_CELLS)
    if higher:
        raise InputError(
            f"{source}: second-order elements {higher} are not supported; mesh with first-order "
            "elements (gmsh: -order 1)"
        )
    if dimension is None:
        dimension = 3 if kinds & set(VOLUME_CELLS) else 2
    if dimension not in (2, 3):
        raise InputError(f"dimension must be 2 or 3, got {dimension}")
    wanted = VOLUME_CELLS if dimension == 3 else AREA_CELLS
    points = np.zeros((len(mesh.points), 3))
    points[:, : mesh.points.shape[1]] = mesh.points
    volume_field = next((mesh.point_data[n] for n in VOLUME_FIELDS if n in mesh.point_data), None)
    blocks = [(b.type, np.asarray(b.data, dtype=np.int64)) for b in mesh.cells if b.type in wanted]
    if volume_field is None and not blocks:
        found = ", ".join(sorted(kinds)) or "none"
        raise InputError(
            f"{source}: no {'tetrahedra or hexahedra' if dimension == 3 else 'triangles or quads'} "
            f"to take nodal volumes from (element kinds found: {found}); mesh the "
            f"{'volume' if dimension == 3 else 'surface'}, or give a point field 'volume'"
        )
    if dimension == 2 and np.any(points[:, 2] != 0):
        if np.ptp(points[:, 2]) > 0:
            raise InputError(f"{source}: a 2D mesh must lie in a plane z = constant")
        points[:, 2] = 0.0
    if volume_field is not None:
        volumes = np.asarray(volume_field, dtype=np.float64).reshape(-1)
        used = np.ones(len(points), dtype=bool)
    else:
        volumes = np.zeros(len(points))
        used = np.zeros(len(points), dtype=bool)
        sizes = []
        for kind, cells in blocks:
            measures = element_measures(kind, points, cells)
            bad = np.flatnonzero(~(measures > 1e-14 * np.max(measures, initial=0.0)))
            if len(bad):
                raise InputError(
                    f"{source}: {len(bad)} {kind} element(s) have zero "
                    f"{'volume' if dimension == 3 else 'area'} (the first is element {bad[0]}); "
                    "remove degenerate elements from the mesh"
                )
            np.add.at(volumes, cells.reshape(-1), np.repeat(measures / wanted[kind], wanted[kind]))
            sizes.append((_SIZE_FACTOR[kind] * measures) ** (1.0 / dimension))
            used[cells.reshape(-1)] = True
    surface = boundary_offsets(blocks, points, dimension) if volume_field is None else None
    # Nodes of no element (gmsh geometry points, boundary-only nodes) carry no volume: drop them.
    positions, volumes = points[used], volumes[used]
    if surface is not None:
        surface = surface[used]
    if len(volumes) == 0:
        raise InputError(f"{source}: the mesh has no nodes")
    bad = np.flatnonzero(~(volumes > 0) | ~np.isfinite(volumes))
    if len(bad):
        raise InputError(
            f"{source}: {len(bad)} node(s) have zero, negative or non-finite volume (the first is "
            f"node {bad[0]}, volume {volumes[bad[0]]}); every node needs a positive volume"
        )
    if volume_field is None:
        mesh_size = float(np.median(np.concatenate(sizes)))
    else:
        mesh_size = float(np.median(volumes) ** (1.0 / dimension))
    return NodalMesh(
        np.ascontiguousarray(positions), volumes, mesh_size, dimension, source, surface
    )


def read_mesh(path: str | Path, *, dimension: int | None = None) -> NodalMesh:
    """Nodes and volumes from a gmsh .msh (v2 or v4), .vtu, or other meshio-readable file, or a
    CSV of points with volumes (``read_points_csv``)."""
    if Path(path).suffix.lower() == ".csv":
        return read_points_csv(path, dimension=dimension or 3)
    return nodal_mesh(read_file(path), dimension=dimension, source=str(path))


def read_points_csv(path: str | Path, *, dimension: int) -> NodalMesh:
    """A CSV of nodes: columns x, y, volume (2D) or x, y, z, volume (3D) [m, m^d]; a header
    line is optional; lines starting with # are comments."""
    file = Path(path)
    columns = "x, y, volume" if dimension == 2 else "x, y, z, volume"
    data = read_table(file, what="points", widths=(dimension + 1,), columns=columns)
    positions = np.zeros((len(data), 3))
    positions[:, :dimension] = data[:, :dimension]
    volumes = data[:, dimension]
    bad = np.flatnonzero(~(volumes > 0) | ~np.all(np.isfinite(data), axis=1))
    if len(bad):
        raise InputError(
            f"{file}: {len(bad)} point(s) have a zero, negative or non-finite volume or "
            f"coordinate (the first is point {bad[0]}); every node needs a positive volume"
        )
    mesh_size = float(np.median(volumes) ** (1.0 / dimension))
    return NodalMesh(positions, volumes, mesh_size, dimension, str(file))


# ---------------------------------------------------------------------------- surfaces
def _solid_angles(p: NDArray[np.float64], triangles: NDArray[np.float64]) -> NDArray[np.float64]:
    """Sum over triangles of the signed solid angle they subtend at each point (Van Oosterom &
    Strackee 1983); 4 pi inside a closed outward surface, 0 outside."""
    a = triangles[None, :, 0, :] - p[:, None, :]
    b = triangles[None, :, 1, :] - p[:, None, :]
    c = triangles[None, :, 2, :] - p[:, None, :]
    la, lb, lc = (np.linalg.norm(v, axis=2) for v in (a, b, c))
    numerator = np.einsum("pti,pti->pt", a, np.cross(b, c))
    denominator = (
        la * lb * lc
        + np.einsum("pti,pti->pt", a, b) * lc
        + np.einsum("pti,pti->pt", a, c) * lb
        + np.einsum("pti,pti->pt", b, c) * la
    )
    return 2.0 * np.arctan2(numerator, denominator).sum(axis=1)


def _triangle_distances(
    p: NDArray[np.float64], triangles: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Unsigned distance of each point to the nearest triangle: the distance to the plane when
    the projection falls inside the triangle, else to the nearest edge."""
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    normal = np.cross(b - a, c - a)
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    w = p[:, None, :] - a[None]
    height = np.einsum("pti,ti->pt", w, normal)
    projected = p[:, None, :] - height[..., None] * normal[None]
    inside = np.ones(height.shape, dtype=bool)
    for start, end in ((a, b), (b, c), (c, a)):
        side = np.einsum("pti,ti->pt", np.cross(end - start, projected - start[None]), normal)
        inside &= side >= 0
    best = np.where(inside, np.abs(height), np.inf)
    for start, end in ((a, b), (b, c), (c, a)):
        edge = end - start
        t = np.clip(
            np.einsum("pti,ti->pt", p[:, None, :] - start[None], edge)
            / np.sum(edge * edge, axis=1),
            0,
            1,
        )
        closest = start[None] + t[..., None] * edge[None]
        best = np.minimum(best, np.linalg.norm(p[:, None, :] - closest, axis=2))
    return best.min(axis=1)


@dataclass(frozen=True, eq=False)
class SurfaceMesh(Shape):
    """A solid bounded by a closed triangle surface (3D): ``vertices`` (n, 3) [m], ``triangles``
    (m, 3) vertex indices. Checked to be closed (every edge shared by two triangles) and
    oriented outward (flipped if it is not). ``SurfaceMesh.from_file`` reads STL, OBJ, PLY, OFF
    or any meshio surface format. Inside test: winding number; distance: exact, by brute force
    over the triangles (meant for grain-sized surfaces of up to a few thousand triangles)."""

    vertices: NDArray[np.float64]
    triangles: NDArray[np.int64]
    dimension: int = field(default=3, init=False)

    def __post_init__(self) -> None:
        v = np.asarray(self.vertices, dtype=np.float64)
        t = np.asarray(self.triangles, dtype=np.int64)
        if v.ndim != 2 or v.shape[1] != 3 or not np.all(np.isfinite(v)):
            raise InputError("SurfaceMesh vertices must be a finite (n, 3) array")
        if t.ndim != 2 or t.shape[1] != 3 or len(t) < 4 or t.min() < 0 or t.max() >= len(v):
            raise InputError("SurfaceMesh triangles must be (m >= 4, 3) indices of its vertices")
        v, t = _merge_vertices(v, t)
        edges = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
        _, counts = np.unique(edges, axis=0, return_counts=True)
        if np.any(counts != 2):
            raise InputError(
                f"the triangle surface is not closed: {int(np.sum(counts != 2))} edge(s) are not "
                "shared by exactly two triangles; repair the mesh (e.g. in MeshLab) first"
            )
        x = v[t]
        volume = np.einsum("ij,ij->", x[:, 0], np.cross(x[:, 1], x[:, 2])) / 6.0
        if volume == 0:
            raise InputError("the triangle surface encloses no volume")
        if volume < 0:
            t = t[:, ::-1].copy()
        object.__setattr__(self, "vertices", v)
        object.__setattr__(self, "triangles", t)
        object.__setattr__(self, "_volume", abs(float(volume)))

    @staticmethod
    def from_file(path: str | Path, *, scale: float = 1.0) -> SurfaceMesh:
        """Read a closed triangle surface (STL, OBJ, PLY, OFF, ...), coordinates times scale."""
        mesh = read_file(path)
        triangles = [np.asarray(b.data) for b in mesh.cells if b.type == "triangle"]
        if not triangles:
            raise InputError(f"{path} holds no triangles")
        return SurfaceMesh(
            np.asarray(mesh.points, dtype=float)[:, :3] * scale, np.concatenate(triangles)
        )

    def _chunks(self, p: NDArray[np.float64]):
        step = max(1, 2_000_000 // max(1, len(self.triangles)))
        for start in range(0, len(p), step):
            yield start, p[start : start + step]

    def contains(self, points: ArrayLike) -> NDArray[np.bool_]:
        p = _points(points)
        out = np.empty(len(p), dtype=bool)
        triangles = self.vertices[self.triangles]
        for start, chunk in self._chunks(p):
            out[start : start + len(chunk)] = _solid_angles(chunk, triangles) > 2 * np.pi
        return out

    def signed_distance(self, points: ArrayLike) -> NDArray[np.float64]:
        p = _points(points)
        out = np.empty(len(p))
        triangles = self.vertices[self.triangles]
        for start, chunk in self._chunks(p):
            out[start : start + len(chunk)] = _triangle_distances(chunk, triangles)
        return np.where(self.contains(p), -out, out)

    def bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        return self.vertices.min(axis=0), self.vertices.max(axis=0)

    @property
    def measure(self) -> float:
        return self._volume  # type: ignore[attr-defined]

    @property
    def origin(self) -> NDArray[np.float64]:
        """The centroid of the enclosed volume."""
        x = self.vertices[self.triangles]
        six_volumes = np.einsum("ij,ij->i", x[:, 0], np.cross(x[:, 1], x[:, 2]))
        return (six_volumes[:, None] * x.sum(axis=1)).sum(axis=0) / (4 * six_volumes.sum())

    @property
    def bounding_radius(self) -> float:
        return float(np.max(np.linalg.norm(self.vertices - self.origin, axis=1)))


def _merge_vertices(
    v: NDArray[np.float64], t: NDArray[np.int64]
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """STL repeats each vertex per triangle: merge coincident vertices (to 1e-9 of the size)."""
    tolerance = 1e-9 * max(float(np.ptp(v, axis=0).max()), 1e-300)
    keys = np.round(v / tolerance).astype(np.int64)
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    return v[first], inverse.reshape(-1)[t]
