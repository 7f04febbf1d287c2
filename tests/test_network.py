"""The contact network and granular measures (granulate.network): coordination of hexagonal
and FCC packings, the contact forces against the bodies' own force balance, Love-Weber
particle stresses against the bonds' stresses, the assembly stress and the wall stress of a
pile at rest, and the contact tables and force chains a run writes."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import granulate as gr
from granulate import network, plots
from granulate.io.history import read_history
from granulate.io.vtu import read_pvd

RADIUS = 1e-3
DENSITY = 2000.0


def grain(young: float = 1e8) -> gr.Material:
    return gr.Material(density=DENSITY, youngs_modulus=young, poisson_ratio=0.25, fracture=False)


def hexagonal_patch(rows: int, spacing: float) -> list[tuple[float, float]]:
    return [
        (col * spacing + (row % 2) * spacing / 2, row * spacing * math.sqrt(3) / 2)
        for row in range(rows)
        for col in range(rows)
    ]


def pressed_together(sim: gr.Simulation, centres: list, spread: float) -> None:
    """Builds the bodies `spread` times farther apart than `centres` (the set-up check refuses
    overlapping particles), moves each rigidly onto its centre and evaluates the forces once."""
    positions = sim.positions  # builds
    for body, centre in zip(sim.bodies, centres, strict=True):
        nodes = slice(body.first_node, body.first_node + body.node_count)
        positions[nodes, : len(centre)] -= (spread - 1) * np.asarray(centre)
    sim.run(1)


def lattice_neighbours(centres: np.ndarray, spacing: float) -> set[tuple[int, int]]:
    """The pairs of lattice sites one spacing apart."""
    d = np.linalg.norm(centres[:, None] - centres[None], axis=-1)
    i, j = np.nonzero(np.abs(d - spacing) < 1e-9)
    return {(int(a), int(b)) for a, b in zip(i, j, strict=True) if a < b}


@pytest.mark.filterwarnings("ignore:contact.*bodies pressed")  # pressed on purpose
@pytest.mark.parametrize("pair_law", ["granulate", "surface"])
def test_hexagonal_packing_has_coordination_six(pair_law: str) -> None:
    """Discs (R/h = 4) on a 5 x 5 hexagonal lattice, centres 5 % closer than 2R (1 % under the
    surface law, which follows the true surfaces): the touching pairs are exactly the lattice
    neighbours, each of the 9 inner discs touches 6, the mean coordination is 2 x 56 / 25 =
    4.48, and the fabric tensor of the centre lines is the lattice's. The contact normals are
    the surfaces' normals, which the discs' ring of nodes tilts: measured up to 2.3 degrees off
    the centre lines under the sphere law and 6.9 under the surface law (R/h = 4), so their
    fabric tensor is the lattice's within 0.013 and 0.052 (asserted: 8 degrees and 0.06)."""
    spacing = 2 * RADIUS * (0.95 if pair_law == "granulate" else 0.99)
    centres = hexagonal_patch(5, spacing)
    sim = gr.Simulation(2)
    sim.contact = gr.Contact(restitution=0.5, friction=0.3, pair_law=pair_law)
    for c in centres:
        sim.add_body(
            gr.Disc(tuple(1.25 * np.array(c)), RADIUS),
            grain(),
            RADIUS / 4,
            discretization="conforming",
        )
    pressed_together(sim, centres, 1.25)
    table = sim.contact_table()
    expected = lattice_neighbours(np.array(centres), spacing)
    assert {tuple(p) for p in network.coordination_pairs(table).tolist()} == expected
    z = network.coordination(table, len(sim.bodies)).reshape(5, 5)
    assert np.all(z[1:-1, 1:-1] == 6), z
    assert network.mean_coordination(table, 25) == pytest.approx(2 * 56 / 25, abs=1e-12)
    lines = np.array([np.subtract(centres[b], centres[a]) / spacing for a, b in sorted(expected)])
    lattice = lines.T @ lines / len(lines)
    assert np.allclose(network.fabric_tensor(table, 2, centres=centres), lattice, atol=1e-12)
    assert np.allclose(network.fabric_tensor(table, 2), lattice, atol=0.06)
    branch = np.array(centres)[table["particle_a"]] - np.array(centres)[table["particle_b"]]
    cosine = np.einsum("ij,ij->i", branch / spacing, np.column_stack([table["nx"], table["ny"]]))
    assert np.degrees(np.arccos(np.minimum(cosine, 1.0))).max() < 8.0
    assert np.all(table["normal_force"] > 0)


