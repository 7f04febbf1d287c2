"""Bodies cut at node level across the ranks of an MPI communicator (issue 17, docs/parallel.md):
one body's fracture on many processes, bit for bit the serial run. Simulation(comm=...) runs a
model in which nothing touches (no contact law, wall or PeriDEM damping:
Interactions.contact_free) this way, `mpiexec granulate run case.yaml` included.

The nodes are dealt by recursive coordinate bisection (partition.bisect over the nodes, each
weighted by its bonds plus one), so a body larger than a subdomain is cut wherever the cuts
fall and its bonds cross ranks. Each rank evaluates its own nodes (core.set_foreign_nodes) and
receives, of the others, its halo: the nodes bonded to its own, one horizon deep. A step
exchanges twice with each neighbouring rank: the halo's positions after the drift (core.move),
then, for LPS, the halo's dilatation sums after the bonds' stretch and breaking
(core.begin_step), before the forces (core.finish_step). The core evaluates of a halo node only
its bonds to own nodes, so every own node sums the serial run's terms in the serial order and a
bond across a cut breaks alike on both sides (tests/test_node_split.py in one process,
tests/test_mpi.py on 2 and 3 ranks). The halo is fixed by the bonds, so no node ever needs to
change hands.

Every rank holds the whole model, as a distributed run's ranks do (engine.py). For outputs,
stop criteria and checkpoints rank 0's simulation takes every node's state from its owner
(collect); the measures (damage, fragments, energies) it then makes of the whole state itself.
Contact is not split: a body's rigid motion and fragments, which contact reads, would be sums
across ranks.
"""

from __future__ import annotations

import os
import time
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from granulate import checkpoints, fingerprints
from granulate.errors import InputError
from granulate.evaluation import Evaluation
from granulate.parallel.agreement import attempt, on_root, stop_if_any_failed, together
from granulate.parallel.large_messages import large_message_comm
from granulate.parallel.overlap import while_travelling
from granulate.parallel.partition import bisect
from granulate.parallel.rank_threads import share_of_cores
from granulate.parallel.run_measures import RankMeasures
from granulate.writers.vtu_frame import FIELD_TYPES, point_fields, write_piece_rows

if TYPE_CHECKING:
    from granulate.simulation import Simulation
    from granulate.writers.outputs import Outputs

_TAG = 23
_NODE_FIELDS = ("positions", "velocities", "forces", "dilatation")
_NO_BREAKS = np.zeros((0, 2), np.uint32)  # finish_step's ghost breaks: a split body has none


