"""Static friction and the contact surface (DESIGN.md section 6): a body on an incline sticks
below the friction angle and slides at g (sin a - mu cos a) above it; a body at rest never spins
up; a disc at rest sits at its radius; a disc and a sphere roll at 2/3 and 5/7 of their launch
speed (Cundall-Strack springs acting at the surface, see contact_law.hpp)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import granulate as gr

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "docs" / "validation"))
from oblique_impact import rigid_motion

RUBBER = gr.Material(density=1000, youngs_modulus=5e6, poisson_ratio=0.25, fracture=False)
SOFT = gr.Material(density=1200, bulk_modulus=2.16e7, shear_modulus=1.296e7, fracture=False)


def block_on_incline(dimension: int, angle: float, mu: float) -> tuple[gr.Simulation, gr.Body]:
    """A rubber block on a floor with gravity tilted by `angle` degrees: an incline."""
    a, g = np.radians(angle), 9.81
    sim = gr.Simulation(dimension, gravity=(g * np.sin(a), -g * np.cos(a), 0)[:dimension])
    sim.contact = gr.Contact(restitution=0.3, friction=mu)
    h = 1e-3
    if dimension == 2:
        block = sim.add_body(gr.Rectangle((0, 0.45 * h), (10 * h, 5.45 * h)), RUBBER, h)
        sim.add_wall(gr.Plane((0, 0), (0, 1)), name="floor")
    else:
        block = sim.add_body(gr.Box((0, 0.45 * h, 0), (6 * h, 3.45 * h, 6 * h)), RUBBER, h)
        sim.add_wall(gr.Plane((0, 0, 0), (0, 1, 0)), name="floor")
    return sim, block


@pytest.mark.validation
@pytest.mark.parametrize("dimension", [2, 3])
def test_block_on_an_incline_below_the_friction_angle_stays_put(dimension: int, full: bool) -> None:
    """mu = 0.5 (friction angle 26.6 degrees), incline 20 degrees: once the springs have taken
    the load (0.1 s), the block moves less than 1e-3 of its size in 0.9 s (--full; measured
    1e-6 m in 2D, 0 in 3D; the regularised law crept at the speed that balanced the load), and
    by as little in the smoke test's 0.3 s."""
    sim, block = block_on_incline(dimension, 20.0, 0.5)
    sim.run(until=0.1)
    start = rigid_motion(sim, block)[0]
    sim.run(until=1.0 if full else 0.4)
    drift = np.linalg.norm(rigid_motion(sim, block)[0] - start)
    size = 10e-3 if dimension == 2 else 6e-3
    assert drift < 1e-3 * size, f"crept {drift:.3g} m"


@pytest.mark.validation
@pytest.mark.parametrize("dimension", [2, 3])
def test_block_on_an_incline_above_the_friction_angle_accelerates_at_coulomb_rate(
    dimension: int,
) -> None:
    """Incline 35 degrees, mu = 0.5: a = g (sin a - mu cos a) = 1.609 m/s^2 within 2 %
    (measured 1.6116 in 2D, 1.6091 in 3D)."""
    angle, mu = 35.0, 0.5
    sim, block = block_on_incline(dimension, angle, mu)
    sim.run(until=0.1)
    v0, t0 = rigid_motion(sim, block)[1][0], sim.time
    sim.run(until=0.3)
    acceleration = (rigid_motion(sim, block)[1][0] - v0) / (sim.time - t0)
    a = np.radians(angle)
    expected = 9.81 * (np.sin(a) - mu * np.cos(a))
    assert acceleration == pytest.approx(expected, rel=0.02)


@pytest.mark.validation
def test_a_disc_at_rest_on_a_wall_never_spins_up_and_sits_at_its_radius(full: bool) -> None:
    """Dropped from 0.02 h above its resting height onto a floor (g = 100 made the regularised
    friction flip sign every step and spin the disc up, equally for every mu): after 20 ms (the
    smoke test: 10 ms) the disc neither spins nor slides, and its centre is at its radius within
    0.1 h (the nodes' contact spheres reach the surface; the node-pair law left it 0.4 h too
    high). Measured: omega R and v below 3e-13 m/s from 5 ms to 20 ms, the centre 0.026 h low.
    mu = 0, 0.3 and 1 under g = 9.81 and 100 with --full; the smoke test runs mu = 0 and 1 under
    g = 100 and mu = 0.3 under g = 9.81."""
    radius, h = 1e-3, 1e-4
    cases = [(mu, g) for mu in (0.0, 0.3, 1.0) for g in (9.81, 100.0)]
    for mu, gravity in cases if full else [(0.0, 100.0), (1.0, 100.0), (0.3, 9.81)]:
        sim = gr.Simulation(2, gravity=(0, -gravity))
        sim.contact = gr.Contact(restitution=0.5, friction=mu)
        disc = sim.add_body(gr.Disc((0, radius + 0.02 * h), radius), SOFT, h)
        sim.add_wall(gr.Plane((0, 0), (0, 1)), name="floor")
        sim.run(until=0.02 if full else 0.01)
        centre, velocity, spin = rigid_motion(sim, disc)
        where = f"mu = {mu}, g = {gravity}"
        assert abs(spin[2]) * radius < 1e-7, f"{where}: spins at {spin[2]:.3g} rad/s"
        assert abs(velocity[0]) < 1e-7, where
        rest = (centre[1] - radius) / h
        assert abs(rest) < 0.1, f"{where}: rests at {rest:+.3f} h"


