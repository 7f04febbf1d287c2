"""One simulation stepped on the ranks of an MPI communicator, whole grains per rank
(DESIGN.md section 7, docs/parallel.md).

Each rank holds the grains it owns and, as ghosts, the grains of other ranks whose bounding
spheres come within the contact lists' cutoff plus a margin of its own (partition.py), in the
serial order, at the serial run's time step and neighbour skin. It steps them all; after each
step the owners send their grains' positions, velocities and forces to the ranks that hold them
as ghosts, which overwrite their own copies. An owned grain's next step then needs only its
partners' exact state, which it has (tests/test_locality.py): the owned grains move bit for bit
as in the serial run, for any number of ranks (tests/test_mpi.py).

What is not built yet: grains do not migrate and the partition is not rebalanced. The ghost
sets hold while no node has moved more than half the margin from where it was at the start,
since then no pair left out can come within the cutoff; the run checks that every step and
raises an InputError naming the step once a node has, rather than continue with a wrong
answer. Outputs, stop criteria, checkpoints and wall reactions across ranks are not built
either: the state is gathered on one rank with `gather`.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from granulate.errors import InputError
from granulate.parallel.partition import Partition, bisect, ghosts, near_pairs

if TYPE_CHECKING:
    from granulate.simulation import Simulation

_TAG = 17


class DistributedRun:
    """`sim` (set up, not built) stepped on the ranks of `comm` (an mpi4py communicator).

    ``margin`` [m]: how much farther than the contact lists' cutoff a ghost is taken, so that
    the partition holds while every node stays within margin/2 of its start; default the
    largest grain's bounding radius. Every rank calls the constructor and each method
    together.
    """

    def __init__(self, sim: Simulation, comm: Any, margin: float | None = None) -> None:
        from mpi4py import MPI

        self._mpi = MPI
        self.comm = comm
        rank, size = comm.Get_rank(), comm.Get_size()
        centres, radii = _bounding_spheres(sim)
        counts = np.array([body.node_count for body in sim.bodies], dtype=float)
        self.partition: Partition = bisect(centres, counts, size)
        owned = self.partition.grains_of(rank)
        probe = sim._subdomain(owned)[0].core  # the cutoff, skin and dt of the owned grains
        skin = comm.allreduce(probe.contact_skin, op=MPI.MAX)
        cutoff = comm.allreduce(probe.contact_reach - probe.contact_skin, op=MPI.MAX) + skin
        dt = comm.allreduce(probe.time_step, op=MPI.MIN)
        self.margin = float(radii.max() if margin is None else margin)
        pairs = near_pairs(centres, radii, cutoff + self.margin)
        self.ghosts = ghosts(self.partition, pairs)
        held = np.union1d(owned, self.ghosts[rank])
        self.local, node_map = sim._subdomain(held, dt=dt, skin=skin)
        self._plan(sim, node_map, owned)
        self.local.core.run(0)  # the first forces, then the owners' values for the ghosts
        self._exchange()
        self._start = self.local.core.positions.copy()  # every node held: ghosts are exact
        self._moved = np.empty_like(self._start)
        #: Wall-clock seconds of this rank in its steps, ghost exchanges and partition checks.
        self.seconds = {"steps": 0.0, "exchange": 0.0, "check": 0.0}

    def _plan(self, sim: Simulation, node_map: NDArray[np.int64], owned: NDArray[np.int64]) -> None:
        """Which local nodes go to which rank and come from which, in grain order, with the
        message buffers (9 numbers a node: x, v, f), made once."""
        rank = self.comm.Get_rank()
        owner = self.partition.owner
        self._slices = [body.node_slice for body in sim.bodies]  # each grain's global nodes
        self._node_count = sim._assembly.node_count
        self._owned = owned
        self._owned_nodes = self._nodes_of(owned, node_map)
        self._send = {
            q: self._nodes_of(held[owner[held] == rank], node_map)
            for q, held in enumerate(self.ghosts)
            if q != rank and np.any(owner[held] == rank)
        }
        mine = self.ghosts[rank]
        self._receive = {
            int(q): self._nodes_of(mine[owner[mine] == q], node_map) for q in np.unique(owner[mine])
        }
        self._outbox = {q: np.empty((len(n), 9)) for q, n in self._send.items()}
        self._inbox = {q: np.empty((len(n), 9)) for q, n in self._receive.items()}

    def _nodes_of(
        self, grains: NDArray[np.int64], node_map: NDArray[np.int64] | None = None
    ) -> NDArray[np.int64]:
        """The global indices of the nodes of `grains` in grain order; their local indices
        when `node_map` (global to local) is given."""
        nodes = [np.arange(self._slices[g].start, self._slices[g].stop) for g in grains]
        index = np.concatenate(nodes) if nodes else np.zeros(0, dtype=np.int64)
        return index if node_map is None else node_map[index]

    @property
    def owned_node_count(self) -> int:
        """The nodes of the grains this rank owns."""
        return len(self._owned_nodes)

    @property
    def ghost_node_count(self) -> int:
        """The nodes of the other ranks' grains this rank holds as ghosts."""
        return self.local._assembly.node_count - len(self._owned_nodes)

    def _exchange(self) -> None:
        """Owners' positions, velocities and forces to the ranks that hold their grains as
        ghosts (one message per pair of neighbouring ranks)."""
        core = self.local.core
        x, v, f = core.positions, core.velocities, core.forces
        requests = [self.comm.Irecv(box, source=q, tag=_TAG) for q, box in self._inbox.items()]
        for q, nodes in self._send.items():
            box = self._outbox[q]
            box[:, :3], box[:, 3:6], box[:, 6:] = x[nodes], v[nodes], f[nodes]
            requests.append(self.comm.Isend(box, dest=q, tag=_TAG))
        self._mpi.Request.Waitall(requests)
        for q, nodes in self._receive.items():
            box = self._inbox[q]
            x[nodes], v[nodes], f[nodes] = box[:, :3], box[:, 3:6], box[:, 6:]

    def run(self, steps: int) -> None:
        """Advance every rank `steps` time steps. Raises InputError (on every rank) when a
        node has moved more than half the margin: the ghosts would no longer be enough. An
        error in one rank's step ends every rank: that rank raises its own, the others a
        RuntimeError naming it (no rank is left waiting for a message)."""
        core = self.local.core
        for _ in range(steps):
            start = time.perf_counter()
            failure = None
            try:
                core.run(1)
            except Exception as error:  # re-raised below, after the ranks agree to stop
                failure = error
            stepped = time.perf_counter()
            self._check_step(int(core.step), failure)
            checked = time.perf_counter()
            self._exchange()
            self.seconds["steps"] += stepped - start
            self.seconds["check"] += checked - stepped
            self.seconds["exchange"] += time.perf_counter() - checked

    def _check_step(self, step: int, failure: Exception | None) -> None:
        """One reduction after each step, before the exchange: the first rank whose step
        failed, and the largest distance of a node from its start (the ghosts' positions are
        already exact here: they drifted from exact values). Stops every rank on either."""
        moved = np.subtract(self.local.core.positions, self._start, out=self._moved)
        farthest = float(np.sqrt(np.einsum("ij,ij->i", moved, moved).max(initial=0.0)))
        size = self.comm.Get_size()
        failed_rank = self.comm.Get_rank() if failure is not None else size
        mine = np.array([failed_rank, -farthest])  # elementwise minima: both in one reduction
        least = np.empty(2)
        self.comm.Allreduce(mine, least, op=self._mpi.MIN)
        first_failed, farthest = int(least[0]), float(least[1])
        if failure is not None:
            raise failure
        if first_failed < size:
            raise RuntimeError(f"step {step}: rank {first_failed} failed; every rank stops")
        if -farthest > 0.5 * self.margin:
            raise InputError(
                f"step {step}: a node moved {-farthest:.3g} m from its start, more than "
                f"half the ghost margin ({self.margin:.3g} m); grains do not migrate between "
                "ranks yet, so give DistributedRun a larger margin or run on one process"
            )

    @property
    def dt(self) -> float:
        """The time step [s], the same on every rank: the serial run's."""
        return float(self.local.core.time_step)

    def gather(self, field: str, root: int = 0) -> NDArray[np.float64] | None:
        """The (nodes, 3) array `field` ("positions", "velocities" or "forces") of the whole
        assembly in the serial node order, on rank `root` (None on the others)."""
        if field not in ("positions", "velocities", "forces"):
            raise ValueError(f"gather: field must be positions, velocities or forces: {field!r}")
        mine = getattr(self.local.core, field)[self._owned_nodes]
        parts = self.comm.gather((self._owned, mine), root=root)
        if parts is None:
            return None
        whole = np.empty((self._node_count, 3))
        for grains, values in parts:
            whole[self._nodes_of(grains)] = values
        return whole


def _bounding_spheres(sim: Simulation) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Per grain, the centre of its nodes' box and the radius of the sphere about it that
    holds them, at the start (its start state when one is set) [m]."""
    start = sim._start[0] if sim._start is not None else sim._assembly.reference_positions()
    centres, radii = [], []
    for body in sim.bodies:
        nodes = start[body.node_slice]
        centre = 0.5 * (nodes.min(axis=0) + nodes.max(axis=0))
        centres.append(centre[: sim.dimension])
        radii.append(float(np.linalg.norm(nodes - centre, axis=1).max()))
    return np.array(centres), np.array(radii)
