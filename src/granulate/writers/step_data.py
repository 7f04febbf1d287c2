"""What every writer of one output step reads, computed once for the frame and the history row
of that step."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from granulate import fragments, network, particle_table
from granulate.evaluation import Evaluation

if TYPE_CHECKING:
    from granulate.simulation import Simulation


@dataclass(frozen=True)
class StepData:
    """The current step of `simulation`: damage, fragments, the last force evaluation
    (contacts, contact energy and counts, wall reactions) and particles."""

    simulation: Simulation
    damage: NDArray[np.float64]  #: phi per node
    damage_z: NDArray[np.float64]  #: PeriDEM's Damage_Z per node
    fragments: fragments.Table
    evaluation: Evaluation
    contacts: network.Table
    particles: particle_table.Table
    #: the particles' Love-Weber stresses (N, D, D) [Pa] and volumes [m^3; m^2 in 2D]
    stresses: tuple[NDArray[np.float64], NDArray[np.float64]]

    @classmethod
    def of(cls, simulation: Simulation) -> StepData:
        phi, z = simulation.analysis.damage()
        table = simulation.fragment_table()
        evaluation = simulation.evaluation()
        contacts = evaluation.contacts
        particles, stresses, volumes = simulation.analysis.particles(contacts, phi)
        return cls(simulation, phi, z, table, evaluation, contacts, particles, (stresses, volumes))
