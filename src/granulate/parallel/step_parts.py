"""A distributed run's output step made of what each rank measures of its own grains, with no
node array on rank 0 (writers/step_data.py's StepData without a simulation): the history row,
the particle, fragment and contact tables, and a frame in pieces (each rank writes its own).

Each rank sends rank 0 (StepPart):
- its nodes' sums (step_totals.StepTotals: the energies, the damaged volume, the tracked bodies
  it owns), exact, so that rank 0's totals are the serial run's correctly rounded sums;
- the fragment table of its grains' pieces (fragments.fragment_table over its nodes, labelled by
  their smallest node in the whole run): a piece lies in one grain, and its sums run over its
  nodes run by run (run_sums.py) wherever they are made, so each row is the serial row to the
  bit;
- per grain its motion (particle_table.motion), volume and volume-weighted damage, summed over
  its nodes run by run (run_sums.py) as the serial Analysis sums them;
- what the last force evaluation left of its grains (whole_state.OwnEvaluation, as for the
  whole state).
Rank 0 puts the fragment rows in the serial order (by id), the grains' rows in grain order, the
contacts in the serial slot order, and completes the particle table from them
(analysis.complete_particle_table): every column is the serial run's.

A frame of every node (output without pieces) is made of the ranks' rows of their own nodes,
joined on rank 0 (DistributedRun.step_data). A writer that may read the simulation
(writers/base.py) and the end of a run (unless run(gather=False)) still take the whole state
on rank 0 (DistributedRun.collect). A body cut at node level makes its output steps of its
ranks' nodes (NodeSplitRun.step_data)."""

from __future__ import annotations

import functools
import operator
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from granulate import fragments, particle_table
from granulate.parallel.whole_state import OwnEvaluation, merged_evaluation, own_grain_places
from granulate.step_totals import StepTotals, TrackedSums, node_totals
from granulate.writers.step_data import StepData

if TYPE_CHECKING:
    from granulate.parallel.engine import DistributedRun
    from granulate.simulation import Simulation
    from granulate.writers.vtu_frame import NodeRows


@dataclass(frozen=True)
class StepPart:
    """What one rank sends rank 0 for an output step (the module docstring)."""

    totals: StepTotals
    fragments: fragments.Table
    grains: NDArray[np.int64]  #: the grains it owns, sorted
    motion: particle_table.Table  #: per owned grain
    volumes: NDArray[np.float64]  #: per owned grain [m^3; m^2 in 2D]
    damage: NDArray[np.float64]  #: per owned grain, volume-weighted
    evaluation: OwnEvaluation


def step_part(run: DistributedRun, tracked: tuple[int, ...]) -> StepPart:
    """This rank's StepPart, with the sums of the `tracked` grains it owns (others' empty). Its
    fragment rows label each piece by its smallest node in the whole run's numbering: the part
    numbers a grain's nodes in the whole run's order, so that node is the piece's smallest here
    too."""
    local, nodes = run.local, run.owned_nodes
    core, model = local.core, local.model
    volumes = np.asarray(model.volumes)[nodes]
    density = np.asarray(model.node_density)[nodes]
    mass = density * volumes
    phi = local.analysis.damage_phi()[nodes]  # kept until a bond state changes
    energy = np.asarray(core.strain_energy_density())[nodes]
    x, v = core.positions[nodes], core.velocities[nodes]
    evaluation = OwnEvaluation.of(run)
    totals = node_totals(mass, volumes, v, x, local.gravity, energy, phi)
    sums = tuple(_tracked_sums(run, grain) for grain in tracked)
    grain, count = own_grain_places(run), len(run.owned)
    numbers = run.global_nodes(nodes)
    labels = run.global_nodes(local.analysis.fragment_labels()[nodes])
    pieces = fragments.fragment_table(
        labels, numbers, run.owned[grain], x, v, volumes, density, local.dimension
    )
    grain_volumes, damage = particle_table.volumes(grain, numbers, volumes, phi, count)
    return StepPart(
        replace(totals, contact=evaluation.contact_energy, tracked=sums),
        pieces,
        run.owned,
        particle_table.motion(grain, numbers, mass, volumes, x, v, count),
        grain_volumes,
        damage,
        evaluation,
    )


def step_data(
    sim: Simulation,
    run: DistributedRun,
    parts: list[StepPart],
    broken: int,
    wall_reactions: NDArray[np.float64],
    frame_rows: NodeRows | None = None,
) -> StepData:
    """Rank 0: the output step of `sim` (its set-up: walls, gravity, bodies) from every rank's
    part, with `broken` bonds in all, the walls' reactions and the rows of a frame of every
    node (`frame_rows`, when one is due)."""
    core, grains = run.local.core, len(sim.bodies)
    totals = functools.reduce(operator.add, (part.totals for part in parts))
    table = _merged_fragments([part.fragments for part in parts])
    motion: particle_table.Table = {}
    volumes, damage = np.empty(grains), np.empty(grains)
    for part in parts:
        for column, values in part.motion.items():
            motion.setdefault(column, np.empty(grains))[part.grains] = values
        volumes[part.grains] = part.volumes
        damage[part.grains] = part.damage
    evaluation = merged_evaluation([part.evaluation for part in parts], wall_reactions)
    sums = (totals, broken, table, evaluation)
    return StepData.of_measures(sim, core, sums, (motion, volumes, damage), frame_rows)


def _tracked_sums(run: DistributedRun, grain: int) -> TrackedSums:
    """The sums of a tracked grain's nodes on the rank that owns it; empty elsewhere."""
    if not np.isin(grain, run.owned):
        return TrackedSums()
    local, nodes = run.local, run.local_slice(grain)
    model, core = local.model, local.core
    volumes = np.asarray(model.volumes)[nodes]
    return TrackedSums.of(
        np.asarray(model.node_density)[nodes] * volumes,
        volumes,
        core.forces[nodes],
        core.positions[nodes],
        np.asarray(model.reference_positions)[nodes],
    )


def _merged_fragments(tables: list[fragments.Table]) -> fragments.Table:
    """The ranks' fragment rows as one table in the serial order (by fragment id)."""
    merged = {column: np.concatenate([t[column] for t in tables]) for column in tables[0]}
    order = np.argsort(merged["fragment"], kind="stable")
    return {column: values[order] for column, values in merged.items()}
