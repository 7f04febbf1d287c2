"""Particles against rigid walls (DESIGN.md section 3, "Walls"): a block sliding on a floor
stops at the Coulomb distance, particles at rest load the floor with their weight, a grain in
a turning drum rolls as a rigid one does, a floor read from an STL file, a flexible wall
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


def rigid_rolling_peak(dimension: int, rate: float, drum: float, radius: float) -> float:
    """The highest angle [degrees] a rigid disc (sphere) starting at rest at the bottom of a drum
    turning at `rate` reaches, rolling without slip and without rolling resistance: friction
    first spins it up, conserving its angular momentum about the contact point, so it rolls off
    at v = rate drum k / (1 + k) (k = I / (m R^2): 1/2 for a disc, 2/5 for a sphere); then
    (1 + k) v^2 / 2 = g L (1 - cos theta), L = drum - radius."""
    k = 0.5 if dimension == 2 else 0.4
    speed = rate * drum * k / (1 + k)
    return float(np.degrees(np.arccos(1 - (1 + k) * speed**2 / (2 * 9.81 * (drum - radius)))))


def drum_angles(dimension: int, friction: float, nodes_across_radius: int, until: float):
    """A disc (sphere) of radius 1 mm set on the bottom of a drum of radius 10 mm turning
    counter-clockwise at 2 rad/s, under the surface law: its angle from the bottom [degrees,
    positive towards +x] every 2 ms."""
    radius, drum = 1e-3, 10e-3
    sim = gr.Simulation(dimension, gravity=(0, -9.81, 0)[:dimension])
    sim.contact = gr.Contact(restitution=0.3, friction=friction, pair_law="surface")
    h = radius / nodes_across_radius
    if dimension == 2:
        grain = sim.add_body(gr.Disc((0, radius - drum), radius), SOFT, h)
        wall = gr.CircleContainer((0, 0), drum)
    else:
        grain = sim.add_body(gr.Sphere((0, radius - drum, 0), radius), SOFT, h)
        wall = gr.CircleContainer((0, 0, 0), drum, axis=(0, 0, 1))
    sim.add_wall(gr.Wall((wall,), motion=gr.Rotation.steady(2.0)), name="drum")
    angles = []
    while sim.time < until:
        sim.run(until=sim.time + 0.002)
        x, y = body_centre(sim, grain)[:2]
        angles.append(float(np.degrees(np.arctan2(x, -y))))
    return np.array(angles)


@pytest.mark.validation
@pytest.mark.parametrize("dimension", [2, 3])
def test_a_grain_in_a_turning_drum_rolls_as_a_rigid_one_does(dimension: int, full: bool) -> None:
    """Friction spins a grain at the bottom of a turning drum up until it rolls on the drum's
    surface; it then swings about the bottom like a pendulum, up to the rigid-rolling peak
    (rigid_rolling_peak: 1.574 degrees for the disc, 1.304 for the sphere, 58-62 ms in).
    The deformable grain's flattened contact resists rolling a little, less as h falls.
    Measured peak / rigid at af1eaf8: 1.027 (disc, R/h = 8), 1.024 (sphere, R/h = 4); at
    30b26df, before the surface points' fades, 1.53 (disc and sphere at R/h = 4), 1.15 (disc,
    R/h = 8; sphere, R/h = 6), 1.038 (disc, R/h = 12), 1.036 (disc, R/h = 16), 1.098 (sphere,
    R/h = 8). Asserted: within 20 % at R/h = 8 (disc) and 4 (sphere; 17 s, against 72 s at
    R/h = 6), within 6 % and 12 % at 12 and 8 (--full); and without friction the grain stays
    within 0.5 degrees of the bottom (the sphere under --full). On the node spheres of pair_law
    "granulate" the staircase of the grain's outer nodes catches on the drum: both grains
    (R/h = 4) are dragged up 11.5 degrees in 0.1 s (7.3 and 8.8 times the peak)."""
    coarse, fine = (8, 12) if dimension == 2 else (4, 8)
    peak = drum_angles(dimension, 0.8, fine if full else coarse, until=0.07).max()
    theory = rigid_rolling_peak(dimension, 2.0, 10e-3, 1e-3)
    tolerance = (0.06 if dimension == 2 else 0.12) if full else 0.20
    assert peak / theory == pytest.approx(1.0, abs=tolerance), f"peak {peak:.3f} degrees"
    if dimension == 2 or full:
        frictionless = drum_angles(dimension, 0.0, 4, until=0.02)
        moved = np.abs(frictionless).max()
        assert moved < 0.5, f"frictionless grain moved {moved:.2f} degrees"


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
