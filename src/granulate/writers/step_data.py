"""What every writer of one output step reads, computed once for the frame and the history row
of that step: from a simulation's whole state (StepData.of), or in a distributed run from what
its ranks measured of their own grains (parallel/step_parts.py), with no node array but, for a
frame of every node, the ranks' rows of it."""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from granulate import fragments, network, particle_table
from granulate.analysis import complete_particle_table
from granulate.evaluation import Evaluation
from granulate.exact_sum import ExactSum
from granulate.step_totals import StepTotals, TrackedSums, node_totals

if TYPE_CHECKING:
    from granulate.assembly import Body
    from granulate.simulation import Simulation
    from granulate.walls import Wall
    from granulate.writers.vtu_frame import NodeRows


@dataclass(frozen=True)
class StepData:
    """The current step: its time, sums over the nodes (StepTotals), broken bonds, fragment
    table, the last force evaluation (contacts, contact counts, wall reactions), the particles
    and the walls' displacements; and, when made of the whole state, the simulation (for
    writers that read it)."""

    step: int
    time: float  #: [s]
    totals: StepTotals
    broken_bonds: int
    fragments: fragments.Table
    evaluation: Evaluation
    particles: particle_table.Table
    #: the particles' Love-Weber stresses (N, D, D) [Pa] and volumes [m^3; m^2 in 2D]
    stresses: tuple[NDArray[np.float64], NDArray[np.float64]]
    walls: tuple[tuple[str, Wall], ...]  #: the walls' names and set-ups, in order
    wall_displacements: tuple[float, ...]  #: [m or rad], in the walls' order
    gravity: NDArray[np.float64]  #: (3,) [m/s^2]
    dimension: int
    #: the whole simulation; None when made of the ranks' measures (a frame in pieces, written
    #: by the ranks)
    simulation: Simulation | None = None
    #: when made of the ranks' measures for a frame of every node: the ranks' rows of it,
    #: joined in node order (Outputs.one_file_frame)
    frame_rows: NodeRows | None = None

    @property
    def contacts(self) -> network.Table:
        return self.evaluation.contacts

    @property
    def mean_damage(self) -> float:
        return self.totals.mean_damage

    @classmethod
    def of(cls, simulation: Simulation, tracked: tuple[Body, ...] = ()) -> StepData:
        """The step of `simulation`'s whole state, with the sums of the `tracked` bodies."""
        sim = simulation
        phi = sim.analysis.damage_phi()
        evaluation = sim.evaluation()
        particles, stresses, volumes = sim.analysis.particles(evaluation.contacts, phi)
        core = sim.core
        return cls(
            int(core.step),
            float(core.time),
            whole_totals(sim, phi, evaluation.contact_energy, tracked),
            int(core.broken_bonds()),
            sim.fragment_table(),
            evaluation,
            particles,
            (stresses, volumes),
            *set_up_fields(sim, core),
            sim,
        )

    @classmethod
    def of_measures(
        cls,
        sim: Simulation,
        core: Any,
        sums: tuple[StepTotals, int, fragments.Table, Evaluation],
        particles: tuple[particle_table.Table, NDArray[np.float64], NDArray[np.float64]],
        frame_rows: NodeRows | None = None,
    ) -> StepData:
        """The step of `sim`'s set-up at `core`'s step and time (a rank's part: its walls) made
        of measures its ranks put together: `sums`, the totals, bonds broken, fragment table
        and evaluation; `particles`, the particles' motion columns, volumes and volume-weighted
        damage, which complete_particle_table completes; the rows of a frame of every node."""
        totals, broken, table, evaluation = sums
        motion, volumes, damage = particles
        time = float(core.time)
        rows, stresses = complete_particle_table(
            motion, volumes, damage, evaluation.contacts, time, sim.dimension
        )
        return cls(
            int(core.step),
            time,
            totals,
            broken,
            table,
            evaluation,
            rows,
            (stresses, volumes),
            *set_up_fields(sim, core),
            frame_rows=frame_rows,
        )


def set_up_fields(sim: Simulation, core: Any) -> tuple[Any, ...]:
    """StepData's walls, wall displacements, gravity and dimension: of `sim`'s set-up, the
    walls displaced to `core`'s time (its walls: the whole core's, or a part's)."""
    return (
        sim.walls,
        tuple(float(wall.displacement(core.time)) for wall in core.walls),
        np.asarray(sim.gravity, dtype=np.float64),
        sim.dimension,
    )


def whole_totals(
    sim: Simulation, damage: NDArray[np.float64], contact: float, tracked: tuple[Body, ...]
) -> StepTotals:
    """StepTotals of every node of `sim` (its strain energy densities and `damage` phi), its
    `contact` energy (Evaluation's, a correctly rounded sum already), with the sums of the
    `tracked` bodies."""
    model, core = sim.model, sim.core
    volumes = np.asarray(model.volumes)
    mass = np.asarray(model.node_density) * volumes
    density = sim.analysis.strain_energy_densities()
    totals = node_totals(
        mass, volumes, core.velocities, core.positions, sim.gravity, density, damage
    )
    sums = tuple(
        TrackedSums.of(
            mass[body.node_slice],
            volumes[body.node_slice],
            core.forces[body.node_slice],
            core.positions[body.node_slice],
            model.reference_positions[body.node_slice],
        )
        for body in tracked
    )
    return replace(totals, contact=ExactSum.of([contact]), tracked=sums)
