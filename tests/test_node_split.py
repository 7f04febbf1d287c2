"""What a body split at node level rests on (docs/parallel.md, issue 17): a part of a body
that holds its own nodes and, of the rest, the nodes bonded to them (its halo, one horizon
deep), computes its own nodes' steps exactly as the whole body does, given each step the halo's
positions after the drift and, for LPS, the halo's dilatation sums after pass 1 (the two
exchanges of a step). The core evaluates of a foreign node only its bonds to own nodes
(core.set_foreign_nodes), so each own node sums the serial run's terms in the serial run's
order, and a bond across the cut breaks alike on both sides.

Notched plates and strips (2D, LPS and PMB) and a notched block (3D, LPS) stretched until they
crack are run whole and as parts in one process, the parts exchanging as ranks would; every own
node's position, velocity, force, dilatation and bond states agree bit for bit, for a cut
across the body and for nodes dealt to the parts at random (a halo of nearly the whole body),
with each pass's inner bond blocks (those that read nothing of the halo, which a rank evaluates
while the halo travels) taken before the halo is given. Left out, the positions' exchange
changes every case and the dilatations' every LPS case."""

from __future__ import annotations

import numpy as np
import pytest

import granulate as gr
from assemblies import GLASS, pulled
from granulate import core_model
from granulate.parallel.node_split import _dealt_in_blocks
from granulate.run_sums import BLOCK


def parts_of(sim: gr.Simulation, parts: int, dealt: str) -> np.ndarray:
    """Each node's part: slabs across the longest side (a cut through the notch's plane for two
    parts), or dealt at random."""
    n = sim.node_count
    if dealt == "random":
        return np.random.default_rng(3).integers(0, parts, n)
    x = sim.reference_positions
    order = np.argsort(x[:, np.argmax(np.ptp(x, axis=0))], kind="stable")
    owner = np.empty(n, dtype=np.int64)
    owner[order] = np.arange(n) * parts // n
    return owner


def step_parts(split: list[gr.Simulation], owner: np.ndarray, halos: list[np.ndarray]) -> int:
    """One step of every part, with the two exchanges a rank makes: the halo's positions after
    the drift, its dilatation sums after pass 1 (both from each halo node's owner); before
    each, the inner bond blocks' pass (core.evaluate_dilatation, evaluate_bonds, in two
    parts), which a rank runs while the halo travels and which must read nothing of it (the
    halo here holds the step before's). The own nodes whose dilatation sums the inner blocks
    of pass 1 gave terms to."""
    inner = 0
    for part in split:
        part.core.move()
        before = np.array(part.core.dilatation)
        part.core.evaluate_dilatation(0.5)
        part.core.evaluate_dilatation(1.0)
        inner += int(np.count_nonzero(np.asarray(part.core.dilatation) != before))
    for p, part in enumerate(split):
        for q, other in enumerate(split):
            mine = halos[p][owner[halos[p]] == q]
            part.core.positions[mine] = other.core.positions[mine]
    sums = []
    for part in split:
        part.core.begin_step()
        sums.append(np.array(part.core.dilatation))  # sent, before the own nodes' are scaled
        part.core.evaluate_bonds(0.5)
        part.core.evaluate_bonds(1.0)
    for p, part in enumerate(split):
        part.core.dilatation[halos[p]] = np.choose(owner[halos[p]], [s[halos[p]] for s in sums])
    for part in split:
        part.core.finish_step(np.zeros((0, 2), np.uint32))
    return inner


def bond_copies_of(sim: gr.Simulation, nodes: np.ndarray) -> np.ndarray:
    """The bond copies (positions in core.bond_intact) of these nodes."""
    offsets = np.asarray(sim.model.bond_offsets, dtype=np.int64)
    return np.concatenate([np.arange(offsets[i], offsets[i + 1]) for i in nodes])


