"""A rank's part of a simulation (Simulation._subdomain, for granulate.parallel): the grains it
holds, renumbered in the serial order, set up as the whole (loads on their nodes, initial
motion, contact, walls), and nothing else."""

from __future__ import annotations

import numpy as np
import pytest

import granulate as gr
from granulate.shapes import rotation_matrix

ROCK = gr.Material(density=2000, bulk_modulus=1e7, shear_modulus=6e6, fracture_energy=10)


def row_of_discs() -> gr.Simulation:
    """Four discs in a row; the last one moving, the first one's left half fixed."""
    sim = gr.Simulation(2, gravity=(0, -9.81, 0))
    for k in range(4):
        velocity = (0.3, 0.0) if k == 3 else None
        sim.add_body(gr.Disc((2.2e-3 * k, 0.0), 1e-3), ROCK, 2.5e-4, velocity=velocity)
    sim.fix(sim.select(gr.Rectangle((-2e-3, -2e-3), (-0.5e-3, 2e-3))), "xy")
    sim.add_wall(gr.Wall(gr.Plane((0, -1.2e-3, 0), (0, 1, 0))), name="floor")
    return sim


def test_a_subdomain_holds_its_grains_renumbered_with_their_set_up() -> None:
    whole = row_of_discs()
    part, node_map = whole._subdomain(np.array([0, 3]), dt=1e-8, skin=1e-4)
    a, d = whole.bodies[0], whole.bodies[3]
    assert [b.node_count for b in part.bodies] == [a.node_count, d.node_count]
    assert part.bodies[1].first_node == a.node_count
    np.testing.assert_array_equal(node_map[d.node_slice], part.bodies[1].nodes)
    assert np.all(node_map[whole.bodies[1].node_slice] == -1)
    kept = np.r_[a.nodes, d.nodes]
    np.testing.assert_array_equal(part.positions, whole.positions[kept])
    np.testing.assert_array_equal(part.velocities, whole.velocities[kept])  # disc 3's motion
    assert part.dt == 1e-8 and part.core.contact_skin == 1e-4
    assert part.walls == whole.walls
    part.run(20)  # gravity and the fixed half, on the renumbered nodes
    held = whole._loading.loads[0].nodes
    np.testing.assert_array_equal(part.positions[held], whole.positions[held])
    assert part.velocities[part.bodies[1].nodes, 1].mean() < 0


def test_loads_on_grains_left_out_are_left_out() -> None:
    part, _ = row_of_discs()._subdomain(np.array([2]))
    assert part._loading.loads == []


@pytest.mark.parametrize("grains", [[], [2, 1], [4], [-1, 0]])
def test_a_subdomain_takes_increasing_grains_that_exist(grains: list[int]) -> None:
    with pytest.raises(gr.InputError, match="subset"):
        row_of_discs()._subdomain(np.array(grains, dtype=np.int64))


def test_a_subdomain_keeps_peridem_damping_as_the_whole_sets_it() -> None:
    """PeriDEM's damping (--peridem-compat) on a part: its contact radius is the whole
    assembly's (the law's factor times the smallest mesh size of the bodies of the pair's
    materials: here a finer slab, which one part leaves out) and its walls are the part's
    bodies of the same names."""
    whole = row_of_discs()
    slab = whole.add_body(gr.Rectangle((-1e-3, 1.5e-3), (8e-3, 2e-3)), ROCK, 1.25e-4, name="slab")
    whole.set_peridem_damping(ROCK, ROCK, epsilon=0.9)
    whole.set_peridem_walls([slab])
    reach = whole._interactions.peridem_reach()
    assert reach == pytest.approx(1.01 * gr.Contact().contact_radius_factor * 1.25e-4)
    discs, _ = whole._subdomain(np.array([0, 3]))
    with_slab, _ = whole._subdomain(np.array([3, 4]))
    assert discs._interactions.peridem_reach() == with_slab._interactions.peridem_reach() == reach
    assert discs._interactions.peridem_walls == []
    assert with_slab._interactions.peridem_walls == ["slab"]
    alone = gr.Simulation(2)  # the discs' own smallest mesh size would give another radius
    alone.add_body(gr.Disc((0.0, 0.0), 1e-3), ROCK, 2.5e-4)
    alone.set_peridem_damping(ROCK, ROCK, epsilon=0.9)
    assert alone._interactions.peridem_reach() == pytest.approx(2 * reach)


