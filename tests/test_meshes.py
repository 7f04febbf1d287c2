"""Meshes made elsewhere: gmsh v2/v4, VTU and CSV particle meshes, closed triangle surfaces;
nodal volumes from elements; clear errors for bad files."""

from __future__ import annotations

from pathlib import Path

import meshio
import numpy as np
import pytest

import granulate as gr

# Copies of a PeriDEM deck's files (made by PeriDEM's set-up scripts), kept with the benchmarks.
DECK = (
    Path(__file__).resolve().parents[1] / "src" / "granulate" / "bench_cases" / "compression_small"
)


def structured(dimension: int, kind: str, n: int = 4, size: float = 2e-3) -> meshio.Mesh:
    """A square (cube) of side `size` meshed with n cells per side: quads or triangles
    (hexahedra or tetrahedra, six per cube), slightly distorted so elements differ."""
    axes = [np.linspace(0, size, n + 1)] * dimension
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, dimension)
    rng = np.random.default_rng(3)
    interior = np.all((grid > 0) & (grid < size), axis=1)
    grid[interior] += rng.uniform(-0.15, 0.15, size=(interior.sum(), dimension)) * size / n
    points = np.zeros((len(grid), 3))
    points[:, :dimension] = grid

    def node(*index: int) -> int:
        flat = 0
        for i in index:
            flat = flat * (n + 1) + i
        return flat

    cells = []
    if dimension == 2:
        for i in range(n):
            for j in range(n):
                quad = [node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)]
                if kind == "quad":
                    cells.append(quad)
                else:
                    cells += [[quad[0], quad[1], quad[2]], [quad[0], quad[2], quad[3]]]
    else:
        for i in range(n):
            for j in range(n):
                for k in range(n):
                    c = [
                        node(i + a, j + b, k + z)
                        for z in (0, 1)
                        for a, b in ((0, 0), (1, 0), (1, 1), (0, 1))
                    ]
                    if kind == "hexahedron":
                        cells.append(c)
                    else:  # six tetrahedra around the 0-6 diagonal
                        for a, b in ((1, 2), (2, 3), (3, 7), (7, 4), (4, 5), (5, 1)):
                            cells.append([c[0], c[a], c[b], c[6]])
    return meshio.Mesh(points, [(kind, np.asarray(cells))])


def exact_measure(mesh: meshio.Mesh, kind: str) -> float:
    """Independent reference: 2D shoelace over the boundary polygon is the square's area only
    without distortion of the boundary, which holds (boundary nodes are not moved)."""
    dimension = 2 if kind in ("triangle", "quad") else 3
    return float(np.prod(np.ptp(mesh.points[:, :dimension], axis=0)))


@pytest.mark.parametrize("kind", ["triangle", "quad", "tetra", "hexahedron"])
@pytest.mark.parametrize("file_format", ["gmsh22", "gmsh", "vtu"])
def test_imported_mesh_volumes_sum_to_the_mesh_measure(
    tmp_path: Path, kind: str, file_format: str
) -> None:
    mesh = structured(2 if kind in ("triangle", "quad") else 3, kind)
    path = tmp_path / ("mesh.vtu" if file_format == "vtu" else "mesh.msh")
    extra = {"binary": False} if file_format.startswith("gmsh") else {}
    meshio.write(path, mesh, file_format=file_format, **extra)
    reference = gr.ReferenceShape.from_mesh(str(path))
    assert reference.dimension == (2 if kind in ("triangle", "quad") else 3)
    assert reference.node_count == len(mesh.points)
    assert reference.volumes.sum() == pytest.approx(exact_measure(mesh, kind), rel=1e-12)
    assert reference.mesh_size == pytest.approx(0.5e-3, rel=0.2)