@pytest.mark.validation
@pytest.mark.parametrize("discretization", ["lattice", "conforming"])
def test_resting_sphere_sits_at_its_radius(discretization: str) -> None:
    sim = gr.Simulation(3, gravity=(0, -9.81, 0), viscous_damping=30.0)
    sim.contact = gr.Contact(restitution=0.5, friction=0.3)
    radius, h = 1e-3, 0.25e-3
    sphere = sim.add_body(gr.Sphere((0, radius, 0), radius), SOFT, h, discretization=discretization)
    sim.add_wall(gr.Plane((0, 0, 0), (0, 1, 0)), name="floor")
    sim.run(until=0.02)
    centre = rigid_motion(sim, sphere)[0]
    assert abs(centre[1] - radius) < 0.1 * h, f"rests at {(centre[1] - radius) / h:+.3f} h"


DATA = Path(__file__).resolve().parents[1] / "data"


def placed_on_floor(case: str) -> tuple[gr.Simulation, gr.Body, float, float]:
    """A particle whose nodes on its surface are mesh vertices, placed 0.02 h above a floor;
    returns (simulation, body, the height its centre rests at when its surface touches, h)."""
    dimension = 3 if case in ("tetrahedral sphere", "grid box") else 2
    sim = gr.Simulation(dimension, gravity=(0, -9.81, 0)[:dimension], viscous_damping=30.0)
    sim.contact = gr.Contact(restitution=0.5, friction=0.3)
    if case in ("gmsh hexagon", "tetrahedral sphere"):
        mesh = (
            DATA / "peridem" / "compression_small_set" / "mesh_hex_small_0.msh"
            if dimension == 2
            else DATA / "meshes" / "sphere_tet.msh"
        )
        reference = gr.ReferenceShape.from_mesh(str(mesh))
        h = reference.mesh_size
        lowest = -reference.positions[:, 1].min()  # a side of the hexagon, the sphere's bottom
        position = (0, lowest + 0.02 * h, 0)[:dimension]
        return sim, sim.add_particle(reference, SOFT, position=position), lowest, h
    h = 0.1e-3 if dimension == 2 else 0.25e-3
    lower, upper = (-1e-3, 0.02 * h, -1e-3), (1e-3, 1e-3 + 0.02 * h, 1e-3)
    shape = gr.Rectangle(lower[:2], upper[:2]) if dimension == 2 else gr.Box(lower, upper)
    return sim, sim.add_body(shape, SOFT, h, discretization="grid"), 0.5e-3, h


@pytest.mark.validation
@pytest.mark.parametrize(
    "case", ["gmsh hexagon", "grid rectangle", "tetrahedral sphere", "grid box"]
)
def test_meshed_particles_rest_on_their_true_surface(case: str) -> None:
    """Meshes made elsewhere and grids have their outer nodes on the surface, where a lattice's
    lie h/2 inside it; their contact spheres are centred one contact radius below every face at
    the node, so the particle rests on its surface within 0.1 h (before: PeriDEM's hexagon
    0.475 h above it). Measured after 5 ms: -0.0001, -0.0000 and -0.0001 h for the hexagon,
    rectangle and box, -0.020 h for the sphere, whose flat faces lie inside its vertices."""
    sim, body, resting, h = placed_on_floor(case)
    floor = gr.Plane((0, 0, 0)[: sim.dimension], (0, 1, 0)[: sim.dimension])
    sim.add_wall(floor, name="floor")
    sim.run(until=0.005)
    centre = rigid_motion(sim, body)[0]
    assert abs(centre[1] - resting) < 0.1 * h, f"rests at {(centre[1] - resting) / h:+.3f} h"


