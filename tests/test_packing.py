"""Packings and placements: no overlaps, requested fractions and size statistics, seeds,
PeriDEM CSV files, and particles added from them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import granulate as gr

ROCK = gr.Material(density=2600, bulk_modulus=2.16e7, shear_modulus=1.296e7, fracture_energy=50)
# Copies of a PeriDEM deck's files (made by PeriDEM's set-up scripts), kept with the benchmarks.
DECK = (
    Path(__file__).resolve().parents[1] / "src" / "granulate" / "bench_cases" / "compression_small"
)


def grain(shape: gr.Shape, sizes: gr.SizeDistribution, fraction: float = 1.0) -> gr.Grain:
    return gr.Grain(shape, ROCK, 0.25 * shape.bounding_radius, sizes=sizes, fraction=fraction)


def assert_no_overlap(packing: gr.Packing, gap: float = 0.0) -> None:
    p, r = packing.positions, packing.radii
    d = packing.dimension
    for start in range(0, len(r), 500):
        chunk = slice(start, start + 500)
        distance = np.linalg.norm(p[chunk, None, :d] - p[None, :, :d], axis=2)
        reach = r[chunk, None] + r[None, :] + gap
        np.fill_diagonal(distance[:, start : start + 500], np.inf)
        assert np.all(distance >= reach * (1 - 1e-12)), "bounding spheres overlap"
    sd = packing.container.signed_distance(p)
    assert np.all(sd <= -(r + gap) * (1 - 1e-12)), "a particle leaves the container"


CONTAINERS = [
    gr.Rectangle((0, 0), (0.04, 0.03)),
    gr.Disc((0, 0), 0.02),
    gr.Polygon(((0, 0), (0.04, 0), (0.04, 0.015), (0.02, 0.015), (0.02, 0.035), (0, 0.035))),
    gr.Box((0, 0, 0), (0.012, 0.01, 0.01)),
    gr.Cylinder((0, 0, 0), 0.007, 0.014),
]


@pytest.mark.parametrize("method", ["random", "lattice"])
@pytest.mark.parametrize("container", CONTAINERS, ids=lambda c: type(c).__name__)
def test_packings_have_no_overlaps(container: gr.Shape, method: str) -> None:
    if container.dimension == 2:
        grains = [
            grain(gr.Disc((0, 0), 1e-3), gr.Uniform(0.5e-3, 1e-3), 2),
            grain(gr.RegularPolygon((0, 0), 1e-3, 6), gr.Uniform(0.5e-3, 1e-3), 1),
        ]
        count = 60
    else:
        grains = [grain(gr.Sphere((0, 0, 0), 1e-3), gr.Uniform(0.5e-3, 1e-3))]
        count = 40
    gap = 0.05e-3
    packing = gr.pack(container, grains, count, method=method, gap=gap, seed=3)
    assert len(packing) == count
    assert_no_overlap(packing, gap)
    assert 0 < packing.packing_fraction < 1


def test_number_fractions_are_exact_and_volume_fractions_are_met() -> None:
    box = gr.Rectangle((0, 0), (0.3, 0.3))
    small = grain(gr.Disc((0, 0), 1e-3), gr.Uniform(0.8e-3, 1.2e-3), 3)
    large = grain(gr.RegularPolygon((0, 0), 1e-3, 3), gr.Uniform(1.6e-3, 2.4e-3), 1)
    by_number = gr.pack(box, [small, large], 1001, seed=1)
    assert np.bincount(by_number.kinds).tolist() == [751, 250]
    by_volume = gr.pack(box, [small, large], 3000, by="volume", seed=1)
    unit = np.array([g.measure_at_unit_radius for g in (small, large)])
    volumes = unit[by_volume.kinds] * by_volume.radii**2
    share = volumes[by_volume.kinds == 0].sum() / volumes.sum()
    assert share == pytest.approx(0.75, abs=0.02)


def test_size_statistics_follow_the_distributions() -> None:
    rng = np.random.default_rng(0)
    n = 40_000
    uniform = gr.Uniform(1e-3, 2e-3).sample(rng, n)
    assert uniform.min() >= 1e-3 and uniform.max() <= 2e-3
    assert uniform.mean() == pytest.approx(1.5e-3, rel=0.01)
    assert uniform.std() == pytest.approx(1e-3 / np.sqrt(12), rel=0.02)
    normal = gr.Normal(1e-3, 0.1e-3).sample(rng, n)
    assert normal.mean() == pytest.approx(1e-3, rel=0.005)
    assert normal.std() == pytest.approx(0.1e-3 * 0.9866, rel=0.03)  # truncated at 3 sigma
    lognormal = gr.LogNormal(1e-3, 0.3).sample(rng, n)
    assert np.median(lognormal) == pytest.approx(1e-3, rel=0.02)
    assert np.log(lognormal).std() == pytest.approx(0.3 * 0.9866, rel=0.03)
    # Sieve: the mass passing each sieve opening (mass ~ r^3) matches the curve.
    curve = gr.Sieve((1e-3, 2e-3, 4e-3, 8e-3), (0.0, 0.2, 0.7, 1.0), dimension=3)
    radii = curve.sample(rng, 200_000)
    mass = radii**3
    for diameter, passing in zip(curve.diameters, curve.passing, strict=True):
        assert mass[2 * radii <= diameter].sum() / mass.sum() == pytest.approx(passing, abs=0.02)


def test_packings_are_reproducible_with_a_seed() -> None:
    box = gr.Rectangle((0, 0), (0.03, 0.03))
    g = [grain(gr.Disc((0, 0), 1e-3), gr.Uniform(0.6e-3, 1e-3))]
    a, b = gr.pack(box, g, 50, seed=7), gr.pack(box, g, 50, seed=7)
    np.testing.assert_array_equal(a.positions, b.positions)
    np.testing.assert_array_equal(a.rotations, b.rotations)
    assert not np.array_equal(a.positions, gr.pack(box, g, 50, seed=8).positions)


def test_a_full_container_is_reported_with_the_count_that_fits() -> None:
    box = gr.Rectangle((0, 0), (0.01, 0.01))
    g = [grain(gr.Disc((0, 0), 1e-3), gr.Fixed(1e-3))]
    with pytest.raises(gr.InputError, match=r"holds only \d+ of the 40 particles"):
        gr.pack(box, g, 40, attempts=200)
    with pytest.raises(gr.InputError, match=r"holds only \d+ lattice sites"):
        gr.pack(box, g, 40, method="lattice")
    with pytest.raises(gr.InputError, match="sizes"):
        gr.pack(box, [gr.Grain(gr.Disc((0, 0), 1e-3), ROCK, 1e-4)], 3)
    with pytest.raises(gr.InputError, match="3D grain"):
        gr.pack(box, [grain(gr.Sphere((0, 0, 0), 1e-3), gr.Fixed(1e-3))], 3)


def test_peridem_placement_files_are_read_and_written(tmp_path: Path) -> None:
    path = DECK / "particle_locations_0.csv"
    placements = gr.read_placements(path)
    assert len(placements) == 15
    assert placements.kinds.min() == 0
    np.testing.assert_allclose(placements.positions[0], [0.004808, -0.002797, 0.0])
    assert placements.radii[0] == pytest.approx(0.000968)
    assert placements.rotations[0] == pytest.approx(4.974530)
    placements.write_csv(tmp_path / "again.csv")
    again = gr.read_placements(tmp_path / "again.csv")
    np.testing.assert_allclose(again.positions, placements.positions)
    np.testing.assert_array_equal(again.kinds, placements.kinds)
    # Without an orientation column: random orientations, reproducible with the seed.
    (tmp_path / "loc_rad.csv").write_text("i, x, y, z, r\n0, 0, 0, 0, 1e-3\n1, 3e-3, 0, 0, 1e-3\n")
    first = gr.read_placements(tmp_path / "loc_rad.csv", seed=2)
    second = gr.read_placements(tmp_path / "loc_rad.csv", seed=2)
    np.testing.assert_array_equal(first.rotations, second.rotations)


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ("i, x, y, z, r\n0, 0, 0, 0, -1e-3\n", "non-positive radius"),
        ("i, x, y, z, r\n0, 0, 0, 0\n", r"5 or 6 columns \(i, x, y, z, r"),
        ("i, x, y, z, r\n-1, 0, 0, 0, 1e-3\n", "zone ids"),
        ("i, x, y, z, r\n0, 0, zero, 0, 1e-3\n", "line 2: expected numbers"),
        ("i, x, y, z, r\n", "holds no particles"),
    ],
)
def test_bad_placement_files_give_clear_errors(tmp_path: Path, content: str, message: str) -> None:
    path = tmp_path / "bad.csv"
    path.write_text(content)
    with pytest.raises(gr.InputError, match=message):
        gr.read_placements(path)
    with pytest.raises(gr.InputError, match="does not exist"):
        gr.read_placements(tmp_path / "missing.csv")


def test_a_packing_becomes_particles_that_do_not_touch_at_the_start() -> None:
    box = gr.Rectangle((0, 0), (0.02, 0.02))
    grains = [
        grain(gr.Disc((0, 0), 1e-3), gr.Uniform(0.7e-3, 1e-3)),
        grain(gr.Drum2D((0, 0), 1e-3, 0.4e-3), gr.Uniform(0.7e-3, 1e-3)),
    ]
    packing = gr.pack(box, grains, 30, gap=0.3e-3, seed=4)
    sim = gr.Simulation(2, gravity=(0, -9.81))
    sim.contact = gr.Contact(restitution=0.5)
    sim.add_wall(gr.walls.container(box))
    bodies = sim.add_packing(packing)
    assert len(bodies) == 30
    assert sim.model.material_count == 1
    for k, body in enumerate(bodies):
        nodes = sim.positions[body.nodes]
        reach = np.linalg.norm(nodes - packing.positions[k], axis=1).max()
        assert reach <= packing.radii[k] * (1 + 1e-9)
        g = packing.grains[packing.kinds[k]]
        assert body.mesh_size == pytest.approx(g.mesh_size * packing.radii[k] / g.radius)
    sim.run(1)
    assert sim.core.contact_statistics.node_contacts == 0
    assert sim.core.contact_statistics.wall_contacts == 0


@pytest.mark.parametrize("dimension", [2, 3])
def test_placements_now_follow_bodies_moved_rigidly(dimension: int) -> None:
    """Particles turned and shifted rigidly in the simulation: placements_now gives each one's
    new position and rotation, and a second simulation built from them has the same nodes to
    1e-12 m (2D: angles added; 3D: rotations composed, as rotation vectors)."""
    from granulate.shapes import rotation_matrix

    material = gr.Material(density=1000, youngs_modulus=1e7, poisson_ratio=0.25, fracture=False)
    if dimension == 2:
        container, grain_shape = (
            gr.Rectangle((0, 0), (8e-3, 8e-3)),
            gr.RegularPolygon((0, 0), 1e-3, 6),
        )
    else:
        container, grain_shape = (
            gr.Box((0, 0, 0), (8e-3, 8e-3, 8e-3)),
            gr.Box((-7e-4,) * 3, (7e-4,) * 3),
        )
    grain = gr.Grain(grain_shape, material, 3e-4, gr.Uniform(0.9e-3, 1.1e-3))
    packing = gr.pack(container, [grain], 4, method="lattice", seed=3)
    sim = gr.Simulation(dimension)
    bodies = sim.add_packing(packing)
    turn = 0.7 if dimension == 2 else np.array([0.3, -0.5, 0.9])
    rotation = rotation_matrix(turn, dimension)
    for k, body in enumerate(bodies):
        nodes = slice(body.first_node, body.first_node + body.node_count)
        centre = sim.positions[nodes].mean(axis=0)
        sim.positions[nodes] = (
            centre + (sim.positions[nodes] - centre) @ rotation.T + [20e-3 * k, 2e-3, 0]
        )
    moved = sim.placements_now(bodies, packing)
    again = gr.Simulation(dimension)
    again.add_packing(moved)
    np.testing.assert_allclose(again.positions, sim.positions, rtol=0, atol=1e-12)
    with pytest.raises(gr.InputError, match="3 bodies for 4 placements"):
        sim.placements_now(bodies[:3], packing)
