"""The whole state of a distributed run on rank 0, for the end of a run (unless
run(..., gather=False)) and outputs of writers that may read the simulation (an output step of
the built-in writers, a frame of every node included, is made of the ranks' measures instead:
step_parts.py).

Each rank sends its own grains' nodes (positions, velocities, forces, dilatation) and bonds, and
what its last force evaluation left for them: the contacts whose first body it owns (the
network's rows, in global numbering), its nodes' contact energy and contact counts
(ContactModel::node_contact_terms) and its neighbour-list searches. Rank 0 puts the nodes and
bonds into its simulation, built whole once, and the evaluation in the serial order: contact rows
sorted as the serial core's slots (pairs of bodies by their smallest nodes, then bodies and walls),
the energy's correctly rounded sum (granulate.exact_sum), as the serial Evaluation gives it.
Every value is then the serial run's at that step, bit for bit, except the number of list
searches, which each rank makes for its own part (the largest over the ranks is given).

The measures that read every bond or sum over every node (the damage, the fragment labels, the
strain energy densities and the particles' motion: analysis.GivenMeasures) each rank makes of
its own grains, as the serial core makes them node by node and particle by particle, and rank 0
puts them together (its Analysis uses them for that step) instead of making them all from the
gathered state: the history rows and frames cost rank 0 that much less while the ranks wait.

Rank 0 holds the whole model and state for this, as it holds the whole frame it writes; that
bounds the size of a distributed run to what one process can hold (docs/parallel.md).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from granulate import core_model, network, particle_table
from granulate.analysis import GivenMeasures
from granulate.errors import InputError
from granulate.evaluation import Evaluation
from granulate.exact_sum import ExactSum

if TYPE_CHECKING:
    from granulate.parallel.engine import DistributedRun
    from granulate.simulation import Simulation

_NO_NODE = 2**32 - 1  # ContactNetwork's node_b of a wall contact
_ROW_KEYS = ("particle_a", "node_a", "particle_b", "node_b", "wall")
_VECTOR_KEYS = ("point", "normal", "force")


def require_room(sim: Simulation) -> None:
    """Rank 0 of Simulation(comm=...)'s run, at its start: InputError when its whole
    simulation, which it builds the first time the ranks send it their state (a frame of every
    node, a writer that reads the simulation, the end of a run), would not fit in the memory
    free now (build_model's check), rather than when it first needs it, maybe hours in. A bare
    DistributedRun that never gathers (bench --ranks) is not checked."""
    try:
        outer_layers = sim._interactions.uses_surface_law()
        core_model.require_memory_for(sim._assembly, sim.plane, outer_layers)
    except InputError as error:
        raise InputError(
            f"{error}. On MPI ranks, rank 0 holds the whole model at the end of a run (and for "
            "writers that read the simulation): give it a machine with that much memory free "
            "(fewer ranks beside it), or run(..., gather=False)"
        ) from None


@dataclass
class OwnedPart:
    """What one rank sends rank 0: its grains' nodes (in grain order) and bonds, and its part of
    the last force evaluation."""

    grains: NDArray[np.int64]
    positions: NDArray[np.float64]  # (n, 3) [m]
    velocities: NDArray[np.float64]  # (n, 3) [m/s]
    forces: NDArray[np.float64]  # (n, 3) [N/m^3]
    dilatation: NDArray[np.float64]  # (n,)
    bonds: NDArray[np.uint8]  # the grains' bond copies, in the model's order
    evaluation: OwnEvaluation
    #: of the grains' nodes and of the grains (labels: global nodes), when asked for
    measures: GivenMeasures | None


@dataclass(frozen=True)
class OwnEvaluation:
    """What the last force evaluation left of a rank's own grains: the network's rows whose
    first body it owns (in global numbering), its nodes' contact energy (an exact sum,
    ContactModel::node_contact_terms), their node pair and wall contacts, and its part's
    neighbour-list searches."""

    contacts: dict[str, NDArray[Any]]
    contact_energy: ExactSum  # [J; J/m in 2D]
    node_contacts: int
    wall_contacts: int
    searches: int

    @classmethod
    def of(cls, run: DistributedRun) -> OwnEvaluation:
        core, nodes = run.local.core, run.owned_nodes
        energy, pairs, walls = (np.asarray(a)[nodes] for a in core.node_contact_terms())
        return cls(
            owned_contacts(run, core.contact_network()),
            ExactSum.of(energy),
            int(pairs.sum()),
            int(walls.sum()),
            int(core.contact_statistics.rebuilds),
        )


def merged_evaluation(
    parts: list[OwnEvaluation], wall_reactions: NDArray[np.float64]
) -> Evaluation:
    """Rank 0: the whole run's evaluation (Evaluation) from every rank's, in the serial order:
    contact rows sorted as the serial slots, the energy's correctly rounded sum, the counts,
    the most list searches of any rank, and the walls' reactions."""
    return Evaluation(
        network.contact_table(serial_order([part.contacts for part in parts])),
        sum((part.contact_energy for part in parts), ExactSum()).value,
        sum(part.node_contacts for part in parts),
        sum(part.wall_contacts for part in parts),
        max(part.searches for part in parts),
        wall_reactions,
    )


