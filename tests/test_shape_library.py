"""The shape library: inside tests, signed distances, exact measures, and discretizations whose
volumes converge to the exact measure."""

from __future__ import annotations

import numpy as np
import pytest

import granulate as gr

SHAPES_2D = [
    gr.Rectangle((-1.0, -0.5), (1.0, 0.7)),
    gr.Disc((0.2, -0.1), 1.0),
    gr.Ellipse((0.1, 0.2), (1.5, 0.6), 0.4),
    gr.Polygon(((0, 0), (2, 0), (2, 1), (1, 0.4), (0, 1))),  # concave
    gr.RegularPolygon((0, 0), 1.0, 6, 0.3),
    gr.Star((0, 0), 1.5, 0.6, 5),
    gr.Drum2D((0.1, 0), 1.0, 0.4, 0.2),
]
SHAPES_3D = [
    gr.Box((-1, -0.5, -0.3), (1, 0.5, 0.6)),
    gr.Sphere((0.1, 0, -0.2), 1.0),
    gr.Ellipsoid((0, 0, 0), (1.2, 0.8, 0.5), (0.3, -0.2, 0.5)),
    gr.Cylinder((0, 0, 0), 0.6, 1.5, (1, 1, 0.5)),
]


def random_points(shape: gr.Shape, count: int = 4000, seed: int = 0) -> np.ndarray:
    lower, upper = shape.bounds()
    margin = 0.3 * shape.bounding_radius
    rng = np.random.default_rng(seed)
    points = rng.uniform(lower - margin, upper + margin, size=(count, 3))
    if shape.dimension == 2:
        points[:, 2] = 0
    return points


@pytest.mark.parametrize("shape", SHAPES_2D + SHAPES_3D, ids=lambda s: type(s).__name__)
def test_signed_distance_agrees_with_the_inside_test_and_is_a_distance(shape: gr.Shape) -> None:
    """Sign: negative exactly where contains() holds. Magnitude: 1-Lipschitz, and moving a point
    by its distance towards the surface reaches it (|sd| there below 1e-6 of the size)."""
    p = random_points(shape)
    sd = shape.signed_distance(p)
    inside = shape.contains(p)
    np.testing.assert_array_equal(sd <= 0, inside)
    q = random_points(shape, seed=1)
    lipschitz = np.abs(shape.signed_distance(q) - sd) / np.linalg.norm(q - p, axis=1)
    assert lipschitz.max() <= 1 + 1e-9
    # The distance is attained: the gradient (finite differences) times sd leads to the surface.
    step = 1e-7 * shape.bounding_radius
    d = shape.dimension
    gradient = np.zeros_like(p)
    for k in range(d):
        e = np.zeros(3)
        e[k] = step
        gradient[:, k] = (shape.signed_distance(p + e) - shape.signed_distance(p - e)) / (2 * step)
    smooth = np.abs(np.linalg.norm(gradient, axis=1) - 1) < 1e-4  # away from the medial axis
    landed = p[smooth] - sd[smooth, None] * gradient[smooth]
    assert smooth.sum() > 0.6 * len(p)
    assert np.abs(shape.signed_distance(landed)).max() < 1e-5 * shape.bounding_radius


def test_exact_distances_at_known_points() -> None:
    ellipse = gr.Ellipse((0, 0), (2.0, 1.0))
    np.testing.assert_allclose(
        ellipse.signed_distance([[3, 0, 0], [0, 0.25, 0], [0, -4, 0]]), [1.0, -0.75, 3.0]
    )
    ellipsoid = gr.Ellipsoid((1, 0, 0), (3.0, 2.0, 1.0))
    np.testing.assert_allclose(
        ellipsoid.signed_distance([[5, 0, 0], [1, 0, 0.5], [1, 0, -3]]), [1.0, -0.5, 2.0]
    )
    hexagon = gr.RegularPolygon((0, 0), 1.0, 6)
    apothem = np.sqrt(3) / 2
    np.testing.assert_allclose(
        hexagon.signed_distance([[0, 0, 0], [0, 2, 0]]), [-apothem, 2 - apothem]
    )
    cylinder = gr.Cylinder((0, 0, 0), 1.0, 2.0)
    np.testing.assert_allclose(
        cylinder.signed_distance([[0, 0, 0], [3, 0, 0], [0, 0, 1.5], [2, 0, 2]]),
        [-1.0, 2.0, 0.5, np.sqrt(2)],
    )