def test_gmsh_binary_v4_and_a_vtu_volume_field(tmp_path: Path) -> None:
    mesh = structured(2, "triangle")
    meshio.write(tmp_path / "b.msh", mesh, file_format="gmsh", binary=True)
    assert gr.read_mesh(tmp_path / "b.msh").volumes.sum() == pytest.approx(4e-6, rel=1e-12)
    given = np.full(len(mesh.points), 1e-7)
    vertices = [("vertex", np.arange(len(mesh.points)).reshape(-1, 1))]
    meshio.write(
        tmp_path / "v.vtu", meshio.Mesh(mesh.points, vertices, point_data={"volume": given})
    )
    from_points = gr.read_mesh(tmp_path / "v.vtu", dimension=2)
    np.testing.assert_array_equal(from_points.volumes, given)
    assert from_points.surface is None  # points alone do not tell which lie on the surface
    # The structured square's boundary: 16 of its 25 vertices, corners at (+-1, +-1).
    surface = gr.read_mesh(tmp_path / "b.msh").surface
    assert np.count_nonzero(np.linalg.norm(surface, axis=1)) == 16
    np.testing.assert_allclose(np.abs(surface[0, :2]), [1.0, 1.0], rtol=1e-12)


def test_peridem_deck_meshes_read_with_their_element_areas() -> None:
    """PeriDEM's gmsh v2 disc mesh: volumes sum to the area of its polygonal boundary (the
    inscribed 64-gon of radius 1 mm here), within round-off."""
    path = DECK / "mesh_cir_small_0.msh"
    reference = gr.ReferenceShape.from_mesh(str(path))
    boundary = np.linalg.norm(reference.positions[:, :2], axis=1)
    sides = int(np.sum(np.isclose(boundary, 1e-3, rtol=1e-6)))
    polygon = 0.5 * sides * 1e-6 * np.sin(2 * np.pi / sides)
    assert reference.volumes.sum() == pytest.approx(polygon, rel=1e-6)
    assert reference.node_count == 123


def test_csv_points_with_volumes(tmp_path: Path) -> None:
    path = tmp_path / "points.csv"
    path.write_text("x,y,volume\n0,0,1e-8\n1e-4,0,1e-8\n# comment\n0,1e-4,2e-8\n")
    reference = gr.ReferenceShape.from_mesh(str(path), dimension=2)
    assert reference.node_count == 3
    assert reference.volumes.sum() == pytest.approx(4e-8)
    assert reference.mesh_size == pytest.approx(1e-4)


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ("x,y,volume\n0,0,1e-8\n1,0,0\n", "positive volume"),
        ("x,y,volume\n0,0,-1e-8\n", "positive volume"),
        ("0,0\n", "expected 3 columns"),
        ("0,0,1e-8\n1,zero,1e-8\n", "line 2: expected numbers"),
        ("x,y,volume\n", "holds no points"),
    ],
)
def test_bad_csv_points_give_clear_errors(tmp_path: Path, content: str, message: str) -> None:
    path = tmp_path / "bad.csv"
    path.write_text(content)
    with pytest.raises(gr.InputError, match=message):
        gr.read_mesh(path, dimension=2)


def test_bad_mesh_files_give_clear_errors(tmp_path: Path) -> None:
    with pytest.raises(gr.InputError, match="does not exist"):
        gr.read_mesh(tmp_path / "missing.msh")
    garbage = tmp_path / "garbage.msh"
    garbage.write_text("$MeshFormat\nthis is not a mesh\n")
    with pytest.raises(gr.InputError, match=r"garbage\.msh"):
        gr.read_mesh(garbage)
    points = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0]], float) * 1e-3
    degenerate = meshio.Mesh(points, [("triangle", np.array([[0, 1, 2], [0, 1, 3]]))])
    meshio.write(tmp_path / "flat.vtu", degenerate)
    with pytest.raises(gr.InputError, match="zero area"):
        gr.read_mesh(tmp_path / "flat.vtu")
    lines = meshio.Mesh(points, [("line", np.array([[0, 1], [1, 3]]))])
    meshio.write(tmp_path / "lines.vtu", lines)
    with pytest.raises(gr.InputError, match="no triangles or quads"):
        gr.read_mesh(tmp_path / "lines.vtu")
    quadratic = meshio.Mesh(
        np.vstack([points, [[0.5e-3, 0, 0], [0.5e-3, 0.5e-3, 0]]]),
        [("triangle6", np.array([[0, 1, 3, 4, 5, 5]]))],
    )
    meshio.write(tmp_path / "quadratic.vtu", quadratic)
    with pytest.raises(gr.InputError, match="second-order"):
        gr.read_mesh(tmp_path / "quadratic.vtu")