@pytest.mark.parametrize(
    ("shape", "model", "parts", "dealt"),
    [
        ("plate", "lps", 2, "slabs"),
        ("plate", "pmb", 3, "slabs"),
        ("plate", "lps", 3, "random"),
        ("strip", "lps", 2, "slabs"),
        ("strip", "pmb", 3, "random"),
        ("block", "lps", 2, "slabs"),
    ],
)
def test_a_split_body_steps_as_the_whole_bit_for_bit(
    shape: str, model: str, parts: int, dealt: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`parts` parts stepped with their two exchanges against the whole body, `steps` steps
    into its cracking: own nodes' state and bonds bit for bit, each bond broken counted once.
    Cut in slabs, the parts' inner blocks (evaluated before the halo is given) hold nodes. The
    plate and the strip (under 16,384 forward bonds) are cut into blocks as larger bodies are:
    core_model.WHOLE_PARTICLE_BONDS 4,096."""
    monkeypatch.setattr(core_model, "WHOLE_PARTICLE_BONDS", 4096)
    steps = 200 if shape == "block" else 300
    whole = pulled(shape, model)
    assert list(whole.model.particle_gathers) == [shape == "strip"]
    owner = parts_of(whole, parts, dealt)
    split = [pulled(shape, model) for _ in range(parts)]
    halos = []
    for p, part in enumerate(split):
        own = np.flatnonzero(owner == p)
        part.core.run(0)  # the first evaluation, before the nodes are dealt
        part.core.set_foreign_nodes(np.flatnonzero(owner != p).tolist())
        partners = np.asarray(part.model.bond_partners(own.tolist()), dtype=np.int64)
        halos.append(partners[owner[partners] != p])
    whole.core.run(steps)
    inner = sum(step_parts(split, owner, halos) for _ in range(steps))
    if dealt == "slabs":
        assert inner > 0
    assert whole.core.broken_bonds() > 100  # it cracked
    assert sum(part.core.broken_bonds() for part in split) == whole.core.broken_bonds()
    intact = whole.core.bond_intact
    for p, part in enumerate(split):
        own = np.flatnonzero(owner == p)
        for field in ("positions", "velocities", "forces", "dilatation"):
            np.testing.assert_array_equal(
                getattr(part.core, field)[own], getattr(whole.core, field)[own]
            )
        copies = bond_copies_of(whole, own)
        np.testing.assert_array_equal(part.core.bond_intact[copies], intact[copies])
        assert len(halos[p]) > 0


def test_a_split_body_refuses_contact_it_cannot_measure_yet() -> None:
    sim = gr.Simulation(dimension=2, plane="stress")
    sim.add_body(gr.Rectangle((0, 0), (0.01, 0.01)), gr.Material(**GLASS), mesh_size=1e-3)
    sim.core.run(0)
    with pytest.raises(gr.InputError, match="split at node level runs without contact"):
        sim.core.set_foreign_nodes([0, 1])


def test_foreign_nodes_must_be_this_process_particles() -> None:
    sim = pulled("plate", "lps")
    with pytest.raises(gr.InputError, match="foreign node 99999999 is not a node"):
        sim.core.set_foreign_nodes([99999999])


def test_nodes_are_dealt_in_whole_blocks_of_the_run_sums() -> None:
    """NodeSplitRun deals the nodes of a block and a bar beside it (the bar's first nodes share
    a block with the block's last) to 3 ranks in whole blocks of 64, cut where a particle
    ends (so each rank makes the serial run's runs of the tables' sums, run_sums.py), no rank
    holding nodes of both bodies from one block, each rank's weight within 10 % of a third."""
    sim = gr.Simulation(dimension=3)
    for box in (gr.Box((0, 0, 0), (0.01, 5e-3, 3e-3)), gr.Box((0.012, 0, 0), (0.02, 2e-3, 2e-3))):
        sim.add_body(box, gr.Material(**GLASS), mesh_size=0.5e-3)
    weights = np.diff(np.asarray(sim.model.bond_offsets)) + 1.0
    particles = np.asarray(sim.model.node_particle, dtype=np.int64)
    owner = _dealt_in_blocks(sim.reference_positions, particles, weights, 3)
    blocks = np.arange(sim.node_count) // BLOCK
    shared = blocks[sim.bodies[1].first_node]
    assert particles[blocks == shared].min() == 0 and particles[blocks == shared].max() == 1
    for b in np.unique(blocks):
        for q in np.unique(particles[blocks == b]):
            assert len(np.unique(owner[(blocks == b) & (particles == q)])) == 1
    shares = np.bincount(owner, weights, 3) / weights.sum()
    np.testing.assert_allclose(shares, 1 / 3, rtol=0.1)


def test_a_run_on_ranks_tells_how_it_deals_its_work() -> None:
    """Simulation.distribution (granulate run prints it): None serially; on ranks "nodes" when
    nothing touches (the bodies cut at node level), "grains" with contact."""
    from mpi4py import MPI

    def plate(comm: object | None, contact: bool) -> gr.Simulation:
        sim = gr.Simulation(dimension=2, plane="stress", comm=comm)
        sim.add_body(gr.Rectangle((0, 0), (0.01, 0.01)), gr.Material(**GLASS), mesh_size=1e-3)
        if not contact:
            sim.contact = None
        return sim

    assert plate(None, contact=False).distribution is None
    assert plate(MPI.COMM_SELF, contact=False).distribution == "nodes"
    assert plate(MPI.COMM_SELF, contact=True).distribution == "grains"
