"""Particles against rigid walls (DESIGN.md section 3, "Walls"): a block sliding on a floor
stops at the Coulomb distance, particles at rest load the floor with their weight, rotating
drums and cylinders carry grains up by friction, a floor read from an STL file, a flexible wall
made of a constrained particle. Helpers shared with the pair tests: test_contact.py."""

from __future__ import annotations

import numpy as np
import pytest

import granulate as gr

from .test_contact import (
    SOFT,
    STIFF,
    body_centre,
    body_velocity,
    mean_vertical_load,
)


def sliding_block(dimension: int, friction: float, speed: float):
    rubber = gr.Material(density=1000, youngs_modulus=5e6, poisson_ratio=0.25, fracture=False)
    g = 9.81
    sim = gr.Simulation(dimension, gravity=(0, -g, 0)[:dimension])
    sim.contact = gr.Contact(restitution=0.3, friction=friction)
    h = 1e-3
    if dimension == 2:
        block = sim.add_body(gr.Rectangle((0, 0.5 * h), (10 * h, 5.5 * h)), rubber, h)
        sim.add_wall(gr.Plane((0, 0), (0, 1)), name="floor")
    else:
        block = sim.add_body(gr.Box((0, 0.5 * h, 0), (8 * h, 4.5 * h, 8 * h)), rubber, h)
        sim.add_wall(gr.Plane((0, 0, 0), (0, 1, 0)), name="floor")
    sim.run(until=0.02)  # land and settle
    return sim, block, g


@pytest.mark.validation
@pytest.mark.parametrize("dimension", [2, 3])
def test_sliding_block_stops_at_coulomb_distance(dimension: int) -> None:
    mu, v0 = 0.4, 0.3
    sim, block, g = sliding_block(dimension, mu, v0)
    start = body_centre(sim, block)[0]
    launched = sim.time
    sim.velocities[:, 0] += v0
    while body_velocity(sim, block)[0] > 1e-3:
        sim.run(50)
    distance = body_centre(sim, block)[0] - start
    expected = v0**2 / (2 * mu * g)
    assert abs(distance / expected - 1) < 0.05, f"slid {distance:.5f} m, expected {expected:.5f} m"
    assert abs((sim.time - launched) / (v0 / (mu * g)) - 1) < 0.05  # deceleration mu g


@pytest.mark.validation
@pytest.mark.parametrize("dimension", [2, 3])
def test_particles_at_rest_load_the_floor_with_their_weight(dimension: int) -> None:
    """A pile of particles settled in a box (background damping removes the elastic vibrations
    that peridynamic bodies otherwise keep): the floor carries the total weight within 1 %."""
    g = 9.81
    sim = gr.Simulation(dimension, gravity=(0, -g, 0)[:dimension], viscous_damping=30.0)
    sim.contact = gr.Contact(restitution=0.3, friction=0.3)
    h = 0.5e-3
    centres = [
        (-1.3e-3, 1.6e-3),
        (1.3e-3, 1.6e-3),
        (0.0, 4.0e-3),
        (-1.5e-3, 6.6e-3),
        (1.5e-3, 6.8e-3),
    ]
    for x, y in centres:
        shape = gr.Disc((x, y), 1e-3) if dimension == 2 else gr.Sphere((x, y, 0), 1e-3)
        sim.add_body(shape, SOFT, h)
    if dimension == 2:
        sim.add_wall(gr.BoxContainer((-3e-3, 0), (3e-3, 20e-3)), name="box")
    else:
        sim.add_wall(gr.BoxContainer((-3e-3, 0, -1.5e-3), (3e-3, 20e-3, 1.5e-3)), name="box")
    weight = float(np.sum(sim.volumes) * SOFT.density * g)
    sim.run(until=0.08)
    # At rest: a late slip of one particle (at about 0.08 s in some runs) must have died out.
    while sim.kinetic_energy() > 1e-3 * weight * 1e-6 and sim.time < 0.3:
        sim.run(until=sim.time + 0.01)
    load = mean_vertical_load(sim, "box", 50)
    assert abs(load / weight - 1) < 0.01, f"floor load {load / weight:.4f} x weight"


@pytest.mark.validation
def test_rotating_drum_carries_a_particle_up_by_friction(full: bool) -> None:
    """A disc at the bottom of a drum turning counter-clockwise rides up the rising side with
    friction, and stays at the bottom without it: at 2 rad/s past 10 degrees in 0.15 s
    (--full; measured 16.8); the smoke test turns the drum at 8 rad/s for 0.04 s: past 5
    degrees (measured 7.5). Without friction: within 2 degrees of the bottom (measured 0.0)."""
    rate, until, angle = (2.0, 0.15, 10.0) if full else (8.0, 0.04, 5.0)

    def final_angle(friction: float) -> float:
        sim = gr.Simulation(2, gravity=(0, -9.81))
        sim.contact = gr.Contact(restitution=0.3, friction=friction)
        disc = sim.add_body(gr.Disc((0, -8.85e-3), 1e-3), SOFT, 0.25e-3)
        sim.add_wall(
            gr.Wall((gr.CircleContainer((0, 0), 10e-3),), motion=gr.Rotation.steady(rate)),
            name="drum",
        )
        sim.run(until=until)
        x, y, _ = body_centre(sim, disc)
        return float(np.degrees(np.arctan2(x, -y)))  # 0 at the bottom, positive towards +x

    with_friction, frictionless = final_angle(0.8), final_angle(0.0)
    assert with_friction > angle, f"carried only {with_friction:.1f} degrees"
    assert abs(frictionless) < 2.0, f"frictionless disc moved {frictionless:.1f} degrees"


