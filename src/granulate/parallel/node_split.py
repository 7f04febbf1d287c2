"""Bodies cut at node level across the ranks of an MPI communicator (issue 17, docs/parallel.md):
one body's fracture on many processes, bit for bit the serial run. Simulation(comm=...) runs a
model in which nothing touches (no contact law, wall or PeriDEM damping:
Interactions.contact_free) this way, `mpiexec granulate run case.yaml` included.

The nodes are dealt by recursive coordinate bisection (partition.bisect over blocks of 64
consecutive nodes cut where a particle ends, each weighted by its nodes' bonds plus one), so a
body larger than a subdomain is cut wherever the cuts fall and its bonds cross ranks. Each rank
evaluates its own nodes (core.set_foreign_nodes) and receives, of the others, its halo: the
nodes bonded to its own, one horizon deep. A step exchanges twice with each neighbouring rank:
the halo's positions after the drift (core.move), then, for LPS, the halo's dilatation sums
after the bonds' stretch and breaking (core.begin_step), before the forces (core.finish_step).
The core evaluates of a halo node only its bonds to own nodes, so every own node sums the
serial run's terms in the serial order and a bond across a cut breaks alike on both sides
(tests/test_node_split.py in one process, tests/test_mpi.py on 2 and 3 ranks). The halo is
fixed by the bonds, so no node ever needs to change hands.

Every rank holds the whole model, as a distributed run's ranks do (engine.py). An output step
is made of what each rank measures of its own nodes (step_data): exact totals, fragment labels
found by the ranks together (fragment_labels), and the fragment and particle tables' sums run
by run (run_sums.py: the nodes are dealt in whole blocks, so each rank's runs are the serial
run's). For writers that read the simulation and the end of a run, rank 0's simulation
takes every node's state from its owner (collect); a checkpoint, in the serial format, rank 0
writes from its own core's state with the other ranks' nodes put in. Contact is not split: a body's
rigid motion, which contact reads each step, is a sum in node order across ranks.
"""

from __future__ import annotations