@pytest.mark.filterwarnings("ignore:contact.*bodies pressed")  # pressed on purpose
def test_fcc_packing_has_coordination_twelve() -> None:
    """A sphere (R/h = 3) and its 12 nearest neighbours of a face-centred cubic packing, 5 %
    closer than 2R: the centre touches all 12, each outer sphere the centre and 4 others (a
    cuboctahedron's edges), 36 pairs in all, and the fabric tensor is isotropic, I/3 (exact with
    the centre lines, to 0.01 with the contact normals)."""
    spacing = 2 * RADIUS * 0.95
    offsets = (
        [(a, b, 0) for a in (-1, 1) for b in (-1, 1)]
        + [(a, 0, b) for a in (-1, 1) for b in (-1, 1)]
        + [(0, a, b) for a in (-1, 1) for b in (-1, 1)]
    )
    centres = [(0.0, 0.0, 0.0)] + [tuple(spacing * np.array(o) / math.sqrt(2)) for o in offsets]
    sim = gr.Simulation(3)
    sim.contact = gr.Contact(restitution=0.5)
    for c in centres:
        sim.add_body(gr.Sphere(tuple(1.25 * np.array(c)), RADIUS), grain(), RADIUS / 3)
    pressed_together(sim, centres, 1.25)
    table = sim.contact_table()
    z = network.coordination(table, len(sim.bodies))
    assert z[0] == 12 and np.all(z[1:] == 5), z
    assert len(network.coordination_pairs(table)) == 36
    assert np.allclose(network.fabric_tensor(table, 3, centres=centres), np.eye(3) / 3, atol=1e-12)
    assert np.allclose(network.fabric_tensor(table, 3), np.eye(3) / 3, atol=0.01)


@pytest.mark.parametrize(
    ("dimension", "pair_law"), [(2, "granulate"), (2, "surface"), (3, "granulate")]
)
def test_contact_forces_are_the_whole_load_on_each_body(dimension: int, pair_law: str) -> None:
    """Mid-collision of two grains with friction, damping and a wall: for each particle, the
    network's forces on it sum to its nodes' force less gravity, sum V_i f_i - m g (bond forces
    cancel inside a particle), to 1e-9 of the largest; each wall's contact forces sum to minus
    its reaction. Springs, friction, the dashpots and the turned forces are all in the network."""
    if dimension == 2:
        shapes = [gr.Disc((0, 1.2e-3), RADIUS), gr.Disc((1.4e-3, 3.0e-3), RADIUS)]
        floor, gravity = gr.Plane((0, 0), (0, 1)), (0, -100.0)
    else:
        shapes = [gr.Sphere((0, 0, 1.2e-3), RADIUS), gr.Sphere((1.4e-3, 0, 3.0e-3), RADIUS)]
        floor, gravity = gr.Plane((0, 0, 0), (0, 0, 1)), (0, 0, -100.0)
    sim = gr.Simulation(dimension, gravity=gravity)
    sim.contact = gr.Contact(restitution=0.5, friction=0.4, pair_law=pair_law)
    for k, shape in enumerate(shapes):
        down = [0.0] * dimension
        down[-1] = -1.0 - k
        sim.add_body(shape, grain(), RADIUS / 4, velocity=tuple(down))
    sim.add_wall(floor, name="floor")
    touching = False
    while not touching:
        sim.run(50)
        table = sim.contact_table()
        touching = bool(np.any(table["wall"] < 0)) and bool(np.any(table["wall"] >= 0))
    owner = np.asarray(sim.model.node_particle)
    nodal = sim.volumes[:, None] * np.asarray(sim.core.forces)
    mass = np.bincount(owner, sim.volumes * DENSITY)
    g = np.zeros(3)
    g[:dimension] = gravity
    expected = (
        np.column_stack([np.bincount(owner, nodal[:, k]) for k in range(3)]) - mass[:, None] * g
    )
    force = np.column_stack([table["f" + a] for a in "xyz"])
    on = np.zeros((2, 3))
    np.add.at(on, table["particle_a"], force)
    pairs = table["wall"] < 0
    np.add.at(on, table["particle_b"][pairs], -force[pairs])
    scale = np.abs(expected).max()
    assert np.allclose(on, expected, rtol=0, atol=1e-9 * scale), (on, expected)
    on_floor = force[table["wall"] == 0].sum(axis=0)
    assert np.allclose(-on_floor, sim.wall_reactions()["floor"][:3], rtol=0, atol=1e-9 * scale)