def owned_part(run: DistributedRun, measures: bool = True) -> OwnedPart:
    """This rank's OwnedPart (the run's part holds the last step's evaluation), with its
    grains' measures or without."""
    core, nodes = run.local.core, run.owned_nodes
    offsets = np.asarray(run.local.model.bond_offsets, dtype=np.int64)
    intact = np.asarray(core.bond_intact)
    bond_rows = [intact[offsets[s.start] : offsets[s.stop]] for s in run.owned_slices()]
    return OwnedPart(
        run.owned,
        core.positions[nodes],
        core.velocities[nodes],
        core.forces[nodes],
        np.asarray(core.dilatation)[nodes],
        np.concatenate(bond_rows) if bond_rows else np.zeros(0, np.uint8),
        OwnEvaluation.of(run),
        _owned_measures(run) if measures else None,
    )


def _owned_measures(run: DistributedRun) -> GivenMeasures:
    """The measures of the rank's own grains (analysis.GivenMeasures): per own node, in grain
    order, its damage, Z, fragment label (a global node) and strain energy density, and per
    own grain its motion. Each node's and each grain's are the whole core's, bit for bit: a
    node's reads only its own bonds, and a grain's sums run over its nodes run by run in the serial
    order (run_sums.py), whatever else the part holds."""
    local, nodes = run.local, run.owned_nodes
    core, model = local.core, local.model
    phi, z = (np.asarray(a)[nodes] for a in core.damage())
    labels = run.global_nodes(np.asarray(core.fragments())[nodes]).astype(np.uint32)
    volumes = np.asarray(model.volumes)[nodes]
    mass = np.asarray(model.node_density)[nodes] * volumes
    x, v = core.positions[nodes], core.velocities[nodes]
    numbers, grains = run.global_nodes(nodes), len(run.owned)
    motion = particle_table.motion(own_grain_places(run), numbers, mass, volumes, x, v, grains)
    density = np.asarray(core.strain_energy_density())[nodes]
    return GivenMeasures(phi, z, labels, density, motion)


def own_grain_places(run: DistributedRun) -> NDArray[np.int64]:
    """Per own node (in grain order), its grain's place among the grains the rank owns."""
    particle = np.asarray(run.local.model.node_particle)[run.owned_nodes]
    return np.searchsorted(run.owned, run.held[particle])


def owned_contacts(run: DistributedRun, local: dict[str, Any]) -> dict[str, NDArray[Any]]:
    """The rows of a rank's contact network (ContactNetwork) whose first body it owns, in
    global numbering: grains for particles, global nodes for the bodies' smallest nodes."""
    every = {key: np.asarray(local[key]).astype(np.int64) for key in _ROW_KEYS}
    kept = run.is_owned_node(every["node_a"])
    rows = {key: values[kept] for key, values in every.items()}
    wall = rows["wall"] == 1
    other = np.where(wall, 0, rows["particle_b"])  # a wall's index is no particle
    contacts = {
        "particle_a": run.held[rows["particle_a"]],
        "node_a": run.global_nodes(rows["node_a"]),
        "particle_b": np.where(wall, rows["particle_b"], run.held[other]),
        "node_b": np.where(wall, _NO_NODE, run.global_nodes(np.where(wall, 0, rows["node_b"]))),
        "wall": rows["wall"],
    }
    for key in _VECTOR_KEYS:
        contacts[key] = np.asarray(local[key], dtype=np.float64).reshape(-1, 3)[kept]
    return contacts


