"""What the stop criteria read of a distributed run (stopping.RunMeasures), on every rank, from
each rank's own nodes and one reduction per measure: no rank sends rank 0 its nodes for them.

Each is the serial run's to the bit, however the nodes are dealt:
- the kinetic energy is a correctly rounded sum (granulate.exact_sum): each rank's exact partial
  sum of its nodes' 1/2 m |v|^2, added exactly;
- the farthest node's distance is a maximum;
- the broken bonds and the particles that lost every bond are counts, each bond copy read on the
  rank that evaluates it (an own node's);
- the time and the walls' displacements are every rank's.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from granulate.analysis import kinetic_energies, squared_distances
from granulate.exact_sum import ExactSum

if TYPE_CHECKING:
    from granulate.simulation import Simulation


class RankMeasures:
    """stopping.RunMeasures of the run whose rank holds `local` (a built part) and evaluates its
    nodes `own` (local indices); `bodies`: the whole run's index of each of the part's bodies;
    `broken_bonds`: the run's count (every rank together). Every rank calls each method
    together; each returns the same value on every rank."""

    def __init__(
        self,
        comm: Any,
        local: Simulation,
        own: NDArray[np.int64],
        bodies: NDArray[np.int64],
        broken_bonds: Callable[[], int],
    ) -> None:
        from mpi4py import MPI

        self.mpi, self.comm, self.local, self.own = MPI, comm, local, own
        self.bodies, self.broken_bonds = bodies, broken_bonds

    @property
    def time(self) -> float:
        return float(self.local.core.time)

    def kinetic_energy(self) -> float:
        """sum 1/2 m |v|^2 [J; J/m in 2D] of every node, correctly rounded."""
        model, own = self.local.model, self.own
        mass = (np.asarray(model.node_density) * np.asarray(model.volumes))[own]
        mine = ExactSum.of(kinetic_energies(mass, self.local.core.velocities[own]))
        return self.comm.allreduce(mine, op=self.mpi.SUM).value  # type: ignore[no-any-return]

    def farthest_node_distance(self) -> float:
        """The largest distance of any node from the origin [m]."""
        mine = float(np.max(squared_distances(self.local.core.positions[self.own]), initial=0.0))
        return float(np.sqrt(self.comm.allreduce(mine, op=self.mpi.MAX)))

    def wall_displacement(self, name: str) -> float:
        return self.local.wall_displacement(name)

    def fully_broken_particles(self) -> int:
        """Bodies with at least one bond and none intact. A body whose nodes are all this
        rank's is counted here; one cut among ranks, from every rank's counts of its bonds."""
        model = self.local.model
        body_of = np.asarray(model.node_particle)[self.own]
        count = len(self.bodies)
        copies, intact = _bond_copies(model, self.local.core, self.own)
        copies, intact = (np.bincount(body_of, weights, count) for weights in (copies, intact))
        mine = np.bincount(body_of, minlength=count)
        whole = mine == np.bincount(np.asarray(model.node_particle), minlength=count)
        here = int(np.count_nonzero(whole & (copies > 0) & (intact == 0)))
        cut = (mine > 0) & ~whole
        shared = self.comm.allgather((self.bodies[cut], copies[cut], intact[cut]))
        return int(self.comm.allreduce(here, op=self.mpi.SUM)) + _fully_broken_of(shared)


def _bond_copies(
    model: Any, core: Any, nodes: NDArray[np.int64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Per node of `nodes`: its bond copies and the intact ones among them."""
    offsets = np.asarray(model.bond_offsets, dtype=np.int64)
    intact = np.asarray(core.intact_bond_copies(np.ascontiguousarray(nodes, dtype=np.int64)))
    return (offsets[nodes + 1] - offsets[nodes]).astype(np.float64), intact.astype(np.float64)


def _fully_broken_of(shared: list[tuple[NDArray[Any], ...]]) -> int:
    """Of the bodies cut among ranks (each rank's bodies, bond copies and intact copies of
    them), those with copies and none intact."""
    bodies = np.concatenate([part[0] for part in shared]).astype(np.int64)
    if len(bodies) == 0:
        return 0
    unique, index = np.unique(bodies, return_inverse=True)
    copies, intact = (
        np.bincount(index, np.concatenate([part[k] for part in shared]), len(unique))
        for k in (1, 2)
    )
    return int(np.count_nonzero((copies > 0) & (intact == 0)))
