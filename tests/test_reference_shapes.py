"""A reference shape discretised once and placed many times (translated, rotated, scaled)."""

from __future__ import annotations

import numpy as np
import pytest

import granulate as gr
from granulate import resources

ROCK = gr.Material(density=2000, youngs_modulus=1e8, poisson_ratio=0.25, fracture_energy=5.0)


def test_placed_particles_share_one_bond_family() -> None:
    """Shared bond storage does not grow with the number of particles."""
    reference = gr.ReferenceShape.from_shape(gr.Disc((0, 0), 1e-3), 1e-4)
    bytes_for, bonds_for = {}, {}
    for count in (1, 50):
        sim = gr.Simulation(2)
        for k in range(count):
            sim.add_particle(reference, ROCK, position=(3e-3 * k, 0), rotation=0.37 * k)
        sim.run(1)
        assert sim.core.contact_statistics.rebuilds == 1
        bytes_for[count] = sim._model.shared_bond_bytes()
        assert sim._model.family_count == 1 and sim._model.shape_count == 1
        bonds_for[count] = sim.bond_count
    assert bytes_for[50] == bytes_for[1]
    assert bonds_for[50] == 50 * bonds_for[1]  # every particle has all its bonds


@pytest.mark.parametrize("pair_law", ["granulate", "surface"])
@pytest.mark.parametrize("discretization", ["lattice", "conforming"])
def test_bodies_added_alike_share_one_bond_family(discretization: str, pair_law: str) -> None:
    """add_body at six places makes one family (the crushing bench case's 16 -> 2.8 B/bond);
    a larger, a finer and a jittered disc get their own. A copy bounces off a floor as the
    same disc alone does, to 1e-12 of its mesh size on the node spheres. Under the surface law
    the copies share the family too (their surface normals differ by 4e-12 and are compared
    within round-off: shape_sharing.py), but the disc alone is not followed to round-off: the
    anchors of a lattice's surface nodes are picked among equally near neighbours by round-off
    of the absolute coordinates, so the same disc 11 mm along ends 2.4e-5 h off (ARCHITECTURE.md,
    "The surface law")."""
    h, steps = 1e-4, 300  # the discs bounce off the floor by step 200

    def disc_sim(centres: list[tuple[float, float]]) -> gr.Simulation:
        sim = gr.Simulation(2, gravity=(0, -9.81))
        sim.contact = gr.Contact(pair_law=pair_law)
        for centre in centres:
            sim.add_body(
                gr.Disc(centre, 1e-3), ROCK, h, velocity=(0, -2.0), discretization=discretization
            )
        sim.add_wall(gr.Plane((0, 0), (0, 1)))
        return sim

    centres = [(2.2e-3 * k + 1e-3, 1.01e-3) for k in range(6)]
    together = disc_sim(centres)
    together.run(steps)
    assert together._model.family_count == 1 and together._model.shape_count == 1
    last = together.bodies[-1]
    alone = disc_sim(centres[-1:])
    alone.run(steps)
    copy = slice(last.first_node, last.first_node + last.node_count)
    assert np.mean(alone.velocities[:, 1]) > 1.0  # it has bounced
    if pair_law == "granulate":
        np.testing.assert_allclose(
            together.displacements[copy], alone.displacements, rtol=0, atol=1e-12 * h
        )

    others = gr.Simulation(2)
    variants = ((1e-3, h, 0.0), (1.2e-3, h, 0.0), (1e-3, 0.8 * h, 0.0), (1e-3, h, 0.1))
    for k, (radius, size, jitter) in enumerate(variants):
        others.add_body(gr.Disc((5e-3 * k, 0), radius), ROCK, size, jitter=jitter)
    others.run(1)
    assert others._model.shape_count == 4


def test_the_memory_check_counts_a_shared_bond_family_once(monkeypatch: pytest.MonkeyPatch) -> None:
    """50 equal discs added one by one fit in memory that their 50 bond families would not:
    the free memory is set between the two estimates. 50 discs of mesh sizes 0.1 % apart (no
    copies) are refused, naming the bonds."""
    h = 1e-4

    def discs(spread: float) -> gr.Simulation:
        sim = gr.Simulation(2)
        for k in range(50):
            sim.add_body(gr.Disc((2.2e-3 * k, 0), 1e-3), ROCK, h * (1 + spread * k))
        return sim

    sim = discs(0.0)
    nodes, per_disc = sim.node_count, sim.bodies[0].node_count
    bonds = per_disc * resources.bonds_per_node(2, ROCK.resolved_horizon(h) / h)
    shared = resources.simulation_bytes(nodes, bonds)
    separate = resources.simulation_bytes(nodes, 50 * bonds)
    free = (shared + separate) / 2 / resources.SHARE
    monkeypatch.setattr(resources, "available_memory", lambda: int(free))
    sim.run(1)
    assert sim._model.family_count == 1
    with pytest.raises(gr.InputError, match="bonds\\) would need about"):
        discs(1e-3).run(1)