@pytest.mark.validation
def test_sphere_rests_on_a_triangle_mesh_floor_read_from_stl(tmp_path) -> None:
    """3D walls from an STL file: a box-shaped container of 12 triangles (outward normals); a
    sphere set down on its floor loads it with its weight within 1 % after 20 ms (measured
    0.9996)."""
    import meshio

    side = 4e-3
    corners = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], dtype=float)
    corners = (corners - [0.5, 0.0, 0.5]) * side
    triangles = np.array(
        [
            [0, 2, 3],
            [0, 3, 1],
            [4, 5, 7],
            [4, 7, 6],
            [0, 1, 5],
            [0, 5, 4],
            [2, 6, 7],
            [2, 7, 3],
            [1, 3, 7],
            [1, 7, 5],
            [0, 4, 6],
            [0, 6, 2],
        ]
    )
    path = tmp_path / "box.stl"
    meshio.write(path, meshio.Mesh(corners, [("triangle", triangles)]))
    g = 9.81
    sim = gr.Simulation(3, gravity=(0, -g, 0), viscous_damping=30.0)
    sim.contact = gr.Contact(restitution=0.3, friction=0.3)
    sim.add_body(gr.Sphere((0, 1.005e-3, 0), 1e-3), SOFT, 0.25e-3)
    sim.add_wall(gr.TriangleMesh.from_file(path), name="box")
    weight = float(np.sum(sim.volumes) * SOFT.density * g)
    sim.run(until=0.02)
    load = mean_vertical_load(sim, "box", 20)
    assert abs(load / weight - 1) < 0.01, f"floor load {load / weight:.4f} x weight"


@pytest.mark.validation
def test_flexible_wall_made_of_a_constrained_particle_carries_a_disc() -> None:
    """PeriDEM's meshed walls are particles with every node held: a disc set down on one loads
    it with its weight after 20 ms (the reaction is the held nodes' force)."""
    g = 9.81
    sim = gr.Simulation(2, gravity=(0, -g), viscous_damping=30.0)
    sim.contact = gr.Contact(restitution=0.3, friction=0.3)
    slab = sim.add_body(gr.Rectangle((-3e-3, -1e-3), (3e-3, 0)), STIFF, 0.25e-3, name="slab")
    disc = sim.add_body(gr.Disc((0, 1.02e-3), 1e-3), SOFT, 0.25e-3)
    sim.fix(slab.nodes)
    weight = float(np.sum(sim.volumes[disc.nodes]) * SOFT.density * g)
    sim.run(until=0.02)
    # The contact force chatters (sample standard deviation 0.42 x the weight), so the mean is
    # taken over 4,000 steps: 1.0006 x the weight (0.9904 when dropped from 0.4 mm for 50 ms).
    loads = []
    for _ in range(200):
        sim.run(20)
        # Held nodes: the force density that holds them is minus what acts on them.
        loads.append(
            -float(
                np.sum((sim.forces[slab.nodes, 1] - STIFF.density * -g) * sim.volumes[slab.nodes])
            )
        )
    assert abs(np.mean(loads) / weight - 1) < 0.02, (
        f"slab load {np.mean(loads) / weight:.4f} x weight"
    )


@pytest.mark.validation
def test_rotating_cylinder_carries_a_sphere_up_by_friction(full: bool) -> None:
    """3D: a sphere in a cylinder turning about z rides up the rising side with friction: at
    2 rad/s past 10 degrees in 0.1 s (--full; measured 10.8). The smoke test turns the drum at
    8 rad/s for 0.03 s: past 4 degrees (measured 5.0; 0.0 without friction)."""
    rate, until, angle = (2.0, 0.1, 10.0) if full else (8.0, 0.03, 4.0)
    sim = gr.Simulation(3, gravity=(0, -9.81, 0))
    sim.contact = gr.Contact(restitution=0.3, friction=0.8)
    sphere = sim.add_body(gr.Sphere((0, -8.8e-3, 0), 1e-3), SOFT, 0.25e-3)
    drum = gr.Wall(
        (gr.CircleContainer((0, 0, 0), 10e-3, axis=(0, 0, 1)),), motion=gr.Rotation.steady(rate)
    )
    sim.add_wall(drum, name="drum")
    sim.run(until=until)
    x, y, _ = body_centre(sim, sphere)
    assert np.degrees(np.arctan2(x, -y)) > angle
