"""Bodies cut at node level across the ranks of an MPI communicator (issue 17, docs/parallel.md):
single-body fracture on many processes, bit for bit the serial run.

The nodes are dealt by recursive coordinate bisection (partition.bisect over the nodes, each
weighted by its bonds plus one), so a body larger than a subdomain is cut wherever the cuts
fall and its bonds cross ranks. Each rank evaluates its own nodes (core.set_foreign_nodes) and
holds, of the others, its halo: the nodes bonded to its own, one horizon deep. A step exchanges
twice with each neighbouring rank: the halo's positions after the drift (core.move), then, for
LPS, the halo's dilatation sums after the bonds' stretch and breaking (core.begin_step), before
the forces (core.finish_step). The core evaluates of a halo node only its bonds to own nodes,
so every own node sums the serial run's terms in the serial order and a bond across a cut
breaks alike on both sides (tests/test_node_split.py in one process, tests/test_mpi.py on 2 and
3 ranks).

Every rank holds the whole model, as a distributed run's ranks do (engine.py). Contact is not
split yet (a body's rigid motion, which contact reads, would be a sum across ranks): the model
must run without contact, walls or PeriDEM's damping (core.set_foreign_nodes refuses them).
Outputs, checkpoints and Simulation(comm=...) do not run through it yet: `gather` gives rank 0
a field of every node.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
from numpy.typing import NDArray

from granulate.errors import InputError
from granulate.parallel.agreement import RankFailed
from granulate.parallel.partition import bisect

_TAG = 23


class NodeSplitRun:
    """`sim` (built alike on every rank of `comm`) stepped with its nodes dealt to the ranks.

    owner: each node's rank; seconds: "steps" (the core's halves) and "exchange" (the halos'
    messages, waits included) [s]; halo_nodes: the nodes this rank receives a step.
    """

    def __init__(self, sim: Any, comm: Any) -> None:
        from mpi4py import MPI

        self.comm, self.mpi = comm, MPI
        self.core, model = sim.core, sim.model
        if comm.Get_size() > sim.node_count:
            raise InputError(
                f"{comm.Get_size()} ranks for {sim.node_count} nodes: run on at most as many "
                "ranks as nodes"
            )
        self.core.run(0)  # the first evaluation, before the nodes are dealt (its breaks too)
        bonds = np.diff(np.asarray(model.bond_offsets, dtype=np.int64))
        points = np.asarray(sim.reference_positions)[:, : sim.dimension]
        self.owner = bisect(points, bonds + 1.0, comm.Get_size()).owner
        rank = comm.Get_rank()
        self.own = np.flatnonzero(self.owner == rank)
        self.core.set_foreign_nodes(np.flatnonzero(self.owner != rank).tolist())
        self._receive, self._send = _halos(model, self.owner, self.own, rank)
        self._lps = any(body.material.model == "lps" for body in sim.bodies)  # reads θ_j
        self.halo_nodes = sum(len(nodes) for nodes in self._receive.values())
        self.seconds = {"steps": 0.0, "exchange": 0.0}

    def run(self, steps: int) -> None:
        """Advance every rank `steps` steps. An error in one rank's step (an instability) ends
        every rank after that step: that rank raises its own, the others RankFailed."""
        for _ in range(steps):
            self._step()

    def _step(self) -> None:
        core = self.core
        failure: Exception | None = None
        start = time.perf_counter()
        try:
            core.move()
        except Exception as error:  # raised after the step's exchanges, once all agree
            failure = error
        moved = time.perf_counter()
        self._exchange(core.positions)
        exchanged = time.perf_counter()
        if failure is None:
            try:
                core.begin_step()
            except Exception as error:
                failure = error
        began = time.perf_counter()
        if self._lps:
            self._exchange(core.dilatation)
        told = time.perf_counter()
        if failure is None:
            try:
                core.finish_step(np.zeros((0, 2), np.uint32))
            except Exception as error:
                failure = error
        stepped = time.perf_counter()
        self._agree(failure)
        self.seconds["steps"] += (moved - start) + (began - exchanged) + (stepped - told)
        self.seconds["exchange"] += (
            (exchanged - moved) + (told - began) + (time.perf_counter() - stepped)
        )

    def _exchange(self, field: NDArray[np.float64]) -> None:
        """The halo's rows of `field` (positions, n x 3, or dilatation sums, n) from their
        owners: one message each way per neighbouring rank."""
        width = 1 if field.ndim == 1 else field.shape[1]
        inbox = {q: np.empty((len(nodes), width)) for q, nodes in self._receive.items()}
        requests = [self.comm.Irecv(box, source=q, tag=_TAG) for q, box in inbox.items()]
        for q, nodes in self._send.items():
            box = np.ascontiguousarray(field[nodes]).reshape(len(nodes), width)
            requests.append(self.comm.Isend(box, dest=q, tag=_TAG))
        self.mpi.Request.Waitall(requests)
        for q, nodes in self._receive.items():
            field[nodes] = inbox[q].reshape(field[nodes].shape)

    def _agree(self, failure: Exception | None) -> None:
        """One reduction: the first rank whose step failed; it raises its error, the others
        RankFailed."""
        size = self.comm.Get_size()
        mine = self.comm.Get_rank() if failure is not None else size
        first = self.comm.allreduce(mine, op=self.mpi.MIN)
        if failure is not None:
            raise failure
        if first < size:
            raise RankFailed(f"rank {first} failed in step {int(self.core.step)}; every rank stops")

    def gather(self, field: str, root: int = 0) -> NDArray[np.float64] | None:
        """core.<field> (positions, velocities, forces, dilatation) of every node on `root`,
        each row from its owner; None on the other ranks."""
        mine = np.ascontiguousarray(np.asarray(getattr(self.core, field))[self.own])
        parts = self.comm.gather(mine, root=root)
        if parts is None:
            return None
        whole = np.empty((len(self.owner), *mine.shape[1:]))
        for q, part in enumerate(parts):
            whole[self.owner == q] = part
        return whole

    def broken_bonds(self) -> int:
        """The bonds broken on every rank, each counted once (by the owner of its lower end)."""
        return int(self.comm.allreduce(int(self.core.broken_bonds()), op=self.mpi.SUM))


def _halos(
    model: Any, owner: NDArray[np.int64], own: NDArray[np.int64], rank: int
) -> tuple[dict[int, NDArray[np.int64]], dict[int, NDArray[np.int64]]]:
    """Per neighbouring rank q: the nodes of q bonded to own nodes (received from q), and the
    own nodes bonded to q's (sent to q), each sorted: what q receives from this rank is its own
    list of this rank's nodes, computed alike there."""
    partners = np.asarray(model.bond_partners(own.tolist()), dtype=np.int64)
    halo = partners[owner[partners] != rank]
    receive, send = {}, {}
    for q in np.unique(owner[halo]).tolist():
        theirs = halo[owner[halo] == q]
        receive[q] = theirs
        reached = np.asarray(model.bond_partners(theirs.tolist()), dtype=np.int64)
        send[q] = reached[owner[reached] == rank]
    return receive, send