def test_exact_measures() -> None:
    r = 1.3
    for n in (3, 4, 6, 11):
        polygon = gr.RegularPolygon((0, 0), r, n)
        assert polygon.measure == pytest.approx(0.5 * n * r * r * np.sin(2 * np.pi / n), rel=1e-12)
    # Star: 2n triangles (centre, tip, notch).
    star = gr.Star((0, 0), 1.5, 0.6, 5)
    assert star.measure == pytest.approx(10 * 0.5 * 1.5 * 0.6 * np.sin(np.pi / 5), rel=1e-12)
    # Drum: the hexagon less two triangles of base r sqrt(3) and height r - w.
    drum = gr.Drum2D((0, 0), 1.0, 0.4)
    assert drum.measure == pytest.approx(1.5 * np.sqrt(3) - np.sqrt(3) * 0.6, rel=1e-12)
    assert gr.Ellipse((0, 0), (2, 3)).measure == pytest.approx(6 * np.pi)
    assert gr.Ellipsoid((0, 0, 0), (1, 2, 3)).measure == pytest.approx(8 * np.pi)
    assert gr.Cylinder((0, 0, 0), 2, 3).measure == pytest.approx(12 * np.pi)


def test_drum_vertices_follow_peridem() -> None:
    """v1 = c + w a, v2 = c + r R(60 deg) a, v3 = v2 - r a, v4 = c - w a, v5, v6 mirrored."""
    drum = gr.Drum2D((1.0, 2.0), 1.0, 0.3)
    h = np.sqrt(3) / 2
    expected = [(1.3, 2), (1.5, 2 + h), (0.5, 2 + h), (0.7, 2), (0.5, 2 - h), (1.5, 2 - h)]
    np.testing.assert_allclose(drum.vertices, expected, atol=1e-15)


@pytest.mark.parametrize("shape", SHAPES_2D + SHAPES_3D[:3], ids=lambda s: type(s).__name__)
def test_lattice_volume_converges_to_the_exact_measure(shape: gr.Shape) -> None:
    """Lattice volume error is a boundary layer: |sum V - |S|| <= |dS| h (perimeter or surface
    area times h), so it falls to zero with h; checked at four mesh sizes."""
    radius = shape.bounding_radius
    p = random_points(shape, 200_000, seed=2)
    lower, upper = shape.bounds()
    box = np.prod((upper - lower + 0.6 * radius)[: shape.dimension])
    inside_fraction = shape.contains(p).mean()
    assert inside_fraction * box == pytest.approx(shape.measure, rel=0.03)  # measure is right
    # Boundary measure estimated from the volume of a thin shell around the surface.
    shell = 0.02 * radius
    boundary = (np.abs(shape.signed_distance(p)) < shell).mean() * box / (2 * shell)
    steps = [radius / k for k in ((5, 10, 20, 40) if shape.dimension == 2 else (4, 8, 12, 16))]
    errors = []
    for h in steps:
        _, volumes = gr.lattice(shape, h)
        errors.append(abs(volumes.sum() - shape.measure))
        assert errors[-1] <= boundary * h, f"h = {h:.3g}: error {errors[-1]:.3g}"
    assert errors[-1] / shape.measure < (0.02 if shape.dimension == 2 else 0.06)