def test_translated_copies_in_a_subdomain_keep_the_whole_assemblys_bonds() -> None:
    """The four discs are translated copies: the whole run builds one bond family from disc
    0's nodes, whose lengths differ from disc 2's own by round-off. A part without disc 0 must
    use the same family (its first copy would otherwise make one from disc 2's nodes), or its
    dilatations differ in the last bits."""
    whole = row_of_discs()
    whole.core.run(0)
    part, node_map = whole._subdomain(np.array([2, 3]))
    part.core.run(0)
    disc = whole.bodies[2].node_slice
    np.testing.assert_array_equal(part.core.dilatation[node_map[disc]], whole.core.dilatation[disc])
    alone = row_of_discs()._subdomain(np.array([2, 3]))[0]
    alone._assembly.parent = None  # the part as if it were a whole assembly of its own
    alone.core.run(0)
    assert np.any(alone.core.dilatation[node_map[disc]] != whole.core.dilatation[disc])


def test_a_part_sums_its_grains_bonds_in_the_whole_models_order() -> None:
    """Six discs of 103 bond copies a node (horizon 4.5 h) out of 40: Model::cut_bond_blocks
    cuts a particle by its own bonds alone (these 10,700 forward bonds: whole), so a disc's
    bond forces in the part are the whole model's to the bit. When the cut followed the
    model's bonds, the part cut the discs into ranges the whole did not, and their nodes took
    their terms in another order: 1.1e-11 apart (6 ulp of rho g) on 71 of 208 nodes."""
    rock = ROCK.model_copy(update={"horizon": 4.5 * 1.25e-4})

    def rows() -> gr.Simulation:
        sim = gr.Simulation(2, gravity=(0, -9.81, 0))
        for k in range(40):
            row, column = divmod(k, 10)
            centre = (2e-3 * (column + 0.5 * (row % 2)), np.sqrt(3) * 1e-3 * row)
            sim.add_body(gr.Disc(centre, 0.99e-3), rock, 1.25e-4)
        sim.contact = None
        return sim

    whole = rows()
    whole.core.run(0)
    part, node_map = rows()._subdomain(np.arange(6), dt=whole.dt)
    part.core.run(0)
    disc = whole.bodies[1].node_slice
    np.testing.assert_array_equal(part.core.forces[node_map[disc]], whole.core.forces[disc])


def test_placed_particles_hold_no_node_arrays() -> None:
    """A particle placed from a reference shape keeps its placement, not its nodes
    (body_nodes.py): the assembly holds node arrays only of the bodies meshed where they stand,
    and a placed particle's nodes, computed when asked, are x = c + R (s p) (z = 0 in 2D) and
    V s^d, the same bits at every call and in the built model."""
    sim = gr.Simulation(2)
    disc = gr.ReferenceShape.from_shape(gr.Disc((0, 0), 1e-3), 2.5e-4)
    sim.add_particle(disc, ROCK, position=(1e-3, 2e-3), rotation=0.3, scale=1.2)
    sim.add_body(gr.Disc((5e-3, 0), 1e-3), ROCK, 2.5e-4)
    assembly = sim._assembly
    meshed = assembly.positions[1], assembly.volumes[1]
    assert [a is b for a, b in zip(assembly.stored_arrays(), meshed, strict=True)] == [True, True]
    expected = np.array([1e-3, 2e-3, 0.0]) + (1.2 * disc.positions) @ rotation_matrix(0.3, 2).T
    expected[:, 2] = 0.0
    np.testing.assert_array_equal(assembly.positions[0], expected)
    np.testing.assert_array_equal(assembly.positions[0], assembly.positions[0])
    np.testing.assert_array_equal(assembly.volumes[0], disc.volumes * 1.2**2)
    sim.core.run(0)
    nodes = sim.bodies[0].node_slice
    np.testing.assert_array_equal(sim.model.reference_positions[nodes], expected)