class NodeSplitRun:
    """`sim` (set up alike on every rank of `comm`, not built) stepped with its nodes dealt to
    the ranks. Every rank calls the constructor and each method together.

    owner: each node's rank; nodes_of: each rank's nodes (own: this rank's); halo_nodes: the
    nodes it receives a step;
    seconds: "steps" (the core's parts of the steps), "exchange" (the halo's messages and the
    step's one reduction, waits included) and "collect" [s].
    """

    def __init__(self, sim: Simulation, comm: Any) -> None:
        from mpi4py import MPI

        self.comm, self.mpi, self._sim = comm, MPI, sim
        self.large = large_message_comm(comm)  # for messages of states (large_messages.py)
        share_of_cores(comm)
        ranks, nodes = comm.Get_size(), sim.node_count
        if ranks > nodes:
            raise InputError(
                f"{ranks} ranks for {nodes} nodes: run on at most as many ranks as nodes"
            )
        every = np.arange(len(sim.bodies))
        self.local: Simulation = together(comm, lambda: _built(sim._subdomain(every)[0]))
        core, model = self.local.core, self.local.model
        #: The stable time-step estimate [s]: the serial run's (every rank holds the model).
        self.stable_dt = float(core.stable_time_step)
        self._offsets = np.asarray(model.bond_offsets, dtype=np.int64)
        points = np.asarray(model.reference_positions)[:, : sim.dimension]
        self.owner = bisect(points, np.diff(self._offsets) + 1.0, ranks).owner
        rank = comm.Get_rank()
        self.nodes_of = [np.flatnonzero(self.owner == q) for q in range(ranks)]
        self.own = self.nodes_of[rank]
        core.set_foreign_nodes(np.flatnonzero(self.owner != rank).tolist())
        self._receive, self._send = _halos(model, self.owner, self.own, rank)
        # The halo's messages in and out, for positions (3 numbers a node) and dilatation sums
        # (1), made once.
        self._inboxes = {
            width: {q: np.empty((len(halo), width)) for q, halo in self._receive.items()}
            for width in (3, 1)
        }
        self._outboxes = {
            shape: {q: np.empty((len(nodes), *shape)) for q, nodes in self._send.items()}
            for shape in ((3,), ())
        }
        self._lps = any(body.material.model == "lps" for body in sim.bodies)  # reads theta_j
        self.halo_nodes = sum(len(halo) for halo in self._receive.values())
        self.seconds = dict.fromkeys(("steps", "exchange", "collect"), 0.0)
        self.waiting = 0.0  # of the exchange's seconds, those waiting for the halo (Waitall)
        self._setup_digest: str | None = None  # of the set-up's fingerprint, made once

    @property
    def dt(self) -> float:
        """The time step [s], the serial run's."""
        return float(self.local.core.time_step)

    @property
    def bond_count(self) -> int:
        """Every bond, counted once per end (Simulation.bond_count)."""
        return int(self._offsets[-1])

    def run(self, steps: int) -> None:
        """Advance every rank `steps` steps. An error in one rank's step (an instability) ends
        every rank after that step: that rank raises its own, the others RankFailed."""
        self._sim._ranks_ahead |= steps > 0  # rank 0's simulation until it takes the state
        for _ in range(steps):
            self._step()

    def _step(self) -> None:
        """One step: the kick and drift; the halo's positions, while pass 1 of the inner bond
        blocks runs (core.evaluate_dilatation); the rest of pass 1 (core.begin_step); for LPS
        the halo's dilatation sums, while pass 2 of the inner blocks runs (core.evaluate_bonds);
        the rest of the step; and the reduction that agrees on failures. Every rank goes
        through every exchange whatever failed."""
        core = self.local.core
        start, exchanged = time.perf_counter(), self.seconds["exchange"]
        failure = attempt(core.move)
        failure = self._exchange(core.positions, core.evaluate_dilatation, failure)
        failure = attempt(core.begin_step, failure)
        if self._lps:
            failure = self._exchange(core.dilatation, core.evaluate_bonds, failure)
        failure = attempt(lambda: core.finish_step(_NO_BREAKS), failure)
        reducing = time.perf_counter()
        stop_if_any_failed(self.comm, failure, f"taking step {int(core.step) + 1}")
        end = time.perf_counter()
        self.seconds["exchange"] += end - reducing
        self.seconds["steps"] += end - start - (self.seconds["exchange"] - exchanged)

    def _exchange(
        self, field: NDArray[np.float64], inner: Any, failure: Exception | None
    ) -> Exception | None:
        """The halo's rows of `field` (positions, n x 3, or dilatation sums, n) from their
        owners, one message each way per neighbouring rank, while `inner` (core.
        evaluate_dilatation or evaluate_bonds: the inner blocks, which read nothing of them)
        runs (overlap.while_travelling). The step's failure so far, or `inner`'s."""
        start = time.perf_counter()
        width = 1 if field.ndim == 1 else field.shape[1]
        inbox = self._inboxes[width]
        requests = [self.comm.Irecv(box, source=q, tag=_TAG) for q, box in inbox.items()]
        outbox = self._outboxes[field.shape[1:]]
        for q, nodes in self._send.items():
            np.take(field, nodes, axis=0, out=outbox[q])
        requests += [self.comm.Isend(box, dest=q, tag=_TAG) for q, box in outbox.items()]
        posted = time.perf_counter()
        failure, testing = while_travelling(self.mpi, requests, inner, failure)
        waiting = time.perf_counter()
        self.mpi.Request.Waitall(requests)
        self.waiting += time.perf_counter() - waiting
        for q, halo in self._receive.items():
            field[halo] = inbox[q][:, 0] if field.ndim == 1 else inbox[q]
        self.seconds["exchange"] += posted - start + testing + time.perf_counter() - waiting
        return failure

    def gather(self, field: str, root: int = 0) -> NDArray[np.float64] | None:
        """core.<field> (positions, velocities, forces or dilatation) of every node on `root`,
        each row from its owner; None on the other ranks."""
        if field not in _NODE_FIELDS:
            raise ValueError(f"gather: field must be one of {', '.join(_NODE_FIELDS)}: {field!r}")
        mine = np.asarray(getattr(self.local.core, field))[self.own]
        parts = self.large.gather(mine, root=root)
        if parts is None:
            return None
        whole = np.empty((len(self.owner), *mine.shape[1:]))
        for nodes, part in zip(self.nodes_of, parts, strict=True):
            whole[nodes] = part
        return whole

    def broken_bonds(self) -> int:
        """The bonds broken on every rank, each counted once (by the owner of its lower end),
        on every rank."""
        return int(self.comm.allreduce(int(self.local.core.broken_bonds()), op=self.mpi.SUM))

    def measures(self) -> RankMeasures:
        """What the stop criteria read (stopping.RunMeasures), from each rank's own nodes."""
        every = np.arange(len(self._sim.bodies))
        return RankMeasures(self.comm, self.local, self.own, every, self.broken_bonds)

    def deepest_contact(self) -> SimpleNamespace:
        """No contact: nothing overlaps (the contact statistics' names, for the run's check)."""
        return SimpleNamespace(deepest_overlap=0.0, half_overlap_step=0, full_overlap_step=0)

    def collect(self, measures: bool = True) -> None:
        """Rank 0's simulation (built whole on the first call) takes every node's position,
        velocity, force, dilatation and bond states from its owner, the step and time, and an
        evaluation with no contacts (the most list searches of any rank): its outputs, measures
        and stop criteria are then the serial run's at this step, which it measures itself
        (`measures` is for the interface: nothing is measured elsewhere). An error on rank 0
        (its whole simulation too large for its memory, say) ends every rank: InputError with
        the same message, else rank 0's error and RankFailed."""
        start = time.perf_counter()
        core = self.local.core
        intact = np.asarray(core.bond_intact)[_copies_of(self._offsets, self.own)]
        mine = (*(np.asarray(getattr(core, f))[self.own] for f in _NODE_FIELDS), intact)
        parts = self.large.gather(mine, root=0)
        searches = self.comm.reduce(int(core.contact_statistics.rebuilds), op=self.mpi.MAX, root=0)
        moment = (float(core.time), int(core.step))
        on_root(self.comm, lambda: self._install(parts, moment, int(searches)))
        self.seconds["collect"] += time.perf_counter() - start

    def _install(
        self, parts: list[tuple[NDArray[Any], ...]], moment: tuple[float, int], searches: int
    ) -> None:
        """Rank 0: every rank's nodes (`parts`, in rank order) into its whole simulation."""
        sim = self._sim
        sim._ranks_ahead = False  # it takes the ranks' state now
        core = sim._build()
        bonds = np.empty(self._offsets[-1], dtype=np.uint8)
        for nodes, part in zip(self.nodes_of, parts, strict=True):
            for field, values in zip(_NODE_FIELDS, part[:-1], strict=True):
                getattr(core, field)[nodes] = values
            bonds[_copies_of(self._offsets, nodes)] = part[-1]
        core.assign_bonds(bonds)
        core.time, core.step = moment
        sim.analysis.give(None)
        sim._gathered = replace(
            Evaluation.of_core(core, sim.analysis.contact_table()), list_rebuilds=searches
        )

    def fingerprint(self) -> str:
        """The set-up's fingerprint (Simulation.fingerprint), on every rank from the whole
        model it holds (no message)."""
        if self._setup_digest is None:
            self._setup_digest = fingerprints.whole_model_digest(self._sim, self.local.model)
        return fingerprints.fingerprint(self._sim, self._setup_digest, self.dt)

    def save_checkpoint(self, path: str | os.PathLike[str], outputs: Outputs | None = None) -> Path:
        """The serial run's checkpoint (granulate.checkpoints, with `outputs`' bookkeeping),
        written by rank 0 from the whole state (collect); it restarts on any number of ranks,
        or serially, bit for bit. Rank 0 raises a failure to write, the others RankFailed. The
        path written, on every rank."""
        self.collect(measures=False)

        def write() -> Path:
            self._sim.analysis.forget_fragments()
            return checkpoints.save(self._sim, path, outputs, self.fingerprint())

        return Path(self.comm.bcast(on_root(self.comm, write), root=0))

    def load_checkpoint(self, path: str | os.PathLike[str], outputs: Outputs | None = None) -> None:
        """Continue from a checkpoint of this set-up written by a run on any number of ranks,
        or serially (else InputError on every rank): rank 0 reads it into its simulation (with
        `outputs`' bookkeeping) and every rank restores the whole state from it."""

        def read() -> dict[str, Any]:
            self._sim._ranks_ahead = False  # it reads the whole state itself
            checkpoints.load(self._sim, path, outputs, self.fingerprint())
            self._sim._gathered = None  # the evaluation gathered before is not the checkpoint's
            return dict(self._sim.core.checkpoint())

        start = time.perf_counter()
        state = self.large.bcast(on_root(self.comm, read), root=0)
        together(self.comm, lambda: self.local.core.restore(state), "restoring the checkpoint")
        self.seconds["collect"] += time.perf_counter() - start

    def write_piece(self, folder: Path, fields: tuple[str, ...]) -> None:
        """This rank's piece of a frame in pieces (writers/vtu_frame.py): its own nodes now,
        with `fields`, as folder/piece_<rank>.vtu. The fragment labels come from rank 0, which
        holds every bond (collect): a rank's own bonds do not tell which piece a node is in."""
        labels = None
        if "Fragment_ID" in fields:
            whole = on_root(self.comm, lambda: self._sim.analysis.fragment_labels())
            mine = None if whole is None else [whole[nodes] for nodes in self.nodes_of]
            labels = self.large.scatter(mine, root=0)
        local = [f for f in fields if f != "Fragment_ID"]
        values = point_fields(self.local, tuple(local))
        rows = {name: field[self.own] for name, field in values.items()}
        if labels is not None:
            rows["Fragment_ID"] = labels
        path = Path(folder) / f"piece_{self.comm.Get_rank()}.vtu"
        ordered = {f: rows[f].astype(FIELD_TYPES[f][0]) for f in fields}
        write_piece_rows(path, self.local.core.positions[self.own], ordered, self.own)


def _built(part: Simulation) -> Simulation:
    """`part` with its core built and its first forces evaluated (before the nodes are dealt:
    that evaluation breaks bonds everywhere alike)."""
    part.core.run(0)
    return part


def _copies_of(offsets: NDArray[np.int64], nodes: NDArray[np.int64]) -> NDArray[np.int64]:
    """The bond copies of `nodes` (their places in core.bond_intact), node after node."""
    counts = offsets[nodes + 1] - offsets[nodes]
    starts = np.repeat(offsets[nodes] - np.cumsum(counts) + counts, counts)
    return starts + np.arange(int(counts.sum()))


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