@pytest.mark.parametrize(
    "shape",
    [
        gr.Disc((0.3, 0), 1.0),
        gr.Ellipse((0, 0), (1.4, 0.7), 0.5),
        gr.Sphere((0, 0, 1), 1.0),
        gr.Ellipsoid((0, 0, 0), (1, 0.7, 0.5)),
    ],
    ids=lambda s: type(s).__name__,
)
def test_conforming_nodes_have_the_exact_measure_and_follow_the_surface(shape: gr.Shape) -> None:
    h = 0.1
    positions, volumes = gr.conforming(shape, h)
    assert volumes.sum() == pytest.approx(shape.measure, rel=1e-12)
    assert shape.contains(positions).all()
    # The outermost nodes sit on a smooth surface about half a spacing inside.
    distance = -shape.signed_distance(positions)
    outer = distance < 0.75 * h
    assert np.ptp(distance[outer]) < 0.35 * h
    # Spacing close to h: nearest-neighbour distances.
    sample = positions[:: max(1, len(positions) // 300)]
    nearest = np.sort(np.linalg.norm(sample[:, None] - positions[None], axis=2), axis=1)[:, 1]
    assert 0.3 * h < np.median(nearest) < 1.2 * h


def test_shapes_reject_bad_parameters() -> None:
    with pytest.raises(gr.InputError, match="sides"):
        gr.RegularPolygon((0, 0), 1.0, 2)
    with pytest.raises(gr.InputError, match="inner_radius"):
        gr.Star((0, 0), 1.0, 1.5)
    with pytest.raises(gr.InputError, match="neck_half_width"):
        gr.Drum2D((0, 0), 1.0, 1.2)
    with pytest.raises(gr.InputError, match="semi_axes"):
        gr.Ellipse((0, 0), (1.0, -1.0))
    with pytest.raises(gr.InputError, match="axis"):
        gr.Cylinder((0, 0, 0), 1.0, 1.0, (0, 0, 0))
    with pytest.raises(gr.InputError, match="conforming"):
        gr.conforming(gr.Rectangle((0, 0), (1, 1)), 0.1)
    with pytest.raises(gr.InputError, match="discretization"):
        gr.ReferenceShape.from_shape(gr.Disc((0, 0), 1), 0.1, discretization="voronoi")


@pytest.mark.parametrize(
    "shape",
    [
        gr.RegularPolygon((0, 0), 1e-3, 6),
        gr.RegularPolygon((0, 0), 1e-3, 3),
        gr.RegularPolygon((0, 0), 0.9e-3, 4),
        gr.Box((0, 0, 0), (1e-3, 1e-3, 1e-3)),
    ],
    ids=("hexagon", "triangle", "square", "cube"),
)
def test_every_outer_node_of_a_lattice_has_a_normal_corners_their_bisector(
    shape: gr.Shape,
) -> None:
    """outer_layer gives every node less than h deep a unit normal. These sizes put lattice
    nodes on corner bisectors (and a cube's on its edges' and corners' diagonals), where the
    signed distance's central differences straddle its kink and |grad phi| < 1 (the cosine of
    half the faces' angle at a polygon's corner): such nodes had been left without a normal,
    holes in the contact surface at two of a 1 mm hexagon's six corners. Their normal is the
    bisector, the differences' direction."""
    from granulate.shapes.discretize import lattice, outer_layer

    h = 0.2e-3
    positions, _ = lattice(shape, h)
    normals, _ = outer_layer(shape, positions, h)
    outer = -shape.signed_distance(positions) < h
    lengths = np.linalg.norm(normals, axis=1)
    np.testing.assert_allclose(lengths[outer], 1.0, rtol=1e-12)
    assert np.all(lengths[~outer] == 0)
    step = 1e-3 * h
    on_kink = 0
    for node, normal in zip(positions[outer], normals[outer], strict=True):
        gradient = np.zeros(3)
        for k in range(shape.dimension):
            e = np.zeros(3)
            e[k] = step
            ahead, behind = shape.signed_distance(np.stack([node + e, node - e]))
            gradient[k] = (ahead - behind) / (2 * step)
        if np.linalg.norm(gradient) < 1 - 1e-6:
            on_kink += 1
            np.testing.assert_allclose(normal, gradient / np.linalg.norm(gradient), atol=1e-9)
    assert on_kink > 0  # the case does test nodes on a bisector


def test_the_medial_axis_of_a_thin_part_gets_no_normal() -> None:
    """A strip one h thick: its one row of nodes lies on the medial axis between opposite faces
    (|grad phi| = 0) and gets no normal, so no surface point is put where no face is."""
    from granulate.shapes.discretize import lattice, outer_layer

    h = 0.2e-3
    strip = gr.Rectangle((0, 0), (4e-3, h))
    positions, _ = lattice(strip, h)
    normals, _ = outer_layer(strip, positions, h)
    middle = np.abs(positions[:, 1] - h / 2) < 1e-9 * h
    interior = middle & (positions[:, 0] > 2 * h) & (positions[:, 0] < 4e-3 - 2 * h)
    assert interior.sum() > 0
    assert np.all(np.linalg.norm(normals[interior], axis=1) == 0)