def test_a_part_keeps_the_outer_layers_of_its_grains_alone() -> None:
    """A part's scan of the whole assembly for translated copies (every grain, on every rank)
    compares the surface law's outer layers only of grains whose nodes match an earlier one's
    and keeps none: the part keeps the outer layers of the grains it builds (session 49: every
    rank kept every grain's, 32 bytes a node of the whole run). Two rows of discs, the second
    a size apart: the copies in each row are still found (one shape a row)."""
    whole = gr.Simulation(2)
    for k in range(6):
        radius = 1e-3 if k < 3 else 0.8e-3
        whole.add_body(gr.Disc((2.2e-3 * k, 0.0), radius), ROCK, 2.5e-4)
    part, _ = whole._subdomain(np.array([4]))
    part.core.run(0)
    kept = ["outer_layer_of" in vars(shape) for shape in whole._assembly.surfaces]
    assert kept == [False, False, False, True, False, False]  # disc 4 is built from disc 3's
    assert part.model.shape_count == 1
    whole.core.run(0)
    assert whole.model.shape_count == 2


def test_a_grains_critical_stretch_does_not_depend_on_the_grains_held_with_it() -> None:
    """Three discs of one material meshed at 0.25, 0.19 and 0.22 mm (each its own horizon, 3
    mesh sizes): each grain's s0 is the material's at its own horizon. It was the material's
    s0 at the horizon of the model's first grain of that material, scaled by sqrt(h_first /
    h): a part without disc 0 made its discs' s0 one rounding apart from the whole run's
    (1.7e-16 and 1.8e-16 relative), so a bond could break on one rank and not in the serial
    run, and PeriDEM's Z differed in the last bits."""
    whole = gr.Simulation(2)
    for k, mesh in enumerate((2.5e-4, 1.9e-4, 2.2e-4)):
        whole.add_body(gr.Disc((2.2e-3 * k, 0.0), 1e-3), ROCK, mesh)
    part, _ = whole._subdomain(np.array([1, 2]))
    for grain, held in ((1, 0), (2, 1)):
        s0 = ROCK.critical_stretch(whole.bodies[grain].mesh_size, 2)
        assert whole.model.particle_critical_stretch(grain) == s0
        assert part.model.particle_critical_stretch(held) == s0


def two_materials() -> gr.Simulation:
    """Discs of a heavy and a light material at mesh sizes 0.08-0.4 mm, the pair of materials
    with a contact law of its own (ten times stiffer)."""
    heavy = gr.Material(density=8000, youngs_modulus=1e9, poisson_ratio=0.25, fracture=False)
    light = gr.Material(density=300, youngs_modulus=1e9, poisson_ratio=0.25, fracture=False)
    sim = gr.Simulation(2)
    sim.set_contact(heavy, light, gr.Contact(stiffness_factor=10))
    for k, (material, h) in enumerate(
        [(heavy, 0.08e-3), (heavy, 0.3e-3), (heavy, 0.4e-3), (light, 0.2e-3), (light, 0.35e-3)]
    ):
        sim.add_body(gr.Disc((2.5e-3 * k, 0.0), 1e-3), material, h)
    return sim


def test_a_part_finds_the_contact_time_step_against_every_grain_as_a_partner() -> None:
    """A distributed run's part builds its own grains (and each material's coarsest) and takes
    every grain of the run as a contact partner (core.contact_partners, gathered, then
    core.contact_stable_time_step_against): the least over parts that cover the grains is
    the whole run's estimate, bit for bit; the whole's own rows give its own estimate."""
    whole = two_materials()
    rows = np.asarray(whole.core.contact_partners()).reshape(-1, 5)
    expected = whole.core.contact_stable_time_step
    assert whole.core.contact_stable_time_step_against(rows.ravel()) == expected
    estimates = []
    for grains in ([0, 2, 4], [1, 2, 3, 4]):  # 2 and 4 are each material's coarsest
        part = whole._subdomain(np.array(grains))[0]
        core = part.core  # numbers its materials
        numbers = {id(m): k for k, m in enumerate(part._core_materials)}
        table = rows.copy()
        table[:, 0] = [numbers[id(whole._core_materials[int(m)])] for m in rows[:, 0]]
        estimates.append(core.contact_stable_time_step_against(table.ravel()))
    assert min(estimates) == expected