def settled_pile(mesh_ratio: int, pair_law: str) -> tuple[gr.Simulation, float]:
    """Three discs (two on a floor, one on them) between frictionless side walls, settled under
    g = 100 m/s^2 with background damping; returns the simulation and the floor's width."""
    width = 4.25e-3
    sim = gr.Simulation(2, gravity=(0, -100.0), viscous_damping=300.0)
    sim.contact = gr.Contact(restitution=0.2, friction=0.5, pair_law=pair_law)
    for c in [(1.05e-3, 1.0e-3), (3.2e-3, 1.0e-3), (2.1e-3, 2.9e-3)]:
        sim.add_body(
            gr.Disc(c, RADIUS), grain(1e7), RADIUS / mesh_ratio, discretization="conforming"
        )
    sim.add_wall(gr.Wall((gr.Plane((0, 0), (0, 1)),), name="floor", area=width))
    smooth = gr.Contact(restitution=0.2, friction=0.0, pair_law=pair_law)
    sim.add_wall(gr.Wall((gr.Plane((0, 0), (1, 0)),), name="left", contact=smooth))
    sim.add_wall(gr.Wall((gr.Plane((width, 0), (-1, 0)),), name="right", contact=smooth))
    sim.run(until=0.08)
    return sim, width


@pytest.fixture(scope="module", params=["granulate", "surface"])
def pile(request: pytest.FixtureRequest) -> tuple[gr.Simulation, float]:
    return settled_pile(4, request.param)


def test_pile_at_rest_loads_its_floor_with_its_weight(pile: tuple[gr.Simulation, float]) -> None:
    """The floor's normal stress (its vertical reaction over its width) is the pile's weight
    over that width (measured to 2e-8 under both laws; asserted 1e-4); the assembly stress,
    sum V_p sigma_p, is the virial of the external forces, sum_walls x_c (x) f_c + sum_p m_p x_p
    (x) g (measured to 5e-8 of its vertical part; asserted 1e-5)."""
    sim, width = pile
    weight = float(sim.volumes.sum()) * DENSITY * 100.0
    stress = -float(sim.wall_reactions()["floor"][1]) / width
    assert stress == pytest.approx(weight / width, rel=1e-4)
    table, particles = sim.contact_table(), sim.particle_table()
    volumes = np.bincount(np.asarray(sim.model.node_particle), sim.volumes)
    sigma = network.assembly_stress(sim.particle_stresses(), volumes, volume=1.0)
    walls = table["wall"] >= 0
    point = np.column_stack([table[a] for a in "xy"])[walls]
    force = np.column_stack([table["f" + a] for a in "xy"])[walls]
    centres = np.column_stack([particles["x"], particles["y"]])
    weighted = (particles["mass"][:, None] * centres).sum(axis=0)
    virial = point.T @ force + np.outer(weighted, [0.0, -100.0])
    assert np.allclose(sigma, 0.5 * (virial + virial.T), rtol=0, atol=1e-5 * abs(virial[1, 1]))


def test_love_weber_stress_agrees_with_the_bonds_at_rest(
    pile: tuple[gr.Simulation, float], full: bool
) -> None:
    """Each disc's stress from its bond forces is that from its contacts times 1 - h / (2R):
    the contact forces reach a particle at its nodes, half a mesh size inside the surface where
    Love-Weber puts them, so the two converge as h falls. Measured sigma_yy ratios 0.881,
    0.875, 0.880 (surface law: 0.878, 0.868, 0.870) at R/h = 4, where 1 - h / (2R) = 0.875, and
    0.941, 0.939, 0.940 (0.935, 0.938, 0.931) at R/h = 8 (0.9375, --full); asserted for every
    component, |sigma_bonds - (1 - h / (2R)) sigma_contacts| below 0.05 |sigma_yy| (measured
    at most 0.014 (0.020) at R/h = 4, 0.007 (0.006) at R/h = 8)."""
    law = pile[0].contact.pair_law if pile[0].contact is not None else "granulate"
    cases = [(pile[0], 4)] + ([(settled_pile(8, law)[0], 8)] if full else [])
    for sim, ratio in cases:
        contacts, bonds = sim.particle_stresses("contacts"), sim.particle_stresses("bonds")
        assert np.all(contacts[:, 1, 1] < 0)  # compressed
        scale = np.abs(contacts[:, 1, 1])[:, None, None]
        deviation = np.abs(bonds - (1 - 0.5 / ratio) * contacts) / scale
        assert deviation.max() < 0.05, (ratio, deviation.max())