@pytest.mark.parametrize("dimension", [2, 3])
def test_a_rotated_placement_behaves_as_the_rotated_body(dimension: int) -> None:
    """Pulling a placed, rotated particle gives the rotated displacements of the unrotated one."""
    shape = (
        gr.Rectangle((-2e-3, -1e-3), (2e-3, 1e-3))
        if dimension == 2
        else gr.Box((-2e-3, -1e-3, -1e-3), (2e-3, 1e-3, 1e-3))
    )
    reference = gr.ReferenceShape.from_shape(shape, 0.5e-3)
    angle = 0.6
    rotation = angle if dimension == 2 else np.array([0.0, 0.0, angle])
    R = gr.shapes.rotation_matrix(angle, 3)

    def pulled(rotated: bool) -> np.ndarray:
        sim = gr.Simulation(dimension, dt=2e-8)
        body = sim.add_particle(
            reference,
            ROCK,
            position=(0.01, 0.02, 0)[:dimension],
            rotation=rotation if rotated else None,
        )
        local = (sim.reference_positions - (0.01, 0.02, 0)) @ (R if rotated else np.eye(3))
        right = np.flatnonzero(local[:, 0] > 1.5e-3)
        left = np.flatnonzero(local[:, 0] < -1.5e-3)
        direction = (R if rotated else np.eye(3)) @ np.array([1.0, 0, 0])
        sim.prescribe_displacement(right, direction[:dimension], gr.Linear(0.5))
        sim.fix(left)
        sim.run(300)
        assert body.node_count == reference.node_count
        return sim.displacements @ (R if rotated else np.eye(3))  # back to the local frame

    np.testing.assert_allclose(pulled(True), pulled(False), rtol=0, atol=1e-12)


def test_a_scaled_placement_keeps_the_material_behaviour() -> None:
    """Scale s: the horizon follows the mesh (factor 3), so a homogeneous strain gives the same
    energy density; volumes grow as s^d."""
    reference = gr.ReferenceShape.from_shape(gr.Rectangle((0, 0), (6e-3, 6e-3)), 0.25e-3)
    densities = []
    for scale in (1.0, 2.5):
        material = gr.Material(density=2000, youngs_modulus=1e8, poisson_ratio=0.25, fracture=False)
        sim = gr.Simulation(2)
        sim.add_particle(reference, material, scale=scale)
        np.testing.assert_allclose(sim.volumes, reference.volumes * scale**2)
        X = sim.reference_positions
        sim.positions[:] = X * (1 + 1e-4)
        sim.positions[:, 2] = 0
        sim.core.compute_forces()
        densities.append(sim.core.strain_energy_density())
    np.testing.assert_allclose(densities[1], densities[0], rtol=1e-9)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"scale": 0.0}, "scale must be positive"),
        ({"rotation": np.eye(3)}, "in 2D, rotation is an angle"),
        ({"position": (1.0,)}, "position must be 2 finite numbers"),
    ],
)
def test_bad_placements_are_refused(kwargs: dict, message: str) -> None:
    reference = gr.ReferenceShape.from_shape(gr.Disc((0, 0), 1e-3), 2e-4)
    with pytest.raises(gr.InputError, match=message):
        gr.Simulation(2).add_particle(reference, ROCK, **kwargs)


def test_bad_rotation_matrix_and_dimension_mismatch() -> None:
    sphere = gr.ReferenceShape.from_shape(gr.Sphere((0, 0, 0), 1e-3), 2.5e-4)
    with pytest.raises(gr.InputError, match="determinant"):
        gr.Simulation(3).add_particle(sphere, ROCK, rotation=np.diag([1.0, 1.0, -1.0]))
    with pytest.raises(gr.InputError, match="3D but the simulation is 2D"):
        gr.Simulation(2).add_particle(sphere, ROCK)