def cube_surface(size: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    v = np.array([[x, y, z] for x in (0, size) for y in (0, size) for z in (0, size)], float)
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    triangles = [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]
    return v, np.asarray(triangles)


def test_surface_mesh_from_stl_matches_the_box_it_describes(tmp_path: Path) -> None:
    vertices, triangles = cube_surface(2e-3)
    meshio.write(tmp_path / "cube.stl", meshio.Mesh(vertices, [("triangle", triangles)]))
    surface = gr.SurfaceMesh.from_file(tmp_path / "cube.stl")
    box = gr.Box((0, 0, 0), (2e-3, 2e-3, 2e-3))
    assert surface.measure == pytest.approx(8e-9, rel=1e-12)
    np.testing.assert_allclose(surface.origin, [1e-3] * 3, atol=1e-15)
    rng = np.random.default_rng(4)
    p = rng.uniform(-1e-3, 3e-3, size=(3000, 3))
    np.testing.assert_array_equal(surface.contains(p), box.contains(p))
    np.testing.assert_allclose(surface.signed_distance(p), box.signed_distance(p), atol=1e-15)
    # Filled with a lattice, it holds the box's nodes.
    positions, _ = gr.lattice(surface, 0.25e-3)
    assert len(positions) == 8**3


def test_surface_mesh_orientation_is_fixed_and_holes_are_refused() -> None:
    vertices, triangles = cube_surface()
    inverted = gr.SurfaceMesh(vertices, triangles[:, ::-1])
    assert inverted.measure == pytest.approx(1.0)
    assert inverted.contains([[0.5, 0.5, 0.5]])[0]
    with pytest.raises(gr.InputError, match="not closed"):
        gr.SurfaceMesh(vertices, triangles[:-1])


def test_a_meshed_particle_runs(tmp_path: Path) -> None:
    """A PeriDEM disc mesh placed twice: the particles collide and separate."""
    path = DECK / "mesh_cir_small_0.msh"
    reference = gr.ReferenceShape.from_mesh(str(path))
    material = gr.Material(density=1200, bulk_modulus=2.16e7, shear_modulus=1.296e7, fracture=False)
    sim = gr.Simulation(2)
    sim.contact = gr.Contact(restitution=0.8)
    a = sim.add_particle(reference, material, position=(0, 0), velocity=(0.5, 0))
    b = sim.add_particle(reference, material, position=(2.3e-3, 0), velocity=(-0.5, 0))
    sim.run(until=3e-3)
    va = np.average(sim.velocities[a.nodes, 0], weights=sim.volumes[a.nodes])
    vb = np.average(sim.velocities[b.nodes, 0], weights=sim.volumes[b.nodes])
    assert va < 0 < vb
    assert (vb - va) / 1.0 == pytest.approx(0.8, abs=0.05)


def test_surface_offsets_reach_every_face_at_a_node() -> None:
    """ReferenceShape.surface: o with n . o = 1 for each boundary face normal n at a node, zero
    inside. PeriDEM's hexagon: |o| = 1 on its sides and 1 / sin(60 deg) at its corners (two
    sides at 120 degrees); its triangle: 2 = 1 / sin(30 deg) at the corners; the gmsh disc: 1
    radially outward within 0.5 % (its 32 sides meet at 169 degrees); a grid: +-1 along each
    axis whose face a node lies on."""
    hexagon = gr.ReferenceShape.from_mesh(str(DECK / "mesh_hex_small_0.msh"))
    o, x = hexagon.surface, hexagon.positions
    length = np.linalg.norm(o, axis=1)
    corners = np.isclose(np.linalg.norm(x, axis=1), 1e-3, rtol=1e-9)
    assert corners.sum() == 6
    np.testing.assert_allclose(length[corners], 1 / np.sin(np.pi / 3), rtol=1e-9)
    on_sides = (length > 0) & ~corners
    np.testing.assert_allclose(length[on_sides], 1.0, rtol=1e-9)
    assert np.all(np.einsum("ij,ij->i", o[on_sides], x[on_sides]) > 0)  # outward
    assert np.all(length[np.linalg.norm(x, axis=1) < 0.8e-3] == 0)
    triangle = gr.ReferenceShape.from_mesh(str(DECK / "mesh_tri_small_0.msh"))
    assert np.max(np.linalg.norm(triangle.surface, axis=1)) == pytest.approx(2.0, rel=1e-9)
    disc = gr.ReferenceShape.from_mesh(str(DECK / "mesh_cir_small_0.msh"))
    rim = np.linalg.norm(disc.surface, axis=1) > 0
    radial = disc.positions[rim] / np.linalg.norm(disc.positions[rim], axis=1)[:, None]
    np.testing.assert_allclose(disc.surface[rim], radial, atol=5e-3)
    box = gr.ReferenceShape.from_shape(gr.Box((0, 0, 0), (1, 2, 3)), 0.5, discretization="grid")
    np.testing.assert_array_equal(np.unique(box.surface), [-1.0, 0.0, 1.0])
    corner = np.flatnonzero(np.all(box.positions == 0, axis=1))[0]
    np.testing.assert_array_equal(box.surface[corner], [-1.0, -1.0, -1.0])
    # A lattice has no node on its surface; for the surface law its outer layer (nodes less
    # than h deep) carries the shape's unit normal and its depth, so contact sees its surface
    # points on the true circle (a centred shape's too).
    lattice = gr.ReferenceShape.from_shape(gr.Disc((0, 0), 1), 0.1)
    centred = gr.ReferenceShape.from_shape(gr.Disc((2, 1), 1), 0.1, centered=True)
    assert lattice.surface is None and centred.surface is None
    for reference in (lattice, centred):
        normals, depths = reference.outer_layer_of
        layer = np.linalg.norm(normals, axis=1) > 0
        x = reference.positions[:, :2]
        r = np.linalg.norm(x, axis=1)
        np.testing.assert_array_equal(layer, 1 - r < 0.1)
        np.testing.assert_allclose(normals[layer, :2], x[layer] / r[layer, None])
        points = x[layer] + depths[layer, None] * normals[layer, :2]
        np.testing.assert_allclose(np.linalg.norm(points, axis=1), 1.0, rtol=1e-6)


def test_surface_offsets_of_the_wrong_size_are_refused() -> None:
    from granulate import _core

    model = _core.Model(2)
    positions, volumes = np.zeros((2, 3)), np.ones(2)
    positions[1, 0] = 1.0
    none = np.zeros(0)
    with pytest.raises(gr.InputError, match="1 surface offsets for 2 nodes"):
        model.add_shape(positions, volumes, 1.0, np.zeros(3), none)
    with pytest.raises(gr.InputError, match="not finite"):
        model.add_shape(positions, volumes, 1.0, np.array([0, 0, 0, np.nan, 0, 0]), none)
    offsets = np.array([1.0, 0, 0, 0, 0, 0])
    with pytest.raises(gr.InputError, match="1 surface depths for 2 nodes"):
        model.add_shape(positions, volumes, 1.0, offsets, np.zeros(1))
    with pytest.raises(gr.InputError, match="surface depth is negative"):
        model.add_shape(positions, volumes, 1.0, offsets, np.array([-0.1, 0.0]))