import functools
import operator
import os
import time
from dataclasses import dataclass, replace
from pathlib import Path
from types import SimpleNamespace
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from granulate import checkpoints, fingerprints, fragments, particle_table
from granulate.errors import InputError
from granulate.evaluation import Evaluation
from granulate.parallel.agreement import attempt, on_root, stop_if_any_failed, together
from granulate.parallel.large_messages import large_message_comm
from granulate.parallel.overlap import while_travelling
from granulate.parallel.partition import bisect
from granulate.parallel.rank_threads import share_of_cores
from granulate.parallel.run_measures import RankMeasures
from granulate.run_sums import BLOCK, Runs
from granulate.step_totals import StepTotals, TrackedSums, node_totals
from granulate.writers.step_data import StepData
from granulate.writers.vtu_frame import FIELD_TYPES, NodeRows, point_fields, write_piece_rows

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
        blocks = -(-nodes // BLOCK)
        if ranks > blocks:
            raise InputError(
                f"{ranks} ranks for {nodes} nodes: a body is cut in blocks of {BLOCK} nodes, "
                f"so run it on at most {blocks} rank(s)"
            )
        every = np.arange(len(sim.bodies))
        self.local: Simulation = together(comm, lambda: _built(sim._subdomain(every)[0]))
        core, model = self.local.core, self.local.model
        #: The stable time-step estimate [s]: the serial run's (every rank holds the model).
        self.stable_dt = float(core.stable_time_step)
        self._offsets = np.asarray(model.bond_offsets, dtype=np.int64)
        points = np.asarray(model.reference_positions)[:, : sim.dimension]
        particles = np.asarray(model.node_particle, dtype=np.int64)
        self.owner = _dealt_in_blocks(points, particles, np.diff(self._offsets) + 1.0, ranks)
        rank = comm.Get_rank()
        self.nodes_of = [np.flatnonzero(self.owner == q) for q in range(ranks)]
        self.own = self.nodes_of[rank]
        #: The own nodes' volumes, densities, masses and particles (set-up data, for outputs).
        self._own_volumes = np.asarray(model.volumes)[self.own]
        self._own_density = np.asarray(model.node_density)[self.own]
        self._own_mass = self._own_density * self._own_volumes
        self._own_particles = np.asarray(model.node_particle)[self.own]
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
        self._labels: tuple[int, NDArray[np.int64]] | None = None  # (step, fragment_labels())

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
        start = time.perf_counter()
        failure = attempt(core.move)
        failure, communicated, waited = self._exchange(
            core.positions, core.evaluate_dilatation, failure
        )
        failure = attempt(core.begin_step, failure)
        if self._lps:
            failure, more, waits = self._exchange(core.dilatation, core.evaluate_bonds, failure)
            communicated, waited = communicated + more, waited + waits
        failure = attempt(lambda: core.finish_step(_NO_BREAKS), failure)
        reducing = time.perf_counter()
        stop_if_any_failed(self.comm, failure, f"taking step {int(core.step) + 1}")
        end = time.perf_counter()
        communicated += end - reducing
        self.seconds["exchange"] += communicated
        self.seconds["steps"] += end - start - communicated
        self.waiting += waited

    def _exchange(
        self, field: NDArray[np.float64], inner: Any, failure: Exception | None
    ) -> tuple[Exception | None, float, float]:
        """The halo's rows of `field` (positions, n x 3, or dilatation sums, n) from their
        owners, one message each way per neighbouring rank, while `inner` (core.
        evaluate_dilatation or evaluate_bonds: the inner blocks, which read nothing of them)
        runs (overlap.while_travelling). The step's failure so far, or `inner`'s; the seconds
        spent communicating (`inner`'s not counted) and, of them, waiting for the halo [s]."""
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
        waited = time.perf_counter() - waiting
        for q, halo in self._receive.items():
            field[halo] = inbox[q][:, 0] if field.ndim == 1 else inbox[q]
        return failure, posted - start + testing + time.perf_counter() - waiting, waited

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
        parts = self.large.gather(self._own_state(), root=0)
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

    def fragment_labels(self) -> NDArray[np.int64]:
        """Every rank: its own nodes' fragment labels, each the smallest node of its piece in
        the whole body (the serial run's core.fragments): the pieces among its own nodes
        (core.fragments_among), joined through the intact bonds leaving them to the pieces
        their partners' owners found (one exchange with each neighbouring rank, one
        allgather of the pairs of pieces so joined). Kept for the step."""
        step = int(self.local.core.step)
        if self._labels is not None and self._labels[0] == step:
            return self._labels[1]
        labels, leaving = self.local.core.fragments_among(self.own.astype(np.uint32))
        labels = np.asarray(labels, dtype=np.int64)
        field = np.zeros(len(self.owner))  # node indices as floats: exact below 2^53
        field[self.own] = labels
        self._exchange(field, lambda share: None, None)  # its seconds are an output's, not a step's
        leaving = np.asarray(leaving, dtype=np.int64)
        mine = labels[np.searchsorted(self.own, leaving[:, 0])]
        nodes = len(self.owner)  # a pair of pieces (a, b) as the key a n + b
        keys = np.unique(mine * nodes + field[leaving[:, 1]].astype(np.int64))
        joined = _joined_pieces(self.comm.allgather(np.column_stack(np.divmod(keys, nodes))))
        if joined:
            labels = _relabelled(labels, joined)
        self._labels = (step, labels)
        return labels

    def step_data(
        self, tracked: tuple[int, ...], frame: tuple[str, ...] | None = None
    ) -> StepData | None:
        """Every rank: the current output step made of what each rank measures of its own
        nodes, with no whole state on rank 0 (as DistributedRun.step_data makes it of whole
        grains), with the sums of the `tracked` bodies and, for a frame of every node with the
        fields `frame`, each rank's rows of its own nodes joined in node order
        (StepData.frame_rows); on rank 0 (None on the others). The sums over the nodes are
        exact (step_totals.py); the fragment and particle tables' are made run by run
        (run_sums.py) of the nodes dealt in whole blocks and joined in node order on rank 0,
        which sends back the particles' centres for their second sums: every column is the
        serial run's."""
        start = time.perf_counter()
        labels, broken = self.fragment_labels(), self.broken_bonds()
        searches = self.comm.reduce(
            int(self.local.core.contact_statistics.rebuilds), op=self.mpi.MAX, root=0
        )
        part = together(self.comm, lambda: self._part(tracked, labels), "measuring its nodes")
        parts = self.large.gather(part, root=0)
        count = len(self._sim.bodies)
        first = on_root(self.comm, lambda: Runs.joined([p.first for p in parts]).totals(count))
        centre, velocity = self.comm.bcast(
            None if first is None else particle_table.centres(first), root=0
        )
        mine = together(self.comm, lambda: self._moments(centre, velocity), "measuring its nodes")
        moments = self.large.gather(mine, root=0)
        rows = None if frame is None else self.large.gather(self._own_rows(frame), root=0)
        counts = (broken, searches)
        data = on_root(self.comm, lambda: self._step_data(parts, first, moments, counts, rows))
        self.seconds["collect"] += time.perf_counter() - start
        return data

    def _part(self, tracked: tuple[int, ...], labels: NDArray[np.int64]) -> _NodesPart:
        """This rank's _NodesPart of an output step, its fragment `labels` given."""
        local, own, core = self.local, self.own, self.local.core
        volumes, density, mass = self._own_volumes, self._own_density, self._own_mass
        particle = self._own_particles
        phi = local.analysis.damage_phi()[own]
        energy = np.asarray(core.strain_energy_density())[own]
        x, v = core.positions[own], core.velocities[own]
        totals = node_totals(mass, volumes, v, x, local.gravity, energy, phi)
        sums = tuple(self._tracked_sums(body) for body in tracked)
        return _NodesPart(
            replace(totals, tracked=sums),
            fragments.fragment_runs(labels, own, x, v, volumes, density),
            np.unique(labels),
            Runs.first_sums(particle, own, mass, volumes, x, v),
            particle_table.volume_runs(particle, own, volumes, phi),
        )

    def _tracked_sums(self, body: int) -> TrackedSums:
        """The sums of the tracked body's own nodes."""
        span = self._sim.bodies[body].node_slice
        mine = slice(*np.searchsorted(self.own, [span.start, span.stop]))
        nodes, model, core = self.own[mine], self.local.model, self.local.core
        return TrackedSums.of(
            self._own_mass[mine],
            self._own_volumes[mine],
            core.forces[nodes],
            core.positions[nodes],
            np.asarray(model.reference_positions)[nodes],
        )

    def _moments(self, centre: NDArray[np.float64], velocity: NDArray[np.float64]) -> Runs:
        """The runs of this rank's particle sums about the particles' `centre` and `velocity`."""
        own, core = self.own, self.local.core
        x, v = core.positions[own], core.velocities[own]
        return Runs.moments(self._own_particles, own, self._own_mass, x, v, centre, velocity)

    def _step_data(
        self,
        parts: list[_NodesPart],
        first: NDArray[np.float64],
        moments: list[Runs],
        counts: tuple[int, int],
        rows: list[NodeRows] | None,
    ) -> StepData:
        """Rank 0: the output step of every rank's part, the particles' first sums and the
        runs of their moments, and the ranks' rows of a frame of every node (`rows`, when one
        is due); `counts`: the bonds broken and the list searches."""
        sim, core = self._sim, self.local.core
        broken, searches = counts
        totals = functools.reduce(operator.add, (part.totals for part in parts))
        ids = np.unique(np.concatenate([part.ids for part in parts]))
        particle_of = np.asarray(self.local.model.node_particle)[ids]
        pieces = Runs.joined([part.pieces for part in parts])
        table = fragments.table_of_runs(pieces, ids, particle_of, sim.dimension)
        count = len(sim.bodies)
        motion = particle_table.table_of(first, Runs.joined(moments).totals(count))
        volumes, damage = particle_table.volumes_of(
            Runs.joined([part.volumes for part in parts]).totals(count)
        )
        contacts = self.local.analysis.contact_table()  # none: nothing touches
        evaluation = replace(Evaluation.of_core(core, contacts), list_rebuilds=searches)
        frame = None if rows is None else NodeRows.joined(rows, len(self.owner))
        sums = (totals, broken, table, evaluation)
        return StepData.of_measures(sim, core, sums, (motion, volumes, damage), frame)

    def fingerprint(self) -> str:
        """The set-up's fingerprint (Simulation.fingerprint), on every rank from the whole
        model it holds (no message)."""
        if self._setup_digest is None:
            self._setup_digest = fingerprints.whole_model_digest(self._sim, self.local.model)
        return fingerprints.fingerprint(self._sim, self._setup_digest, self.dt)

    def save_checkpoint(self, path: str | os.PathLike[str], outputs: Outputs | None = None) -> Path:
        """The serial run's checkpoint (granulate.checkpoints, with `outputs`' bookkeeping),
        written by rank 0 from its own core's state with every other rank's nodes put in:
        rank 0 builds no whole simulation for it. It restarts on any number of ranks, or
        serially, bit for bit. Rank 0 raises a failure to write, the others RankFailed. The
        path written, on every rank."""
        start = time.perf_counter()
        parts = self.large.gather(self._own_state(), root=0)

        def write() -> Path:
            state = self._whole_checkpoint(parts)
            moment = (int(state["step"]), float(state["time"]))
            header = checkpoints.header_of(*moment, self.fingerprint(), outputs)
            return checkpoints.save_state(path, state, header)

        written = Path(self.comm.bcast(on_root(self.comm, write), root=0))
        self.seconds["collect"] += time.perf_counter() - start
        return written

    def _own_state(self) -> tuple[NDArray[Any], ...]:
        """This rank's own nodes' fields (_NODE_FIELDS) and bond states (their bond copies)."""
        core = self.local.core
        intact = np.asarray(core.bond_intact)[_copies_of(self._offsets, self.own)]
        return (*(np.asarray(getattr(core, f))[self.own] for f in _NODE_FIELDS), intact)

    def _whole_checkpoint(self, parts: list[tuple[NDArray[Any], ...]]) -> dict[str, Any]:
        """Rank 0: its core's checkpoint (core.checkpoint) with every node's fields and bond
        states from its owner (`parts`, every rank's _own_state in rank order)."""
        state = dict(self.local.core.checkpoint())
        nodes = len(self.owner)
        fields = {f: np.array(state[f], dtype=np.float64).reshape(nodes, -1) for f in _NODE_FIELDS}
        bonds = np.array(state["bond_intact"], dtype=np.uint8)
        for own, part in zip(self.nodes_of, parts, strict=True):
            for name, values in zip(_NODE_FIELDS, part[:-1], strict=True):
                fields[name][own] = np.asarray(values).reshape(len(own), -1)
            bonds[_copies_of(self._offsets, own)] = part[-1]
        for name, values in fields.items():
            state[name] = values.reshape(np.shape(state[name]))
        state["bond_intact"] = bonds
        return state

    def load_checkpoint(self, path: str | os.PathLike[str], outputs: Outputs | None = None) -> None:
        """Continue from a checkpoint of this set-up written by a run on any number of ranks,
        or serially (else InputError on every rank): rank 0 reads it into its own core (with
        `outputs`' bookkeeping; no whole simulation is built for it) and the other ranks
        restore the whole state from it."""

        def read() -> dict[str, Any]:
            checkpoints.load(self.local, path, outputs, self.fingerprint())
            return dict(self.local.core.checkpoint())

        start = time.perf_counter()
        state = self.large.bcast(on_root(self.comm, read), root=0)

        def restore() -> None:
            if self.comm.Get_rank() != 0:  # rank 0's core holds it already
                self.local.core.restore(state)

        together(self.comm, restore, "restoring the checkpoint")
        self._sim._ranks_ahead = True  # rank 0's simulation does not hold the checkpoint's state
        self._sim._gathered = None
        self._labels = None
        self.seconds["collect"] += time.perf_counter() - start

    def write_piece(self, folder: Path, fields: tuple[str, ...]) -> None:
        """This rank's piece of a frame in pieces (writers/vtu_frame.py): its own nodes now,
        with `fields`, as folder/piece_<rank>.vtu."""
        rows = self._own_rows(fields)
        path = Path(folder) / f"piece_{self.comm.Get_rank()}.vtu"
        write_piece_rows(path, rows.positions, rows.values, rows.numbers)

    def _own_rows(self, fields: tuple[str, ...]) -> NodeRows:
        """Every rank: the rows of its own nodes in a frame with `fields`, the fragment labels
        found by the ranks together (fragment_labels)."""
        labels = self.fragment_labels() if "Fragment_ID" in fields else None
        local = tuple(f for f in fields if f != "Fragment_ID")
        values = together(self.comm, lambda: point_fields(self.local, local), "measuring its nodes")
        rows = {name: field[self.own] for name, field in values.items()}
        if labels is not None:
            rows["Fragment_ID"] = labels
        ordered = {f: rows[f].astype(FIELD_TYPES[f][0]) for f in fields}
        return NodeRows(self.own, self.local.core.positions[self.own], ordered)


@dataclass(frozen=True)
class _NodesPart:
    """What one rank sends rank 0 for an output step (NodeSplitRun.step_data): the sums over its
    own nodes, the runs of its pieces' sums and the pieces (their labels, sorted), and the runs
    of the particles' first sums and volumes."""

    totals: StepTotals
    pieces: Runs
    ids: NDArray[np.int64]
    first: Runs
    volumes: Runs


def _dealt_in_blocks(
    points: NDArray[np.float64],
    particles: NDArray[np.int64],
    weights: NDArray[np.float64],
    ranks: int,
) -> NDArray[np.int64]:
    """Each node's rank: the blocks of run_sums.BLOCK consecutive nodes, each cut where a
    particle ends, dealt whole by recursive coordinate bisection of their centres, each
    weighing its nodes' `weights`, so that every rank makes the runs of its nodes' sums as the
    serial run does (run_sums.py: no run crosses a block or a particle's end)."""
    block = np.arange(len(points)) // BLOCK
    starts = (block[1:] != block[:-1]) | (particles[1:] != particles[:-1])
    unit = np.concatenate([[0], np.cumsum(starts)])
    count = int(unit[-1]) + 1
    sizes = np.bincount(unit, minlength=count)
    centres = np.column_stack(
        [np.bincount(unit, points[:, k], count) for k in range(points.shape[1])]
    )
    dealt = bisect(centres / sizes[:, None], np.bincount(unit, weights, count), ranks)
    return dealt.owner[unit]


def _joined_pieces(pairs: list[NDArray[np.int64]]) -> dict[int, int]:
    """Per piece in `pairs` (rows of two pieces joined by an intact bond, every rank's), the
    smallest piece it is joined to through them."""
    parent: dict[int, int] = {}

    def root(piece: int) -> int:
        while parent.setdefault(piece, piece) != piece:
            parent[piece] = parent[parent[piece]]
            piece = parent[piece]
        return piece

    for a, b in np.concatenate(pairs).tolist():
        first, second = root(a), root(b)
        parent[max(first, second)] = min(first, second)
    return {piece: root(piece) for piece in list(parent)}


def _relabelled(labels: NDArray[np.int64], joined: dict[int, int]) -> NDArray[np.int64]:
    """`labels` with each piece that `joined` names replaced by the piece it joins."""
    pieces = np.fromiter(joined.keys(), np.int64, len(joined))
    roots = np.fromiter(joined.values(), np.int64, len(joined))
    order = np.argsort(pieces)
    pieces, roots = pieces[order], roots[order]
    place = np.minimum(np.searchsorted(pieces, labels), len(pieces) - 1)
    return np.where(pieces[place] == labels, roots[place], labels)


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