def roll(
    dimension: int,
    nodes_across_radius: int,
    window: float,
    mu: float = 0.3,
    land: float = 0.01,
    pair_law: str = "granulate",
) -> tuple[float, float]:
    """A conforming disc (sphere) that has landed on a floor (for `land` seconds) is set sliding
    at v0 without spin, friction mu: the ratio v / v0 and the slip (v - omega R) / v, averaged
    over `window` seconds of the rolling phase, from v0 / (2 mu g) on (slipping ends at
    v0 / (3 mu g) for a disc, 2 v0 / (7 mu g) for a sphere)."""
    g, v0, radius = 9.81, 0.1, 1e-3
    h = radius / nodes_across_radius
    sim = gr.Simulation(dimension, gravity=(0, -g, 0)[:dimension])
    sim.contact = gr.Contact(restitution=1.0, friction=mu, pair_law=pair_law)
    if dimension == 2:
        body = sim.add_body(gr.Disc((0, radius), radius), SOFT, h, discretization="conforming")
        sim.add_wall(gr.Plane((0, 0), (0, 1)), name="floor")
    else:
        body = sim.add_body(gr.Sphere((0, radius, 0), radius), SOFT, h, discretization="conforming")
        sim.add_wall(gr.Plane((0, 0, 0), (0, 1, 0)), name="floor")
    sim.run(until=land)
    sim.velocities[:, 0] += v0
    rolling = sim.time + 0.5 * v0 / (mu * g)
    sim.run(until=rolling)
    speeds, slips = [], []
    while sim.time < rolling + window:
        sim.run(50)
        _, velocity, spin = rigid_motion(sim, body)
        speeds.append(velocity[0] / v0)
        slips.append((velocity[0] + spin[2] * radius) / velocity[0])
    return float(np.mean(speeds)), float(np.mean(slips))


@pytest.mark.validation
@pytest.mark.parametrize(
    "pair_law", [pytest.param("granulate", marks=pytest.mark.full_only), "surface"]
)
def test_disc_rolls_at_two_thirds_of_its_launch_speed(pair_law: str) -> None:
    """Friction acts at the surface (radius R), not at the outer nodes (R - h/2, which gave
    0.646 v0 with 4.7 % slip). R/h = 10, landed for 3 ms: 2/3 v0 within 2 %, slip < 1 %
    (measured 0.6577 v0, -0.34 %; 0.6591 v0 landed for 10 ms). Under the surface law the wall
    sees the disc's circle through its points' osculating spheres: 0.6678 v0, slip -0.002 %
    (on its points' contact spheres, the polygon of them: 0.638 v0 over the test's window);
    at R/h = 8, which the surface law runs, 0.6684 v0 and -0.002 % in half the time. The node
    spheres' variant (pair_law "granulate") runs under --full only, here and in the sphere's
    test below: the default suite keeps the default law."""
    nodes_across_radius = 8 if pair_law == "surface" else 10
    speed, slip = roll(2, nodes_across_radius, 0.013, land=0.003, pair_law=pair_law)
    assert speed == pytest.approx(2 / 3, rel=0.02)
    assert abs(slip) < 0.01


@pytest.mark.validation
@pytest.mark.parametrize(
    "pair_law", [pytest.param("granulate", marks=pytest.mark.full_only), "surface"]
)
def test_sphere_rolls_at_five_sevenths_of_its_launch_speed(pair_law: str, full: bool) -> None:
    """As above for a sphere: 5/7 v0 within 2 % and slip < 1 % at R/h = 10, mu = 0.3 (--full,
    about 150 s). The smoke test rolls a coarser sphere (R/h = 5) on mu = 1, which ends its
    slipping phase 3.3 times sooner, landed for 3 ms and averaged over 5 ms: 5/7 v0 within 2 %,
    slip < 1.5 % (under the surface law measured 0.7202 v0, -0.06 %, in 6.8 s; at R/h = 6,
    0.7198 v0 and 0.68 % in 15.7 s; R/h = 4 gave 0.7232 v0, 0.14 %; the node spheres at R/h = 6
    0.7172 v0, -0.88 %, and at mu = 0.3 0.7034 v0)."""
    if full:
        speed, slip = roll(3, 10, 0.033, pair_law=pair_law)
    else:
        speed, slip = roll(3, 5, 0.005, mu=1.0, land=0.003, pair_law=pair_law)
    assert speed == pytest.approx(5 / 7, rel=0.02)
    assert abs(slip) < (0.01 if full else 0.015)


