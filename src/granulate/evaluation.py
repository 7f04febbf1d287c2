"""What the last force evaluation left besides the nodes' state, for a step's outputs and
measures: the contacts between bodies (granulate.network's table), the normal contact springs'
energy, the node and wall contacts, the neighbour-list searches so far and the walls' reactions.

A serial run reads them from its core. In a distributed run each rank evaluated the forces of
its own grains; rank 0's simulation holds them gathered from the owners in the serial order
(granulate.parallel.whole_state), so that its outputs are the serial run's.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from granulate import network
from granulate.exact_sum import ExactSum


@dataclass(frozen=True)
class Evaluation:
    """The last force evaluation's contacts, energies, counts and wall reactions."""

    contacts: network.Table  #: one row per contact (granulate.network.COLUMNS)
    contact_energy: float  #: the normal springs' energy [J; J/m in 2D], correctly rounded
    node_contacts: int  #: node pairs in contact (each once)
    wall_contacts: int  #: node-wall contacts
    list_rebuilds: int  #: neighbour-list searches so far (distributed: the most of any rank)
    wall_reactions: NDArray[np.float64]  #: (walls, 6) force and torque on each wall [N, N m]

    @classmethod
    def of_core(cls, core: Any, contacts: network.Table) -> Evaluation:
        """A serial simulation's, read from its core, with its contact table (Analysis's)."""
        statistics = core.contact_statistics
        energy = np.asarray(core.node_contact_terms()[0])  # per node
        return cls(
            contacts,
            ExactSum.of(energy).value,
            int(statistics.node_contacts),
            int(statistics.wall_contacts),
            int(statistics.rebuilds),
            np.asarray(core.wall_reactions(), dtype=np.float64).reshape(-1, 6),
        )
