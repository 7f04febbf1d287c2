"""What distributed runs will rest on (docs/parallel.md, issue 17): a grain's motion is a
function of the grains within reach and of nothing else, bit for bit. A rank that holds a grain
and, as ghosts, the grains near it, in the serial run's order and at the serial run's time step,
then computes that grain's steps exactly as the serial run does.

An assembly of grains pressed into each other and thrown at each other (so springs, dashpots,
friction and the surface law's probes all act from the first step) is run whole and cut down to
one grain and its neighbours; the grain's nodes must agree bit for bit. The forces at the end
of step s depend on the neighbours' positions then, which depend on their neighbours' forces a
step before, and so on: s + 1 hops from grain to touching grain, so the cut keeps the grains
within (s + 1) x 2.1 radii of the grain's centre (the lattices' spacing is 1.9)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import granulate as gr
from assemblies import RADIUS, assembly, layout, pulled, tumbling_drum
from granulate import core_model


@pytest.mark.filterwarnings("ignore:contact.*bodies pressed")  # placed pressed, on purpose
@pytest.mark.parametrize(("dimension", "steps"), [(2, 1), (2, 3), (3, 1)])
def test_a_grain_moves_as_its_neighbourhood_says_bit_for_bit(dimension: int, steps: int) -> None:
    centres, _ = layout(dimension)
    everything = np.arange(len(centres))
    whole = assembly(dimension, everything)
    middle = int(np.argmin(np.linalg.norm(centres - centres.mean(axis=0), axis=1)))
    reach = (steps + 1) * 2.1 * RADIUS
    near = np.flatnonzero(np.linalg.norm(centres - centres[middle], axis=1) < reach)
    assert 1 < len(near) < len(centres)  # a real cut
    part = assembly(dimension, near, dt=whole.dt)
    whole.run(steps)
    part.run(steps)
    a, b = whole.bodies[middle], part.bodies[int(np.flatnonzero(near == middle)[0])]
    nodes = slice(a.first_node, a.first_node + a.node_count)
    pushed = np.abs(whole.forces[nodes] - whole.bond_forces()[nodes]).max()
    assert pushed > 1e-3 * np.abs(whole.forces[nodes]).max()  # the grain is in contact
    for field in ("positions", "velocities", "forces"):
        ours = getattr(whole, field)[a.first_node : a.first_node + a.node_count]
        theirs = getattr(part, field)[b.first_node : b.first_node + b.node_count]
        np.testing.assert_array_equal(ours, theirs, err_msg=field)


def within_reach(nodes: np.ndarray, others: np.ndarray, reach: float) -> np.ndarray:
    """Whether each of `nodes` (positions) lies within `reach` of one of `others`."""
    near = np.zeros(len(nodes), dtype=bool)
    for start in range(0, len(others), 2048):
        gaps = np.linalg.norm(nodes[:, None, :] - others[None, start : start + 2048, :], axis=2)
        near |= gaps.min(axis=1) <= reach
    return near


# The shattered square's fragments hit hard enough to pass half the contact radius (warned).
@pytest.mark.filterwarnings("ignore:contact.*bodies pressed")
@pytest.mark.parametrize(
    ("fracture", "law", "rolling"),
    [(True, "granulate", 0.0), (False, "granulate", 0.0), (True, "surface", 0.1)],
)
def test_a_ghost_grain_needs_only_its_owners_cap_motion_and_breaks(
    fracture: bool, law: str, rolling: float, tmp_path: Path
) -> None:
    """A rank skips its ghosts' bonds and moves (core.set_ghost_particles): between the halves
    of a step (core.begin_step, finish_step) their owners give them the positions and
    velocities of their nodes within reach of the rank's own (the cap: those whose list
    positions lie within the lists' cutoff of an own node's, and their anchors before and
    after the step's breaks, as DistributedRun._exchange_caps and _joining take them), the
    surface normals of those within the reach at which the contact reads them that are
    bonded to a node outside the cap (sums over their bonds: core.surface_normals,
    core.give_ghost_surface_normals; the part sums the others' itself), the breaks, and the
    motion of each of their bodies (core.fragment_motions, core.give_ghost_motions). The
    tumbling drum run twice, once with grain 1 a ghost given that within each step (node
    spheres, and the surface law with rolling resistance), its other nodes a little off (1e-9
    of their positions and velocities, so that any use of them would show) and out of the
    contact lists (core.set_inert_contact_nodes, the cap picked anew each step), and its
    bond forces evaluated before they are given (core.evaluate_bonds, as the ranks do while
    the exchange is under way; the whole run's finish_step takes them itself): the other
    grains' nodes agree bit for bit through 900 steps of contact and breaking (and do not
    without the normals, under the node-sphere law), the part breaks the other
    grains' bonds as the whole run does, and every bond ends the same, and so do the damage, Z
    and strain energy density of its own nodes. The ghost's own forces, dilatation and
    measures are not computed."""
    whole = tumbling_drum(tmp_path / "whole", fracture=fracture, law=law, rolling=rolling)
    part = tumbling_drum(tmp_path / "part", fracture=fracture, law=law, rolling=rolling)
    whole.core.run(0)
    part.core.run(0)
    part.core.set_ghost_particles([1])
    ghost = part.bodies[1].node_slice
    others = np.ones(part.core.positions.shape[0], dtype=bool)
    others[ghost] = False
    reach, normal_reach = part.core.contact_reach, part.core.contact_surface_normal_reach
    differed, given, left_out, faces = 0, 0, 0, 0
    for _ in range(900):
        broken = np.asarray(whole.core.begin_step()).reshape(-1, 2)
        own = np.asarray(part.core.begin_step()).reshape(-1, 2)
        part.core.evaluate_bonds()  # before the ghosts are given this step's state, as the ranks
        in_ghost = (broken[:, 0] >= ghost.start) & (broken[:, 0] < ghost.stop)
        assert sorted(map(tuple, own)) == sorted(map(tuple, broken[~in_ghost]))
        x = whole.core.list_positions  # where the lists see the nodes: what the caps go by
        near = ghost.start + np.flatnonzero(within_reach(x[ghost], x[others], reach))
        normal = near[within_reach(x[near], x[others], normal_reach)]
        read = (  # the anchors before and after this step's breaks (_joining's)
            part.core.contact_anchors(near.tolist()),
            whole.core.contact_anchors(near.tolist()),
        )
        cap = np.unique(np.concatenate([near, *(np.asarray(r, np.int64) for r in read)]))
        rest = np.setdiff1d(np.arange(ghost.start, ghost.stop), cap)
        left_out += len(rest)
        for field in ("positions", "velocities"):  # as the ranks' exchange within the step
            getattr(part.core, field)[cap] = getattr(whole.core, field)[cap]
            getattr(part.core, field)[rest] = getattr(whole.core, field)[rest] * (1 + 1e-9)
        part.core.set_inert_contact_nodes(rest.tolist())  # out of the lists, as on the ranks
        face = np.asarray(part.model.bonded_beyond(normal.tolist(), cap.tolist()), np.int64)
        normals = whole.core.surface_normals(face.tolist())  # the rest: from the cap, here
        part.core.give_ghost_surface_normals(face.astype(np.uint32), normals)
        faces += len(face)
        nodes, motions = whole.core.fragment_motions([1])
        part.core.give_ghost_motions(
            np.asarray(nodes, np.uint32), np.asarray(motions).reshape(-1, 15)
        )
        part.core.finish_step(broken[in_ghost].astype(np.uint32))
        whole.core.finish_step(np.zeros((0, 2), np.uint32))
        given += int(in_ghost.sum())
        for field in ("positions", "velocities", "forces"):
            ours, theirs = getattr(whole.core, field), getattr(part.core, field)
            np.testing.assert_array_equal(ours[others], theirs[others], err_msg=field)
        differed += int(not np.array_equal(whole.core.forces[ghost], part.core.forces[ghost]))
    assert differed == 900
    assert left_out > 900 * 0.1 * (ghost.stop - ghost.start)  # the caps leave nodes out
    assert faces > 450  # normals given: of the cap nodes within the normal reach (580-odd a run)
    assert (given > 20) if fracture else (given == 0)
    np.testing.assert_array_equal(whole.core.bond_intact, part.core.bond_intact)
    assert part.broken_bonds() == whole.broken_bonds()
    assert np.all(np.asarray(part.core.dilatation)[ghost] == 0)
    assert np.abs(np.asarray(whole.core.dilatation)[ghost]).max() > 0
    # What the part measures of its own grains for rank 0's outputs (whole_state): the whole
    # run's, bit for bit; nothing of the ghost's, which its owner measures.
    measures = {
        "phi": lambda core: np.asarray(core.damage()[0]),
        "z": lambda core: np.asarray(core.damage()[1]),
        "strain": lambda core: np.asarray(core.strain_energy_density()),
    }
    for name, measure in measures.items():
        ours, theirs = measure(whole.core), measure(part.core)
        np.testing.assert_array_equal(ours[others], theirs[others], err_msg=name)
        assert np.all(theirs[ghost] == 0), name
        assert np.any(ours[ghost] != 0) or (name != "strain" and not fracture), name


def test_a_ghost_body_in_contact_needs_its_owners_motion(tmp_path: Path) -> None:
    """A step in which a ghost body touches one of the rank's own bodies with no motion given
    for it (core.give_ghost_motions) stops with a RuntimeError naming the body: measured from
    the ghost nodes held, which are only its caps, its motion would be wrong. The tumbling drum
    with grain 1 a ghost given its whole positions and velocities but no motion: it reaches
    another grain within 900 steps (at step 589)."""
    whole = tumbling_drum(tmp_path / "whole")
    part = tumbling_drum(tmp_path / "part")
    whole.core.run(0)
    part.core.run(0)
    part.core.set_ghost_particles([1])
    ghost = part.bodies[1].node_slice
    with pytest.raises(RuntimeError, match=r"motion of ghost body 1 \(first node 52\) was not"):
        for _ in range(900):
            whole.core.begin_step()
            part.core.begin_step()
            for field in ("positions", "velocities"):
                getattr(part.core, field)[ghost] = getattr(whole.core, field)[ghost]
            whole.core.finish_step(np.zeros((0, 2), np.uint32))
            part.core.finish_step(np.zeros((0, 2), np.uint32))


def test_surface_normals_are_given_to_ghost_nodes_only(tmp_path: Path) -> None:
    """core.give_ghost_surface_normals refuses a node of a particle the rank owns and a count
    that does not match the normals; Model.bonded_beyond and core.surface_normals refuse a node
    that does not exist: each one InputError naming the problem."""
    sim = tumbling_drum(tmp_path)
    sim.core.run(0)
    sim.core.set_ghost_particles([1])
    first = sim.bodies[1].first_node
    with pytest.raises(gr.InputError, match="node 0 is not a node of a ghost particle"):
        sim.core.give_ghost_surface_normals(np.array([0], np.uint32), np.zeros((1, 3)))
    with pytest.raises(gr.InputError, match="one node per normal, got 2 nodes and 1 normals"):
        sim.core.give_ghost_surface_normals(
            np.array([first, first + 1], np.uint32), np.zeros((1, 3))
        )
    missing = sim.node_count + 5
    with pytest.raises(gr.InputError, match=f"bonded_beyond: node {missing} does not exist"):
        sim.model.bonded_beyond([missing], [])
    with pytest.raises(gr.InputError, match=f"surface_normals: no node {missing}"):
        sim.core.surface_normals([missing])


def pushed(sim: gr.Simulation, nodes: slice) -> bool:
    """Whether anything but their bonds and gravity acts on `nodes` (gravity: the same force
    density on each, to 1e-9 of the largest force density)."""
    rest = sim.core.forces[nodes] - sim.bond_forces()[nodes]
    return not np.allclose(rest, rest[0], rtol=0, atol=1e-9 * np.abs(sim.core.forces[nodes]).max())


def test_inert_nodes_leave_the_lists_and_come_back(tmp_path: Path) -> None:
    """core.set_inert_contact_nodes (a rank's ghost nodes outside its caps): the next
    evaluation drops their list entries, so the grain they make up is pushed by nothing; set
    back, the one after lists them again where they are, though they have not moved, and the
    contact acts on them again. An index out of range is refused. (Whether the engine's use
    changes no force is tests/test_mpi.py's and the cap test's above.)"""
    sim = tumbling_drum(tmp_path)
    sim.core.run(300)  # grains in contact with each other and the drum
    grain = sim.bodies[1].node_slice
    entries = sim.core.contact_statistics.list_entries
    walls = len(sim.core.contact_wall_entries()[1])
    sim.core.set_inert_contact_nodes(list(range(grain.start, grain.stop)))
    sim.core.compute_forces()
    inert = sim.core.contact_statistics.list_entries
    assert inert < entries
    assert len(sim.core.contact_wall_entries()[1]) < walls
    assert not pushed(sim, grain)
    sim.core.set_inert_contact_nodes([])
    sim.core.compute_forces()
    assert sim.core.contact_statistics.list_entries > inert  # those in reach now: 66 of 70
    assert pushed(sim, grain)
    with pytest.raises(gr.InputError, match="inert contact node 99999 does not exist"):
        sim.core.set_inert_contact_nodes([99999])


@pytest.mark.parametrize("case", ["plate", "drum"])
def test_bond_forces_in_parts_are_the_same_bits(
    case: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """core.evaluate_dilatation(share) and evaluate_bonds(share) walk pass 1's and pass 2's
    blocks in schedule order up to that share of them (with no foreign node every block is
    inner), from where their last call stopped, and begin_step and finish_step take the rest:
    a distributed run evaluates them in parts while its exchanges are under way. Stepped so,
    with the parts cutting through colours, the notched LPS plate cracking under tension
    (several colours) and the tumbling drum (grains: one colour, contact) are bit for bit the
    runs stepped whole. A share outside [0, 1] is refused. The plate (under 16,384 forward
    bonds) is cut into blocks as a larger body is: core_model.WHOLE_PARTICLE_BONDS 4,096."""
    monkeypatch.setattr(core_model, "WHOLE_PARTICLE_BONDS", 4096)
    whole, parted = (
        (pulled("plate", "lps"), pulled("plate", "lps"))
        if case == "plate"
        else (tumbling_drum(tmp_path / "a"), tumbling_drum(tmp_path / "b"))
    )
    blocks = np.asarray(whole.model.bond_colour_blocks)
    assert list(blocks) == ([8, 8] if case == "plate" else [2])  # cut at 4, 8, 14; at 1
    whole.core.run(0)
    parted.core.run(0)
    for _ in range(300):
        whole.core.run(1)
        parted.core.move()
        for share in (0.3, 0.55, 0.55, 0.9):
            parted.core.evaluate_dilatation(share)
        parted.core.begin_step()
        for share in (0.3, 0.3, 0.55, 0.0, 0.9):
            parted.core.evaluate_bonds(share)
        parted.core.finish_step(np.zeros((0, 2), np.uint32))
    for field in ("positions", "velocities", "forces", "bond_intact"):
        np.testing.assert_array_equal(getattr(whole.core, field), getattr(parted.core, field))
    assert whole.broken_bonds() > 0
    parted.core.move()
    for share in (1.5, -0.1, float("nan")):
        with pytest.raises(gr.InputError, match="share of the bond blocks must lie in"):
            parted.core.evaluate_dilatation(share)
    parted.core.begin_step()
    for share in (1.5, -0.1, float("nan")):
        with pytest.raises(gr.InputError, match="share of the bond blocks must lie in"):
            parted.core.evaluate_bonds(share)


def test_ghost_breaks_are_checked(tmp_path: Path) -> None:
    """What begin_step and finish_step refuse: ghosts marked before the first evaluation (its
    breaks would be lost), a finish without a begin, a step begun twice or run over, a ghost
    break that is no intact bond of a ghost particle (the step can still be finished), a ghost
    index out of range; and around them: the fragments' motions outside a step or of a ghost,
    a motion given to a node that is no ghost's or without its 15 numbers, reported numbers
    of the wrong count, the bond forces evaluated outside a step, the inner blocks' pass 1
    outside a move and its step."""
    sim = tumbling_drum(tmp_path)
    sim.core.set_ghost_particles([1])
    with pytest.raises(gr.InputError, match="before marking ghost particles"):
        sim.core.begin_step()
    sim.core.set_ghost_particles([])
    sim.core.run(0)
    sim.core.set_ghost_particles([1])
    with pytest.raises(gr.InputError, match="finish_step without begin_step"):
        sim.core.finish_step(np.zeros((0, 2), np.uint32))
    owned, ghost = sim.bodies[0].first_node, sim.bodies[1].first_node
    with pytest.raises(gr.InputError, match="between begin_step and finish_step"):
        sim.core.fragment_motions([0])
    with pytest.raises(gr.InputError, match="evaluate_bonds: call it between begin_step"):
        sim.core.evaluate_bonds()
    with pytest.raises(gr.InputError, match="evaluate_dilatation: call it between move and begin"):
        sim.core.evaluate_dilatation()
    sim.core.begin_step()
    with pytest.raises(gr.InputError, match="particle 1 is not one of this process's"):
        sim.core.fragment_motions([0, 1])
    with pytest.raises(gr.InputError, match=f"node {owned} is not a node of a ghost particle"):
        sim.core.give_ghost_motions(np.array([owned], np.uint32), np.zeros((1, 15)))
    with pytest.raises(TypeError):
        sim.core.give_ghost_motions(np.array([ghost], np.uint32), np.zeros((1, 14)))
    for start in (lambda: sim.core.run(1), sim.core.begin_step):
        with pytest.raises(gr.InputError, match="not finished"):
            start()
    for pair in ([owned, owned + 1], [ghost, ghost], [ghost, 10**6]):
        with pytest.raises(gr.InputError, match="not an intact bond of a ghost particle"):
            sim.core.finish_step(np.array([pair], np.uint32))
    sim.core.finish_step(np.zeros((0, 2), np.uint32))  # the step is still there to finish
    assert sim.core.step == 1
    with pytest.raises(gr.InputError, match="ghost particle 4 does not exist"):
        sim.core.set_ghost_particles([4])
    with pytest.raises(gr.InputError, match=r"one per node .* and one per particle"):
        sim.core.set_reported_numbers([0, 1], [0])


def farthest(now: np.ndarray, origin: np.ndarray) -> float:
    """The largest distance of a row of `now` from its row in `origin` [m]."""
    return float(np.linalg.norm(now - origin, axis=1).max())


@pytest.mark.parametrize("law", ["granulate", "surface"])
def test_the_core_measures_how_far_the_nodes_and_list_positions_travelled(
    tmp_path: Path, law: str
) -> None:
    """core.largest_travel (a rank's check that its ghosts and caps still hold): once a step
    has moved the nodes (begin_step, before its contact), the largest distance of a node, or
    of where the contact lists see a node watched (core.list_positions: the grid square's
    surface nodes' contact centres inside them, surface points under the surface law), from
    where it was at set_travel_origin [m], as NumPy finds it; 0 before the first step and with
    no origin set. The list positions are where a search lists the nodes (the lists keep them
    in single precision: 1e-8 m at these coordinates). The nodes watched are the grid square's
    (the fourth grain); a node that does not exist is refused."""
    sim = tumbling_drum(tmp_path, grid=True, law=law)
    sim.core.run(100)
    assert sim.core.largest_travel == 0.0
    sim.core.search_contacts()
    listed = np.asarray(sim.core.checkpoint()["contact_positions_at_build"]).reshape(-1, 3)
    assert np.abs(sim.core.list_positions - listed).max() < 1e-8
    assert farthest(sim.core.list_positions, sim.core.positions) > 0.1e-3  # centres off nodes
    square = sim.bodies[3].node_slice
    with pytest.raises(gr.InputError, match="node 100000 is not one of this process's nodes"):
        sim.core.set_travel_origin([0, 100_000])
    origin, list_origin = sim.core.positions.copy(), sim.core.list_positions[square]
    sim.core.set_travel_origin(list(range(square.start, square.stop)))
    assert sim.core.largest_travel == 0.0

    def moved() -> float:
        listed = farthest(sim.core.list_positions[square], list_origin)
        return max(farthest(sim.core.positions, origin), listed)

    for _ in range(4):
        sim.core.run(40)
        assert sim.core.largest_travel == pytest.approx(moved(), rel=1e-14)
        sim.core.begin_step()
        now = moved()
        assert sim.core.largest_travel == pytest.approx(now, rel=1e-14)
        sim.core.finish_step(np.zeros((0, 2), np.uint32))
        assert sim.core.largest_travel == pytest.approx(now, rel=1e-14)
    assert sim.core.largest_travel > 1e-4  # the grains fall and tumble


@pytest.mark.parametrize("watch", [True, False])
def test_a_turned_grains_surface_points_travel_farther_than_its_nodes(
    tmp_path: Path, watch: bool
) -> None:
    """A disc turned by 0.2 rad about its centre under the surface law: its outer nodes'
    surface points lie on its circle, outside them, so they move farther than any node, and
    core.largest_travel is theirs when its nodes are watched, the nodes' when they are not
    (rel 1e-12)."""
    sim = tumbling_drum(tmp_path, law="surface")
    sim.core.run(0)
    disc = sim.bodies[0].node_slice
    y, listed = sim.core.positions.copy(), sim.core.list_positions[disc]
    sim.core.set_travel_origin(list(range(disc.start, disc.stop)) if watch else [])
    centre = y[disc].mean(axis=0)
    turn = np.array([[np.cos(0.2), -np.sin(0.2), 0], [np.sin(0.2), np.cos(0.2), 0], [0, 0, 1]])
    sim.core.positions[disc] = centre + (y[disc] - centre) @ turn.T
    sim.core.begin_step()  # and the drift
    nodes = farthest(sim.core.positions, y)
    points = farthest(sim.core.list_positions[disc], listed)
    assert points > 1.02 * nodes
    assert sim.core.largest_travel == pytest.approx(points if watch else nodes, rel=1e-12)


def test_a_steps_list_positions_are_settled_when_it_begins(tmp_path: Path) -> None:
    """The anchors a step's breaks change are taken anew in begin_step, so where the lists
    see each node (core.list_positions, which the travel is measured at) is, bit for bit,
    where its contact sees it in finish_step: the grid square breaking under the surface law,
    whose surface nodes lose their anchors as it cracks (seen at themselves after)."""
    sim = tumbling_drum(tmp_path, grid=True, law="surface")
    sim.core.run(0)
    at_node = [int(np.all(sim.core.list_positions == sim.core.positions, axis=1).sum())]
    for _ in range(1500):
        broken = sim.core.begin_step()
        begun = sim.core.list_positions
        sim.core.finish_step(np.zeros((0, 2), np.uint32))
        np.testing.assert_array_equal(begun, sim.core.list_positions)
        if len(broken):
            at_node.append(int(np.all(begun == sim.core.positions, axis=1).sum()))
    assert at_node[-1] > at_node[0]  # anchors broke in these steps


def test_a_ghosts_speed_is_its_owners_to_check(tmp_path: Path) -> None:
    """The stability check passes over ghost particles (their velocities after a step are not
    their own; their owner checks them): a ghost node thrown at 1e6 m/s finishes the step, an
    owned one raises InstabilityError naming it."""
    sim = tumbling_drum(tmp_path)
    sim.core.run(0)
    sim.core.set_ghost_particles([1])
    sim.core.velocities[sim.bodies[1].first_node] = 1e6
    sim.core.begin_step()
    sim.core.finish_step(np.zeros((0, 2), np.uint32))
    owned = sim.bodies[0].first_node
    sim.core.velocities[owned] = 1e6
    sim.core.begin_step()
    with pytest.raises(gr.InstabilityError, match=f"node {owned} of particle 0"):
        sim.core.finish_step(np.zeros((0, 2), np.uint32))