def test_a_run_writes_contact_tables_and_force_chains(tmp_path: Path) -> None:
    """Every frame has frames/contacts_NNNNNN.csv and .vtu, listed in contacts.pvd with
    simulation.pvd's times; Results reads the tables back equal to the live ones; the particle
    table carries coordination and stress, and history.csv the wall stress, the contact count,
    the mean coordination, the particles' mean stress and the fabric tensor."""
    sim, width = settled_pile(4, "granulate")
    sim.output(tmp_path / "run", every=20)
    sim.run(40)
    results = gr.Results(tmp_path / "run")
    assert [t for t, _ in read_pvd(tmp_path / "run" / "contacts.pvd")] == list(results.times)
    live = sim.contact_table()
    read = results.contacts(-1)
    for name in network.COLUMNS:
        assert np.allclose(read[name], live[name], rtol=1e-15, atol=0), name
    particles = results.particles(-1)
    assert list(particles["coordination"]) == list(network.coordination(live, 3))
    assert np.allclose(particles["syy"], sim.particle_stresses()[:, 1, 1], rtol=1e-12)
    assert np.all(np.isnan(particles["szz"]))
    history = results.history
    assert history["contacts"][-1] == 2 and history["coordination"][-1] == pytest.approx(4 / 3)
    reaction = np.linalg.norm(sim.wall_reactions()["floor"][:2])
    assert history["floor_stress"][-1] == pytest.approx(reaction / width, rel=1e-12)
    volumes = np.bincount(np.asarray(sim.model.node_particle), sim.volumes)
    solid = network.assembly_stress(sim.particle_stresses(), volumes)
    assert history["stress_yy"][-1] == pytest.approx(solid[1, 1], rel=1e-12)
    assert history["stress_yy"][-1] < 0 and "stress_zz" not in history
    fabric = network.fabric_tensor(live, 2)
    assert history["fabric_xx"][-1] + history["fabric_yy"][-1] == pytest.approx(1.0, rel=1e-12)
    assert history["fabric_xy"][-1] == pytest.approx(fabric[0, 1], rel=1e-12)
    chains = (tmp_path / "run" / "frames" / "contacts_000002.vtu").read_bytes()
    assert b'NumberOfCells="5"' in chains and b'Name="Normal_Force"' in chains


def test_a_tracked_platen_given_an_area_records_its_stress(tmp_path: Path) -> None:
    """A disc settled on a fixed rectangle (a meshed platen, like a PeriDEM deck's wall): the
    platen's history.csv stress, its force resultant over the width given in track_areas, is
    the disc's weight over that width (measured to 3e-7; asserted 1e-4)."""
    sim = gr.Simulation(2, gravity=(0, -100.0), viscous_damping=300.0)
    sim.contact = gr.Contact(restitution=0.2, friction=0.5)
    disc = sim.add_body(gr.Disc((2e-3, 1.05e-3), RADIUS), grain(1e7), RADIUS / 4)
    width = 4e-3
    platen = sim.add_body(gr.Rectangle((0, -0.5e-3), (width, 0)), grain(1e7), RADIUS / 4)
    sim.fix(platen.nodes)
    sim.output(tmp_path / "run", 2000, track=[platen], track_areas={platen.name: width})
    sim.run(until=0.08)
    weight = float(sim.volumes[: disc.node_count].sum()) * DENSITY * 100.0
    history = read_history(tmp_path / "run")
    assert history[f"{platen.name}_stress"][-1] == pytest.approx(weight / width, rel=1e-4)
    assert f"{disc.name}_stress" not in history
    written = plots.plot_history(tmp_path / "run")
    assert tmp_path / "run" / f"body_{platen.name}_stress.png" in written


def test_bad_track_areas_are_input_errors(tmp_path: Path) -> None:
    sim = gr.Simulation(2)
    disc = sim.add_body(gr.Disc((0, 2e-3), RADIUS), grain(), RADIUS / 3, name="disc")
    with pytest.raises(gr.InputError, match="'lid', which is not tracked; track it too"):
        sim.output(tmp_path / "a", 10, track=[disc], track_areas={"lid": 1e-3})
    with pytest.raises(gr.InputError, match=r"track_areas\['disc'\] must be a positive area"):
        sim.output(tmp_path / "b", 10, track=[disc], track_areas={"disc": -1e-3})
    with pytest.raises(gr.InputError, match="must map tracked bodies' names"):
        sim.output(tmp_path / "c", 10, track=[disc], track_areas=[1e-3])  # type: ignore[arg-type]


def test_bad_wall_areas_and_stress_methods_are_input_errors() -> None:
    sim = gr.Simulation(2)
    with pytest.raises(gr.InputError, match="area must be positive"):
        sim.add_wall(gr.Wall((gr.Plane((0, 0), (0, 1)),), area=-1.0))
    with pytest.raises(gr.InputError, match="area must be a number"):
        sim.add_wall(gr.Wall((gr.Plane((0, 0), (0, 1)),), area="1 m"))  # type: ignore[arg-type]
    sim.add_body(gr.Disc((0, 2e-3), RADIUS), grain(), RADIUS / 3)
    with pytest.raises(gr.InputError, match="method must be"):
        sim.particle_stresses("virial")  # type: ignore[arg-type]
