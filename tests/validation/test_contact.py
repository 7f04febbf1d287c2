"""Contact validation (DESIGN.md section 6): restitution of two-particle collisions, energy of
elastic collisions, Newton's third law (momentum), angular momentum, grains of different sizes,
the sideways kick of head-on impacts, fragments in contact (against walls: test_walls.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import granulate as gr

SOFT = gr.Material(density=1200, bulk_modulus=2.16e7, shear_modulus=1.296e7, fracture=False)
STIFF = gr.Material(density=3000, bulk_modulus=5e8, shear_modulus=3e8, fracture=False)


def body_velocity(sim: gr.Simulation, body: gr.Body) -> np.ndarray:
    nodes = slice(body.first_node, body.first_node + body.node_count)
    return np.average(sim.velocities[nodes], axis=0, weights=sim.volumes[nodes])


def body_centre(sim: gr.Simulation, body: gr.Body) -> np.ndarray:
    nodes = slice(body.first_node, body.first_node + body.node_count)
    return np.average(sim.positions[nodes], axis=0, weights=sim.volumes[nodes])


def mean_vertical_load(sim: gr.Simulation, wall: str, samples: int = 20) -> float:
    """Mean downward force of the particles on a wall over `samples` x 20 steps [N or N/m]."""
    loads = []
    for _ in range(samples):
        sim.run(20)
        loads.append(-sim.wall_reactions()[wall][1])
    return float(np.mean(loads))


def collide(
    dimension: int,
    restitution: float,
    *,
    radius: float = 1e-3,
    other_radius: float = 1e-3,
    other: gr.Material = SOFT,
    offset: float = 0.0,
    speed: float = 0.2,
    nodes_across_radius: int = 10,
    friction: float = 0.0,
    discretization: str = "lattice",
    same_nodes_per_radius: bool = False,
    material: gr.Material = SOFT,
    stiffness_factor: float = 1.0,
) -> tuple[float, float, gr.Simulation, tuple[gr.Body, gr.Body], np.ndarray]:
    """Two particles approach head-on (offset: lateral shift of the second, for oblique impacts).
    ``same_nodes_per_radius``: the second is meshed with its own h = other_radius /
    nodes_across_radius (a scaled reference shape), else with the first's.

    Returns (normal restitution, final/initial total energy, simulation, bodies, initial momentum).
    """
    sim = gr.Simulation(dimension)
    sim.contact = gr.Contact(
        restitution=restitution, friction=friction, stiffness_factor=stiffness_factor
    )
    h = radius / nodes_across_radius
    other_h = other_radius / nodes_across_radius if same_nodes_per_radius else h
    x2 = radius + other_radius + 1.5 * max(h, other_h)
    kw = {"discretization": discretization}
    if dimension == 2:
        a = sim.add_body(gr.Disc((0, 0), radius), material, h, velocity=(speed / 2, 0), **kw)
        b = sim.add_body(
            gr.Disc((x2, offset), other_radius), other, other_h, velocity=(-speed / 2, 0), **kw
        )
    else:
        a = sim.add_body(
            gr.Sphere((0, 0, 0), radius), material, h, velocity=(speed / 2, 0, 0), **kw
        )
        b = sim.add_body(
            gr.Sphere((x2, offset, 0), other_radius),
            other,
            other_h,
            velocity=(-speed / 2, 0, 0),
            **kw,
        )
    masses = sim.volumes * np.where(
        np.arange(sim.node_count) < a.node_count, material.density, other.density
    )
    momentum = (masses[:, None] * sim.velocities).sum(axis=0)
    energy = sim.kinetic_energy()
    velocity_b = body_velocity(sim, b)
    before = body_velocity(sim, a) - velocity_b
    touched = False
    for _ in range(100_000):
        sim.run(10)
        in_contact = sim.core.contact_statistics.node_contacts > 0
        touched = touched or in_contact
        if touched and not in_contact:
            break
    assert touched, "the particles never touched"
    sim.run(100)
    after = body_velocity(sim, a) - body_velocity(sim, b)
    # The normal of a finite-duration contact is the direction of its impulse.
    normal = body_velocity(sim, b) - velocity_b
    normal /= np.linalg.norm(normal)
    e = -float(after @ normal) / float(before @ normal)
    total = (sim.kinetic_energy() + sim.strain_energy()) / energy
    return e, total, sim, (a, b), momentum


@pytest.mark.validation
@pytest.mark.parametrize("restitution", [0.5, 0.8, 0.95])
def test_head_on_restitution_of_discs(restitution: float) -> None:
    e, _, _, _, _ = collide(2, restitution, nodes_across_radius=10)
    assert abs(e - restitution) < 0.05, f"measured e = {e:.3f} for requested {restitution}"


@pytest.mark.validation
def test_head_on_restitution_of_spheres(full: bool) -> None:
    """R/h = 6; the smoke test runs e = 0.8 (the discs run all three)."""
    for restitution in (0.5, 0.8, 0.95) if full else (0.8,):
        e, _, _, _, _ = collide(3, restitution, nodes_across_radius=6)
        assert abs(e - restitution) < 0.05, f"measured e = {e:.3f} for requested {restitution}"


@pytest.mark.validation
@pytest.mark.parametrize("restitution", [0.5, 0.8, 0.95])
def test_restitution_with_different_sizes_materials_and_resolutions(
    restitution: float, full: bool
) -> None:
    cases = [dict(other_radius=0.6e-3, other=STIFF), dict(nodes_across_radius=6), dict(speed=1.0)]
    if full:
        cases += [dict(nodes_across_radius=16), dict(nodes_across_radius=20)]
    for case in cases:
        e, _, _, _, _ = collide(2, restitution, **case)
        assert abs(e - restitution) < 0.05, (
            f"{case}: measured e = {e:.3f} for requested {restitution}"
        )


@pytest.mark.validation
@pytest.mark.parametrize("offset", [0.3e-3, 0.6e-3])
@pytest.mark.parametrize("restitution", [0.5, 0.8, 0.95, 1.0])
def test_oblique_restitution_of_smooth_discs(restitution: float, offset: float) -> None:
    """Normal restitution of an oblique impact, centres offset by 0.3 and 0.6 radius (the normal
    is the direction of the impulse), for discs with conforming (ring) nodes: their surfaces are
    smooth, so a frictionless contact passes little tangential impulse. e = 1 keeps the energy.
    Measured: 0.499 / 0.792 / 0.938 at 0.3 R and 0.468 / 0.764 / 0.913 at 0.6 R.

    Lattice discs are staircases, not discs: their steps catch each other and turn part of the
    normal impulse into spin. At 0.3 R and 0.6 R they return e = 0.41 and 0.36 for 0.5, 0.71 and
    0.69 for 0.8 (the dashpot acts at the contact point, along the staircase's normal); use the
    conforming discretisation for round grains in oblique impacts.
    """
    e, energy, _, _, _ = collide(2, restitution, offset=offset, discretization="conforming")
    assert abs(e - restitution) < 0.05, f"measured e = {e:.3f} for requested {restitution}"
    if restitution == 1.0:
        assert abs(energy - 1) < 0.01


@pytest.mark.validation
def test_oblique_restitution_of_smooth_spheres(full: bool) -> None:
    """3D oblique impact at an offset of 0.3 radius, conforming spheres with R/h = 10 at
    0.2 m/s (--full; measured 0.529, 0.806, 0.939 for 0.5, 0.8, 0.95). On the node spheres
    coarser spheres were too bumpy: at R/h = 6 an e = 1 impact returned 0.86 (conforming) and
    0.42 (lattice) of the normal speed; under the surface law it returns 0.999 at 0.5 m/s.
    The smoke test: e = 0.8 at R/h = 6 and 0.5 m/s, a shorter approach and impact (measured
    0.801 in 2.3 s; 0.799 at R/h = 7 in 3.7 s; 0.790 at R/h = 8)."""
    cases = [(0.5, 10, 0.2), (0.8, 10, 0.2), (0.95, 10, 0.2)] if full else [(0.8, 6, 0.5)]
    for restitution, nodes_across_radius, speed in cases:
        e, _, _, _, _ = collide(
            3,
            restitution,
            offset=0.3e-3,
            speed=speed,
            nodes_across_radius=nodes_across_radius,
            discretization="conforming",
        )
        assert abs(e - restitution) < 0.05, f"measured e = {e:.3f} for requested {restitution}"


@pytest.mark.validation
@pytest.mark.parametrize("dimension", [2, 3])
def test_elastic_collision_conserves_energy(dimension: int) -> None:
    e, total, _, _, _ = collide(dimension, 1.0, nodes_across_radius=10 if dimension == 2 else 6)
    assert abs(total - 1) < 0.01, f"total energy changed by {total - 1:.3%}"
    assert e > 0.97


@pytest.mark.validation
def test_momentum_is_conserved_with_damping_and_friction() -> None:
    """Newton's third law for every contact force: momentum is conserved to round-off."""
    _, _, sim, (a, _), momentum = collide(2, 0.6, offset=0.8e-3, friction=0.5)
    masses = sim.volumes * np.where(
        np.arange(sim.node_count) < a.node_count, SOFT.density, SOFT.density
    )
    after = (masses[:, None] * sim.velocities).sum(axis=0)
    scale = np.abs(masses[:, None] * sim.velocities).sum()
    np.testing.assert_allclose(after, momentum, rtol=0, atol=1e-12 * scale)


@pytest.mark.validation
@pytest.mark.parametrize("dimension", [2, 3])
def test_restitution_of_grains_of_different_sizes_meshed_alike(dimension: int, full: bool) -> None:
    """A 0.5 mm grain against a 2 mm one (with --full in 2D also 0.2 mm), each with 10 nodes per
    radius (3D: 6), so the small one is meshed four (ten) times finer, as a scaled reference
    shape is: the requested e within 0.05 and no sideways kick (under 1 % of the approach).
    PeriDEM's node-pair law (one Rc from the finer mesh) gave e = 0.46 / 0.68 / 0.75 for 0.6 /
    0.9 / 1.0 here (fine nodes slipped between coarse ones).

    With --full also 0.01 m/s and, for stiffer grains, 10 m/s (an impact at 10 m/s is 7 % of
    the soft grains' wave speed). Measured at 10 m/s under the surface law (the default), 2D:
    e = 0.571 / 0.854 / 0.947 for 0.6 / 0.9 / 1.0, lateral 0.03-0.05 % of the approach: the
    elastic impact conserves the total energy to 1e-5 and leaves 10 % of it in the grains'
    vibration, so e = 1 is asserted within 0.06, not 0.05 (the node spheres: 0.571 / 0.866 /
    0.963, with 12-17 % lateral kicks for rotated grains). Radius ratio 10 (0.2 mm on 2 mm,
    --full, 2D): 0.584 / 0.858 / 0.948 at 0.05 m/s and 0.566 / 0.822 / 0.905 at 1 m/s for 0.6
    / 0.9 / 1.0 (the node spheres: 0.573 / - / 0.963), the elastic impact conserving the total
    energy to 1e-5 and leaving 18 % of the collision's energy in the 2 mm grain's vibration.
    That is the large grain's elastic response, not its coarse surface: meshed at R/h = 20 /
    40 it returns 0.913 / 0.911 for 1.0 at 1 m/s (the node spheres 0.922 / 0.927), so e
    within 0.05 of 0.9 and 1.0 is out of reach for resolved elastic grains of this size ratio
    whatever the contact law; asserted within 0.1 there (ARCHITECTURE.md, "The surface law").
    3D: 0.594 / 0.898 / 1.000 at the default stiffness, lateral 0.01-0.03 %; the contact
    layer is just overrun at 0.9 and 1.0 (node pairs within 50-52 % of their contact radius,
    and the run warns). On the node spheres the 3D impact overran it further (e = 0.543 /
    0.881 / 1.000) and needed stiffness_factor 10 (0.574 / 0.891 / 0.998). The default suite
    runs in 2D e = 0.6 at 0.05 m/s and e = 1.0 at 1 m/s, in 3D e = 0.6 at 1 m/s (measured
    0.594; the elastic 3D impact, 1.000, took as long again and runs under --full)."""
    npr = 10 if dimension == 2 else 6
    if full:
        speeds = (0.01, 0.05, 1.0) if dimension == 2 else (0.05, 1.0)  # 3D 0.01 m/s: 150 s each
        impacts = [(v, SOFT, 0.5e-3, 1.0) for v in speeds]
        impacts += [(10.0, STIFF, 0.5e-3, 1.0)]
        if dimension == 2:  # radius ratio 10
            impacts += [(0.05, SOFT, 0.2e-3, 1.0), (1.0, SOFT, 0.2e-3, 1.0)]
        cases = [(*impact, e) for impact in impacts for e in (0.6, 0.9, 1.0)]
    elif dimension == 2:  # the slow impact damped, the fast one elastic
        cases = [(0.05, SOFT, 0.5e-3, 1.0, 0.6), (1.0, SOFT, 0.5e-3, 1.0, 1.0)]
    else:  # the elastic one, as in 2D, under --full
        cases = [(1.0, SOFT, 0.5e-3, 1.0, 0.6)]
    for speed, material, radius, stiffness_factor, restitution in cases:
        e, _, sim, (a, b), _ = collide(
            dimension,
            restitution,
            radius=radius,
            other_radius=2e-3,
            speed=speed,
            nodes_across_radius=npr,
            same_nodes_per_radius=True,
            material=material,
            other=material,
            stiffness_factor=stiffness_factor,
        )
        tolerance = 0.05  # the target; the known shortfalls above:
        if dimension == 2 and speed == 10.0 and restitution == 1.0:
            tolerance = 0.06
        if radius == 0.2e-3 and restitution >= 0.9:
            tolerance = 0.1
        assert abs(e - restitution) < tolerance, f"{radius} m, {speed} m/s: e = {e:.3f}"
        lateral = body_velocity(sim, a)[1:] - body_velocity(sim, b)[1:]
        assert np.all(np.abs(lateral) < 0.01 * speed)


def angular_momentum(sim: gr.Simulation, densities: np.ndarray) -> np.ndarray:
    masses = sim.volumes * densities
    return np.sum(masses[:, None] * np.cross(sim.positions, sim.velocities), axis=0)


def momentum_scale(sim: gr.Simulation, densities: np.ndarray) -> float:
    """sum_i m_i |x_i x v_i|: the scale against which angular momentum's round-off is judged."""
    moments = np.linalg.norm(np.cross(sim.positions, sim.velocities), axis=1)
    return float(np.sum(moments * sim.volumes * densities))


def run_through_contact(sim: gr.Simulation) -> None:
    """Runs 20 steps at a time until the bodies have touched and parted again."""
    touched = False
    while not touched or sim.core.contact_statistics.node_contacts > 0:
        sim.run(20)
        touched = touched or sim.core.contact_statistics.node_contacts > 0


def oblique_pair(
    dimension: int, friction: float, pair_law: str = "granulate", rolling_friction: float = 0.0
) -> tuple[gr.Simulation, gr.Body, gr.Body]:
    """Two conforming grains of 1 mm (R/h = 10 in 2D, 6 in 3D) about to meet at 0.6 m/s, the
    second shifted sideways by R/2, e = 0.6."""
    sim = gr.Simulation(dimension)
    sim.contact = gr.Contact(
        restitution=0.6, friction=friction, pair_law=pair_law, rolling_friction=rolling_friction
    )
    radius, h = 1e-3, 1e-3 / (10 if dimension == 2 else 6)
    shape = gr.Disc if dimension == 2 else gr.Sphere
    zero = (0.0,) * (dimension - 2)
    a = sim.add_body(shape((0, 0, *zero), radius), SOFT, h, discretization="conforming")
    b = sim.add_body(
        shape((2 * radius + 1.5 * h, 0.5 * radius, *zero), radius),
        SOFT,
        h,
        discretization="conforming",
    )
    sim.velocities[a.nodes, 0] = 0.3
    sim.velocities[b.nodes, 0] = -0.3
    return sim, a, b


@pytest.mark.validation
@pytest.mark.parametrize("dimension", [2, 3])
@pytest.mark.parametrize("friction", [0.0, 0.5])
def test_oblique_collision_conserves_angular_momentum(dimension: int, friction: float) -> None:
    """Damping and friction act on both bodies at one contact point (the dashpot as rigid-body
    loads, the friction force with its couple about the node), so an isolated oblique collision
    keeps its angular momentum to round-off, with friction too (the body dashpot at the centres
    along a mean normal changed it by 6.3e-3, node-pair friction by 4.2e-3)."""
    sim, a, b = oblique_pair(dimension, friction)
    densities = np.full(sim.node_count, SOFT.density)
    before = angular_momentum(sim, densities)
    scale = momentum_scale(sim, densities)
    run_through_contact(sim)
    spins = [rigid_spin(sim, body) for body in (a, b)]
    assert max(abs(s) for s in spins) > 1.0  # the collision turned the bodies
    np.testing.assert_allclose(angular_momentum(sim, densities), before, rtol=0, atol=1e-12 * scale)


DATA = Path(__file__).resolve().parents[1] / "data"
PERIDEM_MESHES = DATA / "peridem" / "compression_small_set"


@pytest.mark.validation
@pytest.mark.parametrize(("dimension", "friction"), [(2, 0.0), (2, 0.5), (3, 0.5)])
def test_collisions_of_meshed_particles_conserve_angular_momentum(
    dimension: int, friction: float
) -> None:
    """Particles imported from meshes have their nodes on the surface, so each such node's
    contact sphere is centred inside it, at a virtual node that passes its forces on to the
    node and its anchors: an isolated oblique collision (PeriDEM's gmsh disc; a tetrahedral
    sphere) keeps its angular momentum to round-off, and an elastic head-on one at 0.2 m/s its
    energy within 0.1 % (measured 0.9999974 in 2D)."""
    mesh = (
        PERIDEM_MESHES / "mesh_cir_small_0.msh"
        if dimension == 2
        else DATA / "meshes" / "sphere_tet.msh"
    )
    reference = gr.ReferenceShape.from_mesh(str(mesh))
    zero = (0.0,) * (dimension - 2)
    for restitution, offset in ((0.6, 0.5e-3), (1.0, 0.0)):
        sim = gr.Simulation(dimension)
        sim.contact = gr.Contact(restitution=restitution, friction=friction)
        a = sim.add_particle(reference, SOFT, position=(0, 0, *zero))
        b = sim.add_particle(
            reference, SOFT, position=(2e-3 + 0.6 * reference.mesh_size, offset, *zero)
        )
        sim.velocities[a.nodes, 0] = 0.1
        sim.velocities[b.nodes, 0] = -0.1
        densities = np.full(sim.node_count, SOFT.density)
        before, energy = angular_momentum(sim, densities), sim.kinetic_energy()
        scale = momentum_scale(sim, densities)
        run_through_contact(sim)
        after = angular_momentum(sim, densities)
        np.testing.assert_allclose(after, before, rtol=0, atol=1e-12 * scale)
        if restitution == 1.0 and friction == 0.0:
            total = (sim.kinetic_energy() + sim.strain_energy()) / energy
            assert abs(total - 1) < 1e-3, f"energy changed by {total - 1:.2%}"


def rigid_spin(sim: gr.Simulation, body: gr.Body) -> float:
    """Angular velocity about z of a body [rad/s] (2D; the z part in 3D)."""
    nodes = body.nodes
    x, v, m = sim.positions[nodes], sim.velocities[nodes], sim.volumes[nodes]
    r = x - np.average(x, axis=0, weights=m)
    w = v - np.average(v, axis=0, weights=m)
    return float(
        np.sum(m * (r[:, 0] * w[:, 1] - r[:, 1] * w[:, 0]))
        / np.sum(m * (r[:, 0] ** 2 + r[:, 1] ** 2))
    )


@pytest.mark.validation
def test_damping_acts_on_the_fragment_in_contact_not_on_the_whole_particle() -> None:
    """A block cut in two: the left half bounces off a damped wall, the right half flies on.
    The dashpot acts on the left fragment only, so the right one keeps its velocity exactly."""
    sim = gr.Simulation(2)
    sim.contact = gr.Contact(restitution=0.5)
    block = sim.add_body(gr.Rectangle((0.3e-3, 0), (4.3e-3, 1e-3)), SOFT, 0.25e-3)
    sim.add_wall(gr.Plane((0, 0), (1, 0)), name="left")
    assert sim.precrack((2.3e-3, 0), (1, 0)) is None  # kept until the simulation is built
    assert sim.broken_bonds() > 0
    assert len(sim.fragments()) == 2
    X = sim.reference_positions
    left, right = np.flatnonzero(X[:, 0] < 2.3e-3), np.flatnonzero(X[:, 0] > 2.3e-3)
    sim.velocities[left, 0] = -0.2
    sim.velocities[right, 0] = 0.2
    sim.run(until=4e-3)
    assert np.mean(sim.velocities[left, 0]) > 0.05  # bounced
    np.testing.assert_allclose(np.mean(sim.velocities[right, 0]), 0.2, rtol=1e-12)
    assert block.node_count == len(left) + len(right)


@pytest.mark.validation
def test_head_on_impact_of_round_grains_throws_them_barely_sideways(full: bool) -> None:
    """Conforming discs (rings of nodes, R/h = 10) are round but bumpy at the scale of h: the
    node springs that touch first push along lines the node layout tilts. The collision's force
    is turned into the surfaces' normal (ContactModel::slot_redirects): measured lateral speed
    over the approach speed 0.32 % / 0.42 % for equal discs at 0.05 m/s (e = 0.6 / 1) and
    0.32 % / 0.42 % for a 0.5 mm disc against a 2 mm one; before, 9.9 % / 12.5 % and 9.6 % /
    12.1 %. At 1 m/s the unequal pair still gets 1.1 % / 1.4 % (not yet the 1 % Issue 13 asks
    for; 3.2 % / 2.9 % before). The smoke test runs one e per pair: 1, 0.6 and 1."""
    grains = ((1e-3, 0.05, 0.01), (0.5e-3, 0.05, 0.01), (0.5e-3, 1.0, 0.015))
    if full:
        cases = [(*grain, e) for grain in grains for e in (0.6, 1.0)]
    else:
        cases = [(*grains[0], 1.0), (*grains[1], 0.6), (*grains[2], 1.0)]
    for radius, speed, bound, restitution in cases:
        e, _, sim, (a, b), _ = collide(
            2,
            restitution,
            radius=radius,
            other_radius=1e-3 if radius == 1e-3 else 2e-3,
            speed=speed,
            discretization="conforming",
            same_nodes_per_radius=True,
        )
        lateral = abs(body_velocity(sim, a)[1] - body_velocity(sim, b)[1]) / speed
        assert lateral < bound, (radius, speed, restitution, lateral)
        assert abs(e - restitution) < 0.05, (radius, speed, restitution, e)


@pytest.mark.validation
def test_turning_the_collision_force_feeds_no_energy_into_bouncing_grains() -> None:
    """Sixteen conforming discs bounce in a box under gravity, elastic (e = 1) and frictionless:
    kinetic + strain + potential energy, sampled when no contact spring is loaded, stays within
    1 % of the largest kinetic energy over 0.03 s (measured: drift up to 6.3e-7 J/m against
    7.0e-4 J/m; 6.1e-7 before the turn faded out of lasting contacts, 2.9e-8 J/m before the
    force was turned). Turning
    the collision forces into the surfaces' normal does no work (its part along the bodies'
    relative velocity is removed); without that removal the drift reached 3.8e-3 J/m against
    3.1e-3 J/m over 0.05 s, and this test failed."""
    sim = gr.Simulation(2, gravity=(0, -9.81))
    sim.contact = gr.Contact(restitution=1.0)
    rng = np.random.default_rng(3)
    for row in range(4):
        for column in range(4):
            x = 1.2e-3 + column * 2.3e-3 + (row % 2) * 1.1e-3 + rng.uniform(-1e-4, 1e-4)
            centre = (x, 1.2e-3 + row * 2.3e-3)
            sim.add_body(
                gr.Disc(centre, 1e-3 * rng.uniform(0.8, 1.0)),
                SOFT,
                1e-3 / 6,
                discretization="conforming",
            )
    sim.add_wall(gr.BoxContainer((0, 0), (11e-3, 30e-3)), name="box")
    weight = sim.volumes * SOFT.density * 9.81

    def energy() -> float:
        return sim.kinetic_energy() + sim.strain_energy() + float(weight @ sim.positions[:, 1])

    start = energy()
    drift, kinetic = [], []
    while sim.time < 0.03:
        sim.run(200)
        statistics = sim.core.contact_statistics
        if statistics.node_contacts == 0 and statistics.wall_contacts == 0:  # no contact springs
            drift.append(abs(energy() - start))
            kinetic.append(sim.kinetic_energy())
    assert len(drift) > 10
    assert max(drift) < 0.01 * max(kinetic)


@pytest.mark.validation
def test_a_contact_too_soft_for_the_impact_is_reported() -> None:
    """Two soft discs (K = 21.6 MPa, lattice, R/h = 10) meeting at 10 m/s with the default kn:
    the surface law's probes are pressed past their contact radius (measured 1.177 Rc; nodes
    of one disc reach 2.6 h inside the other's surface), and the run warns once that the
    contact gave way, naming stiffness_factor. What follows is not physics, and it is chaotic:
    with the damping ratios fitted to a force that never pulls (13 % more damping) the discs
    lock together, 1.6 h into each other, vibrating; with the unclipped ones they had bounced
    apart at -1.98 m/s. (While the points' weights fell with depth, contact/surface_law.hpp,
    the deepest push was 0.856 Rc and the discs passed through each other, nodes 10.5 h inside.)
    With stiffness_factor 10 the deepest overlap is 0.27 Rc (0.65 h), nothing is said, and the
    discs part at -2.96 m/s, e = 0.59 for the requested 0.6."""
    import warnings

    for factor, deepest in ((1.0, (0.5, 1.3)), (10.0, (0.0, 0.5))):
        sim = gr.Simulation(2)
        sim.contact = gr.Contact(restitution=0.6, stiffness_factor=factor)
        sim.add_body(gr.Disc((0, 0), 1e-3), SOFT, 1e-4, velocity=(5.0, 0))
        sim.add_body(gr.Disc((2.15e-3, 0), 1e-3), SOFT, 1e-4, velocity=(-5.0, 0))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            sim.run(until=6e-4)
        overlap = sim.core.contact_statistics.deepest_overlap
        assert deepest[0] < overlap < deepest[1], (factor, overlap)
        if factor == 10.0:  # bounced back with the requested restitution
            left = sim.bodies[0].nodes
            speed = np.average(sim.velocities[left, 0], weights=sim.volumes[left])
            assert speed == pytest.approx(-0.6 * 5.0, abs=0.05 * 5.0)
        said = [str(w.message) for w in caught if "pressed" in str(w.message)]
        assert len(said) == (1 if factor == 1.0 else 0), (factor, said)
        if said:
            assert said[0].startswith("contact gave way") and "stiffness_factor" in said[0]
            statistics = sim.core.contact_statistics
            assert 0 < statistics.half_overlap_step < statistics.full_overlap_step < sim.step
            assert f"past 100% at step {statistics.full_overlap_step})" in said[0]