@pytest.mark.validation
def test_a_round_grain_rolls_on_a_wall_as_on_its_circle() -> None:
    """Under the surface law a wall sees a round particle's surface points through their
    osculating spheres, which agree on a circle wherever it has turned (ARCHITECTURE.md, "The
    surface law"). A conforming disc (R/h = 8, e = 0.1) set sliding at 0.1 m/s rolls from 12
    ms on: its centre stays within 1e-3 h of its resting height (measured 0.00005 h at most)
    and its mean speed over 18-21 ms within 1e-3 v0 of that over 12-15 ms (measured 0.66835
    and 0.66845 v0). On its points' contact spheres it rolls as their polygon: the centre
    sinks the sagitta h^2 / (8 R) = 0.0156 h (measured 0.0165 h) and each landing takes speed
    (0.6642 to 0.6561 v0; at R/h = 10 over 12-30 ms, 0.0132 h and 0.6626 to 0.6450 v0;
    docs/validation/rolling_polygon.py)."""
    from rolling_polygon import rolling_disc

    rows = rolling_disc(8, 0.1, 1.0, "surface", duration=0.021)
    rolling = rows[rows[:, 0] > 0.012]
    assert np.abs(rolling[:, 2]).max() < 1e-3
    windows = [
        rolling[(rolling[:, 0] >= t) & (rolling[:, 0] < t + 0.003), 3].mean()
        for t in (0.012, 0.018)
    ]
    assert abs(windows[1] - windows[0]) < 1e-3, windows


def stack_height(mu: float, until: float, rolling_friction: float = 0.0) -> float:
    """Two touching discs on a floor with a third in their groove, under gravity (background
    damping settles them), under the surface law: the top disc's height over the radius after
    `until` seconds."""
    sim = gr.Simulation(2, gravity=(0, -9.81), viscous_damping=20.0)
    sim.contact = gr.Contact(
        restitution=0.3, friction=mu, rolling_friction=rolling_friction, pair_law="surface"
    )
    radius = 1e-3
    disc = gr.ReferenceShape.from_shape(
        gr.Disc((0, 0), radius), 0.25e-3, discretization="conforming"
    )
    lift = radius + 0.02e-3
    for x in (-radius, radius):
        sim.add_particle(disc, SOFT, position=(x, lift))
    top = sim.add_particle(disc, SOFT, position=(0, lift + np.sqrt((2.1e-3) ** 2 - radius**2)))
    sim.add_wall(gr.Plane((0, 0), (0, 1)), name="floor")
    sim.run(until=until)
    return float(rigid_motion(sim, top)[0][1] / radius)


@pytest.mark.validation
@pytest.mark.parametrize(
    ("mu", "rolling_friction", "until", "stands"),
    [
        (0.5, 0.0, 0.04, True),
        (0.2, 0.0, 0.1, False),
        (0.2, 0.5, 0.04, True),
        pytest.param(0.1, 0.5, 0.07, False, marks=pytest.mark.full_only),
    ],
)
def test_a_stack_of_discs_stands_where_rigid_statics_lets_it(
    mu: float, rolling_friction: float, until: float, stands: bool
) -> None:
    """Rigid discs (the top one on the two below, its contacts 30 degrees off vertical; all
    friction coefficients mu) stand if mu >= 2 - sqrt(3) = 0.268: below it the bottom discs
    roll apart under the top one. With their rolling held (rolling resistance), the bottom
    discs must instead slide on the floor, whose friction carries the top contact's horizontal
    push (0.5 - 0.866 mu) / (1.732 + mu) of the top disc's weight W against mu 1.5 W: they
    stand if 1.5 mu^2 + 3.464 mu >= 0.5, mu >= 0.136, whatever mu_r. Measured (height of the
    top disc over R; standing is 1 + sqrt(3) = 2.73 less the overlaps): mu = 0.5 stands, 2.685
    at 0.04 s, settling to 2.641 at 0.10 s and 2.642 at 0.12 s; mu = 0.2 collapses (2.186 at
    0.06 s, 1.070 at 0.08 s, 1.000 from 0.09 s on); mu = 0.2 with mu_r = 0.5 stands, 2.707
    from 0.03 s to 0.06 s; mu = 0.1 with mu_r = 0.5 slides apart, 1.000 at 0.065 s (only with
    --full: the default suite has the rolling resistance's stack standing where it would
    roll apart without it). On the node spheres of pair_law "granulate" the discs' node rows
    interlock: mu = 0.2 stands (2.592 at 0.15 s), and so did mu = 0.1 with mu_r = 0.5 (2.605
    at 0.12 s), which rigid statics forbids."""
    height = stack_height(mu, rolling_friction=rolling_friction, until=until)
    assert (height > 2.6) if stands else (height < 1.1), height