def install(
    sim: Simulation,
    parts: list[OwnedPart],
    moment: tuple[float, int],
    wall_reactions: NDArray[np.float64],
) -> None:
    """Rank 0: `parts` (every rank's) into `sim`, built whole on first use: its nodes and bonds
    at `moment` (time [s], step), its last evaluation (Simulation.evaluation) and, when every
    part has them, its grains' measures (Analysis.give)."""
    sim._ranks_ahead = False  # it takes the ranks' state now
    core = sim._build()
    starts = np.array([body.first_node for body in sim.bodies] + [sim.node_count])
    bond_starts = np.asarray(sim.model.bond_offsets, dtype=np.int64)[starts]
    bonds = np.empty(bond_starts[-1], dtype=np.uint8)
    measured = [part.measures for part in parts if part.measures is not None]
    given = _empty_measures(measured[0], sim.node_count, len(sim.bodies)) if measured else None
    x, v, f, dilatation = core.positions, core.velocities, core.forces, core.dilatation
    for part in parts:  # every grain is one rank's: every node and bond is written
        rows = [
            (x, part.positions),
            (v, part.velocities),
            (f, part.forces),
            (dilatation, part.dilatation),
        ]
        if given is not None and part.measures is not None:
            rows += _measured_rows(given, part.measures)
            for column, values in given.motion.items():
                values[part.grains] = part.measures.motion[column]
        _place(part.grains, starts, rows)
        _place(part.grains, bond_starts, [(bonds, part.bonds)])
    core.assign_bonds(bonds)
    core.time, core.step = moment
    sim.analysis.give(given if len(measured) == len(parts) else None)
    sim._gathered = merged_evaluation([part.evaluation for part in parts], wall_reactions)


def _empty_measures(like: GivenMeasures, nodes: int, grains: int) -> GivenMeasures:
    """GivenMeasures of `nodes` nodes and `grains` grains to fill, with `like`'s motion
    columns (particle_table.motion's)."""
    return GivenMeasures(
        np.empty(nodes),
        np.empty(nodes),
        np.empty(nodes, dtype=np.uint32),
        np.empty(nodes),
        {column: np.empty(grains) for column in like.motion},
    )


def _measured_rows(
    whole: GivenMeasures, part: GivenMeasures
) -> list[tuple[NDArray[Any], NDArray[Any]]]:
    """The per-node measures of a part, each with the whole's array it goes into (_place)."""
    return [
        (whole.damage, part.damage),
        (whole.damage_z, part.damage_z),
        (whole.labels, part.labels),
        (whole.strain_energy_density, part.strain_energy_density),
    ]


def _place(
    grains: NDArray[np.int64],
    starts: NDArray[np.int64],
    rows: list[tuple[NDArray[Any], NDArray[Any]]],
) -> None:
    """A part's rows of `grains` (one after the other, in grain order) into the whole's arrays:
    for each (whole, part) of `rows`, grain g's rows go to whole[starts[g] : starts[g + 1]]."""
    at = 0
    for g in grains:
        whole = slice(starts[g], starts[g + 1])
        mine = slice(at, at + whole.stop - whole.start)
        for target, source in rows:
            target[whole] = source[mine]
        at = mine.stop


def serial_order(pieces: list[dict[str, NDArray[Any]]]) -> dict[str, NDArray[Any]]:
    """The ranks' contact rows as one network in the serial core's slot order: pairs of bodies
    sorted by their smallest nodes, then bodies and walls sorted by body and wall."""
    rows = {key: np.concatenate([piece[key] for piece in pieces]) for key in pieces[0]}
    wall = rows["wall"] == 1
    order = np.lexsort((np.where(wall, rows["particle_b"], rows["node_b"]), rows["node_a"], wall))
    return {key: values[order] for key, values in rows.items()}
