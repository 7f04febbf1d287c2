"""Contact and wall set-up: defaults, per-pair settings, wall motion and reactions, errors."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest

import granulate as gr

SOFT = gr.Material(density=1200, bulk_modulus=2.16e7, shear_modulus=1.296e7, fracture=False)


def two_discs(contact: gr.Contact | None) -> gr.Simulation:
    sim = gr.Simulation(2)
    sim.contact = contact
    sim.add_body(gr.Disc((0, 0), 1e-3), SOFT, 0.2e-3, velocity=(0.5, 0))
    sim.add_body(gr.Disc((2.4e-3, 0), 1e-3), SOFT, 0.2e-3, velocity=(-0.5, 0))
    return sim


def test_without_contact_particles_pass_through_each_other() -> None:
    sim = two_discs(None)
    sim.run(until=6e-3)
    first, second = sim.bodies
    assert sim.positions[first.nodes, 0].mean() > sim.positions[second.nodes, 0].mean()


def test_contact_keeps_particles_apart() -> None:
    sim = two_discs(gr.Contact())
    sim.run(until=6e-3)
    first, second = sim.bodies
    assert sim.positions[first.nodes, 0].max() < sim.positions[second.nodes, 0].min()
    assert sim.core.contact_statistics.rebuilds >= 2


def test_gravity_can_be_given_to_the_constructor() -> None:
    sim = gr.Simulation(2, gravity=(0, -9.81))
    np.testing.assert_array_equal(sim.gravity, (0, -9.81, 0))


def test_per_pair_contact_overrides_the_default() -> None:
    other = gr.Material(density=1200, bulk_modulus=2.16e7, shear_modulus=1.296e7, fracture=False)
    sim = gr.Simulation(2)
    sim.contact = gr.Contact()
    sim.set_contact(SOFT, other, None)
    sim.add_body(gr.Disc((0, 0), 1e-3), SOFT, 0.2e-3, velocity=(0.5, 0))
    sim.add_body(gr.Disc((2.4e-3, 0), 1e-3), other, 0.2e-3, velocity=(-0.5, 0))
    sim.run(until=6e-3)
    first, second = sim.bodies
    assert sim.positions[first.nodes, 0].mean() > sim.positions[second.nodes, 0].mean()


def test_translating_wall_pushes_and_reports_its_reaction(tmp_path: Path) -> None:
    """A piston moving down onto a disc resting on the floor: both walls see the load."""
    sim = gr.Simulation(2, gravity=(0, -9.81), viscous_damping=50.0)
    sim.contact = gr.Contact(restitution=0.5)
    sim.add_body(gr.Disc((0, 1.3e-3), 1e-3), SOFT, 0.2e-3)
    sim.add_wall(gr.Plane((0, 0), (0, 1)), name="floor")
    piston = gr.Wall(
        (gr.Plane((0, 2.6e-3), (0, -1)),), motion=gr.Translation((0, -1), gr.Linear(0.02))
    )
    sim.add_wall(piston, name="piston")
    sim.output(tmp_path, every=500)
    sim.run(until=0.04)  # the disc's top is at 2 mm: the piston touches it at 0.03 s
    reactions = sim.wall_reactions()
    assert reactions["piston"][1] > 0 > reactions["floor"][1]  # pushed up, pushed down
    with (tmp_path / "history.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert {"floor_fx", "floor_fy", "floor_tz", "piston_fy", "piston_displacement"} <= set(rows[0])
    assert float(rows[-1]["piston_displacement"]) == pytest.approx(0.02 * float(rows[-1]["time"]))


@pytest.mark.parametrize(
    ("build", "message"),
    [
        (lambda: gr.Contact(restitution=0.0), "restitution"),
        (lambda: gr.Contact(restitution=1.2), "restitution"),
        (lambda: gr.Contact(friction=-0.1), "friction"),
        (lambda: gr.Contact(contact_radius_factor=0.0), "contact_radius_factor"),
        (lambda: gr.Contact(normal_stiffness=-1.0), "normal_stiffness"),
    ],
)
def test_bad_contact_parameters(build, message: str) -> None:
    with pytest.raises(gr.InputError, match=message):
        build()


def test_bad_walls_are_refused() -> None:
    sim = gr.Simulation(2)
    sim.add_wall(gr.Plane((0, 0), (0, 1)), name="floor")
    with pytest.raises(gr.InputError, match="exists already"):
        sim.add_wall(gr.Plane((0, 1), (0, -1)), name="floor")
    with pytest.raises(gr.InputError, match="letters, digits"):
        sim.add_wall(gr.Plane((0, 1), (0, -1)), name="top wall")
    with pytest.raises(gr.InputError, match="at least 3"):
        sim.add_wall(gr.PolygonContainer(((0, 0), (1, 1))))
    with pytest.raises(gr.InputError, match="Translation or a Rotation"):
        sim.add_wall(gr.Wall((gr.Plane((0, 0), (0, 1)),), motion="up"))  # type: ignore[arg-type]
    with pytest.raises(gr.InputError, match=r"must be a surface \(Plane.*or a tuple of them"):
        gr.Wall("floor")  # type: ignore[arg-type]
    one = gr.Wall(gr.Plane((0, 1), (0, -1)), motion=gr.Translation((0, -1), gr.Linear(0.1)))
    assert one.surfaces == (gr.Plane((0, 1), (0, -1)),)  # one surface: a wall of one surface
    sim.add_wall(one, name="top")
    bad_normal = gr.Simulation(2)
    bad_normal.add_body(gr.Disc((0, 1e-3), 1e-3), SOFT, 0.25e-3)
    bad_normal.add_wall(gr.Plane((0, 0), (0, 0)))
    with pytest.raises(gr.InputError, match="non-zero vector"):
        bad_normal.run(1)


def test_break_bonds_refuses_unbonded_pairs_and_the_state_view_is_read_only() -> None:
    sim = gr.Simulation(2)
    sim.add_body(gr.Rectangle((0, 0), (4e-3, 1e-3)), SOFT, 0.25e-3)
    with pytest.raises(gr.InputError, match="are not bonded"):
        sim.core.break_bonds(np.array([[0, sim.node_count - 1]], dtype=np.uint32))
    with pytest.raises(ValueError, match="read-only"):
        sim.core.bond_intact[0] = 0
    assert sim.precrack((2e-3, 0), (1, 0), region=gr.Rectangle((1e-3, -1), (3e-3, 0.5e-3))) > 0
    assert len(sim.fragments()) == 1  # a partial crack leaves the block in one piece


def _mixture(dimension: int) -> tuple[gr.Simulation, list[gr.Material]]:
    """Particles of three materials, sizes varying continuously, one with an absolute horizon."""
    rng = np.random.default_rng(7)
    stiff = gr.Material(density=2400, bulk_modulus=6e7, shear_modulus=3e7, fracture_energy=50)
    absolute = gr.Material(
        density=1500, bulk_modulus=3e7, shear_modulus=2e7, fracture_energy=20, horizon=0.9e-3
    )
    materials = [SOFT, stiff, absolute]
    if dimension == 2:
        reference = gr.ReferenceShape.from_shape(gr.Disc((0, 0), 1e-3), 0.25e-3)
    else:
        reference = gr.ReferenceShape.from_shape(gr.Sphere((0, 0, 0), 1e-3), 0.3e-3)
    sim = gr.Simulation(dimension)
    sim.contact = gr.Contact(restitution=0.8)
    sim.set_contact(SOFT, stiff, gr.Contact(stiffness_factor=3.0, contact_radius_factor=0.8))
    sim.add_wall(gr.Plane((0, -2e-3, 0)[:dimension], (0, 1, 0)[:dimension]))
    for k in range(24):
        position = [4e-3 * (k % 6), 4e-3 * (k // 6), 0.0][:dimension]
        sim.add_particle(
            reference, materials[k % 3], position=position, scale=float(rng.uniform(0.8, 1.5))
        )
    return sim, materials


@pytest.mark.parametrize("dimension", [2, 3])
def test_particles_of_any_size_share_one_core_material(dimension: int) -> None:
    """Continuous size distributions cost no extra materials or laws: the horizon and the
    critical stretch belong to each particle (s0 ~ delta^-1/2), Rc and kn to each pair."""
    sim, materials = _mixture(dimension)
    model = sim.model
    assert model.material_count == len(materials) == 3
    for p, body in enumerate(sim.bodies):
        horizon = body.material.resolved_horizon(body.mesh_size)
        assert model.particle_horizon(p) == pytest.approx(horizon, rel=1e-14)
        expected = body.material.critical_stretch(body.mesh_size, dimension)
        assert model.particle_critical_stretch(p) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("dimension", [2, 3])
def test_contact_time_step_bound_matches_brute_force_over_particle_pairs(dimension: int) -> None:
    """The O(P log P) bound equals max over all particle pairs of kn(p, q) V_max(q) for a finer
    (or equal) partner q, kn(p, q) min(V_max(p), V_max(q)) for a coarser one."""
    sim, materials = _mixture(dimension)
    core = sim.core
    model = sim.model
    moduli = {id(m): model.materials[i].dilatation_modulus for i, m in enumerate(materials)}
    volumes = model.volumes
    pairs = {(id(SOFT), id(materials[1])), (id(materials[1]), id(SOFT))}

    def kn(a: gr.Body, b: gr.Body, pa: int, pb: int) -> float:
        ha, hb = a.mesh_size, b.mesh_size
        da, db = model.particle_horizon(pa), model.particle_horizon(pb)
        delta = da if ha < hb else db if hb < ha else min(da, db)
        ka, kb = moduli[id(a.material)], moduli[id(b.material)]
        effective = 2 * ka * kb / (ka + kb)
        c = 18 / (np.pi * delta**5) if dimension == 3 else 12 / (np.pi * delta**4)
        factor = 3.0 if (id(a.material), id(b.material)) in pairs else 1.0
        return factor * c * effective

    bodies = sim.bodies
    vmax = [volumes[b.first_node : b.first_node + b.node_count].max() for b in bodies]
    partners = 6 if dimension == 3 else 4
    dt = np.inf
    for p, a in enumerate(bodies):
        s = max(
            kn(a, b, p, q) * (vmax[q] if b.mesh_size <= a.mesh_size else min(vmax[p], vmax[q]))
            for q, b in enumerate(bodies)
        )
        s = max(s, kn(a, a, p, p) * vmax[p])  # the floor (default law)
        dt = min(dt, np.sqrt(2 * a.material.density / (2 * partners * s)))
    assert core.contact_stable_time_step == pytest.approx(dt, rel=1e-12)


def test_particles_outside_their_container_or_overlapping_are_refused() -> None:
    sim = gr.Simulation(2)
    sim.add_body(gr.Disc((0, 0), 1e-3), SOFT, 0.25e-3, name="pebble")
    sim.add_wall(gr.BoxContainer((0.5e-3, -5e-3), (5e-3, 5e-3)), name="box")
    with pytest.raises(gr.InputError, match="pebble starts on the wrong side of wall 'box'"):
        sim.run(1)
    overlapping = gr.Simulation(2)
    overlapping.add_body(gr.Disc((0, 0), 1e-3), SOFT, 0.25e-3, name="a")
    overlapping.add_body(gr.Disc((1.5e-3, 0), 1e-3), SOFT, 0.25e-3, name="b")
    with pytest.raises(gr.InputError, match="a and b overlap at the start"):
        overlapping.run(1)
    overlapping.contact = None  # bodies that do not interact may overlap
    overlapping.run(1)
    touching = gr.Simulation(2)  # a gap of one mesh size is fine
    touching.add_body(gr.Disc((0, 0), 1e-3), SOFT, 0.25e-3)
    touching.add_body(gr.Disc((2.25e-3, 0), 1e-3), SOFT, 0.25e-3)
    touching.run(1)


def test_the_start_checks_judge_the_positions_a_run_starts_from() -> None:
    """start_from (a restart from another run's frame): two discs whose reference positions
    overlap, one of them also through the floor, start once moved apart and above it (PeriDEM's
    run2 decks move a wall down onto grains that settled since the reference, and were refused),
    and moved positions that overlap are refused."""

    def discs() -> gr.Simulation:
        sim = gr.Simulation(2)
        sim.add_body(gr.Disc((0, 0.5e-3), 1e-3), SOFT, 0.25e-3, name="a")
        sim.add_body(gr.Disc((1.5e-3, 1.2e-3), 1e-3), SOFT, 0.25e-3, name="b")
        sim.add_wall(gr.Plane((0, 0), (0, 1)), name="floor")
        return sim

    with pytest.raises(gr.InputError, match="a starts on the wrong side of wall 'floor'"):
        discs().run(1)
    up = np.array([0, 1e-3, 0])
    sim = discs()
    moved = sim.reference_positions + up  # both up 1 mm, b 1.5 mm to the right
    moved[sim.bodies[1].first_node :, 0] += 1.5e-3
    velocities = np.zeros_like(moved)
    velocities[:, 1] = -0.1
    sim.start_from(moved, velocities)
    sim.run(1)
    lowest = sim.reference_positions[:, 1].min() + 1e-3  # one step of 0.1 m/s later
    assert sim.positions[:, 1].min() == pytest.approx(lowest, abs=1e-7)
    assert sim.velocities[:, 1].max() < -0.09
    # built by the run: too late to move the start
    with pytest.raises(gr.InputError, match="cannot set the start positions after"):
        sim.start_from(moved, velocities)
    overlapping = discs()
    overlapping.start_from(overlapping.reference_positions + up, np.zeros_like(moved))
    with pytest.raises(gr.InputError, match="a and b overlap at the start"):
        overlapping.run(1)
    with pytest.raises(gr.InputError, match="positions must be 104 x 3"):
        discs().start_from(np.zeros((3, 3)), np.zeros((3, 3)))


@pytest.mark.parametrize(("pair_law", "accepted"), [("surface", True), ("granulate", False)])
def test_grains_pressed_into_each_other_as_at_rest_start_under_the_surface_law(
    pair_law: str, accepted: bool
) -> None:
    """Under the surface law grains meet at their surfaces, so nodes of grains at rest may lie
    closer than half a mesh size (a settled pile carried into a new simulation was refused):
    two hexagons pressed 0.3 h into each other face to face start, and 0.6 h is refused. The
    node spheres keep nodes apart and refuse both (their nodes lie 0.36 h apart at 0.3 h)."""
    apothem = 1e-3 * np.cos(np.pi / 6)
    for overlap, refused in ((0.3, not accepted), (0.6, True)):
        sim = gr.Simulation(2)
        sim.contact = gr.Contact(pair_law=pair_law)
        sim.add_body(gr.RegularPolygon((0, 0), 1e-3, 6), SOFT, 0.2e-3, name="a")
        sim.add_body(
            gr.RegularPolygon((0, 2 * apothem - overlap * 0.2e-3), 1e-3, 6), SOFT, 0.2e-3, name="b"
        )
        if refused:
            with pytest.raises(gr.InputError, match="a and b overlap at the start"):
                sim.run(1)
        else:
            sim.run(1)
