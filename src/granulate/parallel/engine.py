"""One simulation stepped on the ranks of an MPI communicator, whole grains per rank
(DESIGN.md section 7, docs/parallel.md).

Each rank holds the grains it owns and, as ghosts, the grains of other ranks whose bounding
spheres come within the contact lists' cutoff plus a margin of its own (partition.py), in the
serial order, at the serial run's time step and neighbour skin, but evaluates only its own
grains' bonds and moves only its own nodes (core.set_ghost_particles). Each step runs in two
halves (core.begin_step: the drift and the bonds' stretch and breaking; core.finish_step: the
contact and the rest), and between them the owners send the ranks that hold their grains as
ghosts the positions and velocities of the nodes within their reach (the caps), the bonds that
broke in those grains and the rigid-body motion of each of their fragments, which the contact
takes in place of what the ghost copies would give (a ghost's fragments enter its partners'
contact too). That exchange is under way while each rank evaluates its bond forces
(core.evaluate_bonds, which read no ghost), and completed before the contact. An owned grain's
step needs nothing else (tests/test_locality.py): the owned grains move bit for bit as in the
serial run, for any number of ranks (tests/test_mpi.py).

The ghost sets hold while no node has moved more than half the margin from where it was when
the grains were last distributed, since then no pair left out can come within the cutoff; the
caps, while no node, nor where the lists see a node near another rank's, has moved half the
cap margin since they were picked. The run checks both every step: within the step, past half
the cap margin, the ranks pick the caps anew; after it, past a quarter of the margin, they cut
the grains anew where they are (which also rebalances) and hand grains over with their whole
state (transplant.py).
Wall reactions are summed on rank 0 in the serial order. `collect` gathers every grain's state
and the last evaluation into rank 0's simulation (whole_state.py), whose serial writers and
stop criteria then see the serial run (Simulation(comm=...) runs through stepper.py).
Checkpoints are written in pieces, each rank its own grains (checkpoint_pieces.py), and
restart on any number of ranks, or serially.
"""

from __future__ import annotations

import os
import time
import warnings
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from types import SimpleNamespace
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from granulate import checkpoints, fingerprints
from granulate._core import combined_time_step, points_within
from granulate.core_model import materials_in_core_order
from granulate.errors import InputError
from granulate.parallel import checkpoint_pieces
from granulate.parallel.agreement import RankFailed, attempt, on_root, together
from granulate.parallel.large_messages import large_message_comm
from granulate.parallel.overlap import while_travelling
from granulate.parallel.partition import (
    Partition,
    bisect,
    ghosts,
    near_nodes,
    near_pairs,
    near_pairs_with_large,
)
from granulate.parallel.rank_threads import share_of_cores
from granulate.parallel.run_measures import RankMeasures
from granulate.parallel.step_clock import StepClock
from granulate.parallel.step_parts import step_data, step_part
from granulate.parallel.transplant import (
    GrainState,
    body_first_nodes,
    grain_states,
    moment_of,
    restore_grains,
    wall_lists,
)
from granulate.parallel.whole_state import install, owned_part
from granulate.parallel.work_load import imbalance, node_work
from granulate.writers.vtu_frame import NodeRows, node_rows, write_piece

if TYPE_CHECKING:
    from granulate.node_map import NodeMap
    from granulate.simulation import Simulation
    from granulate.writers.outputs import Outputs
    from granulate.writers.step_data import StepData

_TAG = 17
_REST_TAG = 18  # what a step's message has no room for
_CAP_TAG = 19
_BODY = 16  # numbers a body's motion takes in a message: its first node, then 15
_JOINING = 7  # numbers a node joining a cap takes: its global number, x and v
#: A step message's sections: breaks (node pairs), bodies, nodes joining the cap.
_WIDTHS = (2, _BODY, _JOINING)
#: Most steps break no bond and add no node to a cap: these stand for the empty sections.
_NO_JOINING = np.zeros((0, _JOINING))
_NO_REST = np.zeros(0)


class _Exchange(NamedTuple):
    """A step's exchange under way (_send_within_step): its first messages' requests (the
    receives, then the sends), the second messages' sends, and the nodes joining each
    receiving rank's cap."""

    requests: list[Any]
    overflow: list[Any]
    joined: dict[int, NDArray[np.int64]]


class DistributedRun:
    """`sim` (set up, not built) stepped on the ranks of `comm` (an mpi4py communicator).

    ``margin`` [m]: how much farther than the contact lists' cutoff a ghost is taken; default
    the largest bounding radius of a grain none of whose nodes is prescribed (fixed, displaced
    or rotated: not a PeriDEM deck's wall particles, whose radius is the container's), or of
    any grain when every one has such nodes. The ghosts hold while every node stays within
    margin/2 of where it was when the grains were last distributed; once one may have moved
    margin/4, the ranks ``migrate`` (cut the assembly anew and hand grains over with their
    whole state), or with ``migrate=False`` stop with an InputError past margin/2. Bodies over
    twice as large as that grain (meshed walls, containers) are near the grains their nodes
    come near, not all those their bounding spheres take in. The default margin doubles, up to
    ``widest_margin`` times that radius, at a migration after a distribution that lasted fewer
    than ``short_distribution`` steps: grains that flow that fast make migrations (each costs
    about 20 steps) dearer than the wider ghosts (which the ranks hold, but whose caps alone
    travel). A margin given is kept.

    ``cap_margin`` [m]: the same for the caps, the ghost nodes whose positions and velocities
    travel in each step (_exchange_caps); at most the margin. The caps hold while every node,
    and where the lists see each node of a grain another rank holds, stays within
    cap_margin/2 of where it was when they were picked; each step checks that
    once it has moved the nodes, before its contact, and where one has moved farther the ranks
    pick them anew there (refresh_caps: the ghosts made their owners' grains whole, no grain
    changes hands). A smaller cap margin sends fewer nodes each step and refreshes more often.
    The default starts at half the largest mesh size (grains at rest or loaded slowly keep
    thin caps) and doubles, up to the margin, when the caps last fewer than
    ``short_cap_period`` steps (flowing grains refresh less often); a cap margin given is
    kept. Caps that hold every ghost node (coarse grains) are never picked anew.

    The start cuts the grains by their nodes; every migration cuts them by their work
    (work_load.py), and at the start and as the simulation's ``load_balance`` (granulate.
    LoadBalance) says the ranks compare their work and migrate when it has drifted past its
    threshold (_check_balance).

    Every rank calls the constructor and each method together.
    """

    #: Breaks a step's message to a neighbouring rank carries after its nodes' x and v (their
    #: count, then node pairs as float64, exact below 2^53); more go in a second message
    #: (tests lower it to exercise that path).
    break_slots = 64
    #: Bodies' motions it carries beyond one per grain sent (a grain's fragments, each its
    #: first node and 15 numbers); more go in the second message too.
    body_slots = 64
    #: Nodes joining the cap it carries (the new anchors of a cap's nodes whose bonds broke);
    #: more go in the second message too.
    joining_slots = 64
    #: A distribution of the grains shorter than this many steps widens the default margin.
    short_distribution = 200
    #: The widest default margin, in radii of the largest free grain.
    widest_margin = 4.0
    #: Caps picked anew fewer than this many steps after they were picked widen the default
    #: cap margin.
    short_cap_period = 50

    def __init__(
        self,
        sim: Simulation,
        comm: Any,
        margin: float | None = None,
        migrate: bool = True,
        cap_margin: float | None = None,
    ) -> None:
        from mpi4py import MPI

        self.mpi = MPI
        self.comm = comm
        #: `comm` for messages of states (large_messages.py).
        self.large = large_message_comm(comm)
        self._sim = sim
        share_of_cores(comm)
        self._slices = [body.node_slice for body in sim.bodies]  # each grain's global nodes
        self._firsts_global = np.array([s.start for s in self._slices], dtype=np.int64)
        self._counts = np.array([s.stop - s.start for s in self._slices], dtype=np.int64)
        self._node_count = sim._assembly.node_count
        self._weights = np.array([body.node_count for body in sim.bodies], dtype=float)
        start = _start_positions(sim)
        centres, radii = _spheres(start, sim.dimension)
        self._set_up_damping(sim)
        _check_grains_for_ranks(len(self._slices), comm.Get_size())
        start_partition = bisect(centres, self._weights, comm.Get_size())
        first = start_partition.grains_of(comm.Get_rank())
        # The cutoff, skin and dt from the first grains and each material's coarsest grain.
        probed = np.union1d(first, _coarsest_of_each_material(sim))
        probe = together(self.comm, lambda: _built(sim._subdomain(probed)[0]))
        self._skin = comm.allreduce(probe.core.contact_skin, op=MPI.MAX)
        reach = probe.core.contact_reach - probe.core.contact_skin
        cutoff = max(comm.allreduce(reach, op=MPI.MAX) + self._skin, self._damping_reach)
        #: The stable time-step estimate [s]: the serial run's (_stable_time_step).
        own = np.searchsorted(probed, first)
        self.stable_dt = self._stable_time_step(probe, own, start_partition)
        del probe  # before the part is built: both at once would double the peak
        self._dt = sim._dt_safety * self.stable_dt if sim._dt is None else float(sim._dt)
        grain = _largest_free_radius(sim, radii)
        self.margin = float(grain if margin is None else margin)
        self._widest = self.widest_margin * grain if margin is None else self.margin
        #: How many times the default margin was widened (_widen_margin).
        self.margin_widenings = 0
        self._cutoff = cutoff
        #: Bodies over twice as large as the largest free grain (meshed walls, containers):
        #: their pairs with the grains are found from their nodes (partition.near_nodes).
        self._large = np.flatnonzero(radii > 2 * grain)
        largest_mesh = max(body.mesh_size for body in sim.bodies)
        start_cap = min(0.5 * largest_mesh, self.margin)
        self.cap_margin = float(start_cap if cap_margin is None else cap_margin)
        if not 0 < self.cap_margin <= self.margin:
            raise InputError(
                f"cap_margin must be a length in m above 0 and at most the margin "
                f"({self.margin:.3g} m), got {cap_margin!r}"
            )
        self._adapt_caps = cap_margin is None
        #: How many times the default cap margin was widened (_widen_cap_margin).
        self.cap_margin_widenings = 0
        #: How many times the caps were picked anew between distributions (refresh_caps).
        self.cap_refreshes = 0
        #: The ghost nodes this rank received in all its steps (each step, its caps'), and the
        #: surface normals (of its caps' faces, _faces).
        self.nodes_received = 0
        self.normals_received = 0
        #: The nodes that joined its caps between picks (new anchors of cap nodes; _joining).
        self.nodes_joined = 0
        #: How many of this rank's step messages had a second one for the breaks and bodies'
        #: motions they had no room for.
        self.second_messages = 0
        self._migrates = migrate
        #: How many times the grains were distributed anew (migrate()), and how many grains
        #: changed owner then, in all.
        self.migrations = 0
        self.handed_over = 0
        #: How many of the migrations built this rank's part anew (it held other grains).
        self.renewals = 0
        #: Build every rank's part anew at every migration, held grains changed or not (for
        #: tests of the hand-over, tests/mpi_check.py).
        self.always_renew = False
        self._migration_due = False
        #: The steps before which the ranks migrated for their balance (_check_balance).
        self.rebalance_steps: list[int] = []
        self._rebalance_due = False
        self._left_imbalance = 1.0  # what the last cut left, by the work it was cut by
        #: The most loaded rank's work over the mean at the last check (_check_balance), and
        #: how many checks the ranks made.
        self.work_imbalance = 1.0
        self.balance_checks = 0
        # The wall reactions a loaded checkpoint holds, until the next step evaluates them.
        self._loaded_walls: NDArray[np.float64] | None = None
        self._setup_digest: str | None = None  # of the set-up's fingerprint, made once
        held = self._distribute_whole(start, centres, radii)
        together(self.comm, lambda: self._build(held))
        self._exchange_state()
        self._exchange_caps()
        self._bond_count = self._count_bonds()
        #: Wall-clock seconds of this rank in its steps, ghost exchanges, partition checks,
        #: migrations and collections of the whole state on rank 0 (collect).
        self.seconds = dict.fromkeys(
            ("steps", "exchange", "check", "caps", "migrate", "collect"), 0.0
        )
        #: Of the exchange's seconds, those spent waiting for the step's messages (Waitall,
        #: after the bond forces): what the overlap did not hide.
        self.waiting = 0.0
        self._clock = StepClock()  # for LoadBalance(weight="time")
        self._check_balance()

    def _stable_time_step(
        self, probe: Simulation, own: NDArray[np.int64], partition: Partition
    ) -> float:
        """The serial run's stable time-step estimate, 1/dt^2 = 1/dt_pd^2 + 1/dt_contact^2
        (core.combined_time_step), from `probe`, a part of this rank's grains in `partition`
        (its particles `own`) and each material's coarsest grain: dt_pd the least over the ranks of
        their grains' peridynamic estimates; dt_contact the least of their grains' contact
        estimates, each against every grain of the run as a partner (ContactModel's
        stable_time_step: each grain's material, mesh size, horizon, modulus and largest node
        volume, sent by its owner), not only those the part holds."""
        core = probe.core
        materials = _material_numbers(self._sim)
        to_run = np.array([materials[id(m)] for m in probe._core_materials])
        rows = np.asarray(core.contact_partners()).reshape(-1, 5)[own]
        rows[:, 0] = to_run[rows[:, 0].astype(np.int64)]
        table = np.empty((len(self._slices), 5))
        for owner, their_rows in enumerate(self.comm.allgather(rows)):
            table[partition.grains_of(owner)] = their_rows
        to_probe = np.full(len(materials), -1)
        to_probe[to_run] = np.arange(len(to_run))
        table[:, 0] = to_probe[table[:, 0].astype(np.int64)]
        mine = np.array(
            [
                core.peridynamic_stable_time_step,
                core.contact_stable_time_step_against(table.ravel()),
            ]
        )
        least = np.empty(2)
        self.comm.Allreduce(mine, least, op=self.mpi.MIN)
        return float(combined_time_step(least[0], least[1]))

    def _set_up_damping(self, sim: Simulation) -> None:
        """What PeriDEM's damping (--peridem-compat) needs of the ghosts: it acts between
        particles whose centre nodes come within their radii plus `_damping_reach` (0: no
        damping), PeriDEM's wall particles left out, and from wall nodes within that reach of
        a node (contact/peridem_damping.hpp)."""
        self._damping_reach = sim._interactions.peridem_reach()
        self._damped_centres: NDArray[np.int64] | None = None  # global nodes, with damping
        if self._damping_reach == 0:
            return
        centres, radii = sim._assembly.centres_and_radii()
        self._damped_centres = np.asarray(centres, dtype=np.int64)
        self._damping_radii = np.asarray(radii)
        walls = sim._interactions.peridem_wall_indices()
        self._centre_damped = np.setdiff1d(np.arange(len(self._slices)), walls)

    @property
    def _reach(self) -> float:
        """How near a grain's bounding sphere must come to a rank's grains for it to be held
        there as a ghost [m]: the cutoff plus the margin."""
        return self._cutoff + self.margin

    def _build(self, held: NDArray[np.int64]) -> None:
        """This rank's part of the grains `held` at the start, with its first forces (the
        owners' values for the ghosts come with the first exchange)."""
        self.local, node_map = self._sim._subdomain(held, dt=self._dt, skin=self._skin)
        self.held = held
        self.local.core.run(0)  # before the ghosts are marked: they break bonds here too
        self._plan(node_map)

    def _distribute(
        self,
        centres: NDArray[np.float64],
        radii: NDArray[np.float64],
        damped_centres: NDArray[np.float64] | None,
        large_pairs: tuple[NDArray[np.int64], NDArray[np.int64]],
    ) -> NDArray[np.int64]:
        """Owners by recursive coordinate bisection of the grains' `centres` and the ghosts of
        every rank from their bounding spheres (`radii`) and the large bodies' `large_pairs`
        (_pairs_of_large), and with PeriDEM's damping also from where their centre nodes are
        (`damped_centres`; None without it); the grains this rank holds (sorted)."""
        rank = self.comm.Get_rank()
        self.partition: Partition = bisect(centres, self._weights, self.comm.Get_size())
        first, last = near_pairs_with_large(centres, radii, self._reach, self._large, large_pairs)
        if damped_centres is not None:  # centres within radii + reach, each moving < margin/2
            reach = self._damping_reach + self.margin
            ids = self._centre_damped
            more = near_pairs(damped_centres[ids], self._damping_radii[ids], reach)
            first, last = (
                np.concatenate([first, ids[more[0]]]),
                np.concatenate([last, ids[more[1]]]),
            )
        self.ghosts = ghosts(self.partition, (first, last))
        return np.union1d(self.partition.grains_of(rank), self.ghosts[rank])

    def _distribute_whole(
        self,
        grains: Sequence[NDArray[np.float64]],
        centres: NDArray[np.float64],
        radii: NDArray[np.float64],
    ) -> NDArray[np.int64]:
        """_distribute from every grain's node positions (`grains`), which every rank has at
        the start, and their bounding spheres (_spheres)."""
        return self._distribute(*self._layout(grains, centres, radii))

    def _layout(
        self,
        grains: Sequence[NDArray[np.float64]],
        centres: NDArray[np.float64],
        radii: NDArray[np.float64],
    ) -> tuple[Any, ...]:
        """What _distribute reads of every grain's node positions (`grains`) and bounding
        spheres: those, PeriDEM's damped centres' positions and the large bodies' pairs."""
        damped = None
        if self._damped_centres is not None:
            damped = np.array([self._centre_point(g, nodes) for g, nodes in enumerate(grains)])
        large = self._pairs_of_large(centres, radii, {int(g): grains[g] for g in self._large})
        return centres, radii, damped, large

    def _centre_point(self, grain: int, nodes: NDArray[np.float64]) -> NDArray[np.float64]:
        """Where `grain`'s centre node (PeriDEM's damping) is, of its nodes' positions `nodes`
        (its first `dimension` coordinates)."""
        assert self._damped_centres is not None
        centre = self._damped_centres[grain] - self._slices[grain].start
        return nodes[centre, : self._sim.dimension]

    def _pairs_of_large(
        self,
        centres: NDArray[np.float64],
        radii: NDArray[np.float64],
        nodes: dict[int, NDArray[np.float64]],
    ) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """The pairs of the large bodies in `nodes` (their nodes' positions now) with the
        grains whose `centres` and `radii` are given (partition.near_nodes)."""
        pairs = [
            near_nodes(centres, radii, self._reach, g, x, self._large) for g, x in nodes.items()
        ]
        none = np.zeros(0, np.int64)
        return (
            np.concatenate([none, *(first for first, _ in pairs)]),
            np.concatenate([none, *(last for _, last in pairs)]),
        )

    def _plan(self, node_map: NodeMap) -> None:
        """Which grains go to which rank and come from which, and the positions the nodes'
        travel is measured from (the core measures it in each step). The core skips the
        ghosts' bonds and moves (Simulation::set_ghost_particles): their positions,
        velocities, breaks and bodies' motions come from their owners within each step
        (_exchange_within_step), of the nodes _exchange_caps picks. Local work only."""
        rank = self.comm.Get_rank()
        owner = self.partition.owner
        self._node_map = node_map
        # The ghost fragments' first nodes last looked up in node_map, global and local.
        self._firsts_of, self._firsts = np.zeros(0), np.zeros(0, np.uint32)
        self._to_global = node_map.kept()  # subsets keep the serial order
        self._owned = self.partition.grains_of(rank)
        ghost_particles = np.flatnonzero(owner[self.held] != rank)  # the part's particle order
        self.local.core.set_ghost_particles(ghost_particles.tolist())
        self.local.core.set_reported_numbers(self._to_global.tolist(), self.held.tolist())
        self.local.core.set_reported_stable_time_step(self.stable_dt)
        self._owned_nodes = self._nodes_of(self._owned, node_map)
        self._is_owned = _mask(len(self._to_global), self._owned_nodes)
        self._send_grains = {
            q: held[owner[held] == rank]
            for q, held in enumerate(self.ghosts)
            if q != rank and np.any(owner[held] == rank)
        }
        mine = self.ghosts[rank]
        self._receive_grains = {int(q): mine[owner[mine] == q] for q in np.unique(owner[mine])}
        self._send_whole = {q: self._nodes_of(g, node_map) for q, g in self._send_grains.items()}
        self._receive_whole = {
            q: self._nodes_of(g, node_map) for q, g in self._receive_grains.items()
        }
        self._sent_to = {q: _mask(len(self._to_global), n) for q, n in self._send_whole.items()}
        # The own nodes near another rank's (those of the grains it holds as ghosts): where the
        # lists see them is what the caps' check watches (_exchange_caps).
        sent = np.concatenate([np.zeros(0, np.int64), *self._send_whole.values()])
        self._watched = np.unique(sent).tolist()
        particles = {q: np.searchsorted(self.held, g) for q, g in self._send_grains.items()}
        self._motion_particles = np.unique(
            np.concatenate([np.zeros(0, np.int64), *particles.values()])
        ).tolist()
        # Rows of breaks and of bodies' motions a step's message carries, each way (_pack):
        # the sender's grains for q are q's grains from it, so both ends count alike.
        self._rooms_out = {q: self._rooms(len(g)) for q, g in self._send_grains.items()}
        self._rooms_in = {q: self._rooms(len(g)) for q, g in self._receive_grains.items()}
        self._particle_to = {q: _mask(len(self.held), p) for q, p in particles.items()}
        self._node_particle = np.asarray(self.local.model.node_particle, dtype=np.int64)
        # Where the own nodes were distributed, and the farthest any was from there when the
        # caps were last picked (refresh_caps).
        self._distributed_positions = self.local.core.positions[self._owned_nodes]
        self._travelled = 0.0
        self._distributed_at = int(self.local.core.step)

    def _exchange_caps(self) -> None:
        """Which of the ghosts' nodes each step sends (the caps): of each ghost grain, the
        nodes whose list positions (where the contact lists see them: a surface point,
        contact centre or the node, core.list_positions) lie within the cutoff plus the cap
        margin of one of this rank's own nodes' list positions, and the nodes those read:
        their anchors (core.contact_anchors; a node that takes new anchors when its bonds
        break brings them into the cap in that step's message, _joining); under PeriDEM's
        damping also every ghost's centre node (the damping reads it). Of the cap's nodes
        within the reach at which the contact reads surface normals (sums over a node's
        bonds: core.contact_surface_normal_reach, none under PeriDEM's node pairs) plus the
        cap margin, those bonded to a node outside the cap (the faces, _faces) have their
        normals sent too (core.surface_normals), 3 numbers a node in place of the x and v of
        the nodes bonded to them; the holder sums the others' itself. No other
        ghost node can come within those reaches of an own node, as the lists see them,
        before the caps are picked again (each node, and each list position of a grain
        another rank holds, moves less than cap_margin/2: core.largest_travel), so a ghost
        node outside the cap is read by no own node's contact, and stays out of the contact
        lists (core.set_inert_contact_nodes). Each rank picks its caps from the ghosts'
        positions now, which are their owners' (after _exchange_state or a rebuild), and
        tells the owners; one message per neighbour. The travel is measured from here
        (core.set_travel_origin)."""
        core = self.local.core
        normal_reach = self.comm.allreduce(core.contact_surface_normal_reach, op=self.mpi.MAX)
        core.set_travel_origin(self._watched)
        x = core.list_positions
        own = x[self._owned_nodes]
        ghosts = np.concatenate([np.zeros(0, np.int64), *self._receive_whole.values()])
        close = np.zeros(len(x), dtype=bool)  # one grid over the own nodes for every ghost
        close[ghosts] = points_within(x[ghosts], own, self._cutoff + self.cap_margin)
        normals = np.zeros(len(x), dtype=bool)  # nodes whose surface normal may be read
        if normal_reach > 0:
            near = ghosts[close[ghosts]]
            normals[near] = points_within(x[near], own, normal_reach + self.cap_margin)
        caps, faces = {}, {}
        for q, nodes in self._receive_whole.items():
            near = nodes[close[nodes]]
            caps[q] = contact_reads(core, near)
            if self._damped_centres is not None:  # PeriDEM's damping reads ghosts' centres
                centres = self._node_map[self._damped_centres[self._receive_grains[q]]]
                caps[q] = np.union1d(caps[q], centres)
            faces[q] = _faces(self.local.model, near[normals[near]], caps[q])
        to_global = self._to_global
        requests = [
            self.comm.isend((to_global[cap], to_global[faces[q]]), dest=q, tag=_CAP_TAG)
            for q, cap in caps.items()
        ]
        told = {q: self.comm.recv(source=q, tag=_CAP_TAG) for q in self._send_whole}
        self.mpi.Request.waitall(requests)
        self._send = {q: self._node_map[cap] for q, (cap, _) in told.items()}
        sent_faces = {q: self._node_map[face] for q, (_, face) in told.items()}
        # Each step measures every face sent once, and each message takes its rows of them.
        faces_out = np.unique(np.concatenate([np.zeros(0, np.int64), *sent_faces.values()]))
        self._faces_out = faces_out.tolist()
        self._face_rows = {q: np.searchsorted(faces_out, f) for q, f in sent_faces.items()}
        self._in_send = {q: _mask(len(self._to_global), n) for q, n in self._send.items()}
        self._receive, self._receive_faces = caps, faces
        self._faces_in = np.concatenate([np.zeros(0, np.int64), *faces.values()]).astype(np.uint32)
        outside = [np.setdiff1d(self._receive_whole[q], cap) for q, cap in caps.items()]
        self.local.core.set_inert_contact_nodes(np.concatenate([[], *outside]).astype(int).tolist())
        self._caps_picked_at = int(self.local.core.step)
        #: Whether some rank's caps leave ghost nodes out (else no need to pick them anew).
        self.caps_partial = self.comm.allreduce(any(len(o) for o in outside), op=self.mpi.LOR)
        self._outbox = {q: self._message_out(q) for q in self._send}
        self._inbox = {q: self._message_in(q) for q in self._receive}

    def _message_out(self, q: int) -> NDArray[np.float64]:
        """A buffer for the largest step message to rank q (_message)."""
        return _message(len(self._send[q]), len(self._face_rows[q]), self._rooms_out[q])

    def _message_in(self, q: int) -> NDArray[np.float64]:
        """A buffer for the largest step message from rank q (_message)."""
        return _message(len(self._receive[q]), len(self._receive_faces[q]), self._rooms_in[q])

    def _rooms(self, grains: int) -> NDArray[np.int64]:
        """The rows a step's message about `grains` grains carries of each section: break_slots
        breaks, one body per grain plus body_slots, and joining_slots nodes joining the cap."""
        return np.array([self.break_slots, grains + self.body_slots, self.joining_slots])

    def local_slice(self, grain: int) -> slice:
        """The local nodes of a held grain."""
        (nodes,) = self.local_slices([grain])
        return nodes

    def local_slices(self, grains: Iterable[int]) -> list[slice]:
        """The local nodes of each of these held grains (one node-map lookup for them all)."""
        index = np.fromiter(grains, dtype=np.int64)
        firsts = self._node_map[self._firsts_global[index]]
        counts = self._counts[index].tolist()
        return [slice(f, f + c) for f, c in zip(firsts.tolist(), counts, strict=True)]

    def _nodes_of(
        self, grains: NDArray[np.int64], node_map: NodeMap | None = None
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
    def owned(self) -> NDArray[np.int64]:
        """The grains this rank owns, sorted."""
        return self._owned

    @property
    def owned_nodes(self) -> NDArray[np.int64]:
        """The local indices of the owned grains' nodes, in grain order."""
        return self._owned_nodes

    def owned_slices(self) -> list[slice]:
        """The local node slice of each owned grain, in grain order."""
        return self.local_slices(self._owned)

    def is_owned_node(self, local: NDArray[np.int64]) -> NDArray[np.bool_]:
        """Whether each of these local nodes belongs to an owned grain."""
        return self._is_owned[local]

    def global_nodes(self, local: NDArray[np.int64]) -> NDArray[np.int64]:
        """The global indices of these local nodes."""
        return self._to_global[local]

    @property
    def ghost_node_count(self) -> int:
        """The nodes of the other ranks' grains this rank holds as ghosts."""
        return self.local._assembly.node_count - len(self._owned_nodes)

    @property
    def exchanged_node_count(self) -> int:
        """The ghost nodes whose positions and velocities this rank receives each step (the
        caps, _exchange_caps)."""
        return sum(len(nodes) for nodes in self._receive.values())

    @property
    def exchanged_normal_count(self) -> int:
        """The surface normals this rank receives in each step (of its caps' faces)."""
        return sum(len(nodes) for nodes in self._receive_faces.values())

    def _exchange_state(self) -> None:
        """Owners' positions, velocities and forces to the ranks that hold their grains as
        ghosts (one message per pair of neighbouring ranks): every ghost exact, as its owner's
        grain, at the start, before the caps are picked anew and before a migration (between
        them the steps' exchange keeps only what the next step needs)."""
        core = self.local.core
        x, v, f = core.positions, core.velocities, core.forces
        inbox = {q: np.empty((len(n), 9)) for q, n in self._receive_whole.items()}
        outbox = {q: np.hstack([x[n], v[n], f[n]]) for q, n in self._send_whole.items()}
        requests = [self.comm.Irecv(box, source=q, tag=_TAG) for q, box in inbox.items()]
        requests += [self.comm.Isend(box, dest=q, tag=_TAG) for q, box in outbox.items()]
        self.mpi.Request.Waitall(requests)
        for q, nodes in self._receive_whole.items():
            x[nodes], v[nodes], f[nodes] = inbox[q][:, :3], inbox[q][:, 3:6], inbox[q][:, 6:]

    def _send_within_step(self, broken: NDArray[np.uint32] | None) -> _Exchange:
        """After the first half of a step (the drift and pass 1), post the step's exchange:
        each rank sends the ranks that hold its grains as ghosts the positions and velocities
        now (the half-step velocities, which the contact uses) of the nodes in their caps
        (_exchange_caps), the bonds that broke in those grains this step (`broken`: flat (i, j)
        local node pairs; None when the step failed, and then no bodies either), the motion of
        each of their fragments (core.fragment_motions), the nodes joining their caps
        (_joining: number, x, v), all in global numbering, and the surface normals of the
        caps' faces (core.surface_normals, after this step's breaks). One message per pair of
        neighbouring ranks (_pack); what it has no room for goes in a second. The receives are
        posted first; _receive_within_step waits for them, after the rank's bond forces
        (core.evaluate_bonds), which need nothing of them."""
        core = self.local.core
        x, v = core.positions, core.velocities
        pairs = np.asarray([] if broken is None else broken, dtype=np.int64).reshape(-1, 2)
        bodies, rows = self._own_motions(broken is not None)
        touched = np.unique(pairs) if len(pairs) else pairs.ravel()
        faces = self._faces_out
        normals = core.surface_normals(faces) if broken is not None else np.zeros((len(faces), 3))
        requests = [self.comm.Irecv(box, source=q, tag=_TAG) for q, box in self._inbox.items()]
        overflow, joined = [], {}
        for q, nodes in self._send.items():
            theirs = self._to_global[pairs[self._sent_to[q][pairs[:, 0]]]] if len(pairs) else pairs
            joined[q] = self._joining(q, touched)
            joining = _joining_rows(self._to_global, joined[q], x, v)
            box = self._outbox[q]
            sections = [theirs, bodies[rows[q]], joining]
            fields = (x[nodes], v[nodes], normals[self._face_rows[q]])
            used, rest = _pack(box, fields, sections, self._rooms_out[q])
            requests.append(self.comm.Isend(box[:used], dest=q, tag=_TAG))
            if len(rest):
                overflow.append(self.comm.Isend(rest, dest=q, tag=_REST_TAG))
                self.second_messages += 1
        return _Exchange(requests, overflow, joined)

    def _receive_within_step(
        self, exchange: _Exchange
    ) -> tuple[
        NDArray[np.uint32],
        tuple[NDArray[np.uint32], NDArray[np.float64]],
        tuple[NDArray[np.uint32], NDArray[np.float64]],
    ]:
        """The step's exchange (_send_within_step) completed: the ghosts' copies overwritten
        with what their owners sent (the caps growing by the nodes that joined). The ghosts'
        breaks, as (k, 2) local node pairs, their bodies' motions (first nodes, local; (k, 15)
        motions) for core.give_ghost_motions, and the faces' normals (nodes, local; (k, 3)
        normals) for core.give_ghost_surface_normals."""
        core = self.local.core
        x, v = core.positions, core.velocities
        start = time.perf_counter()
        self.mpi.Request.Waitall(exchange.requests)
        self.waiting += time.perf_counter() - start
        received = {q: self._unpack(q, nodes, (x, v)) for q, nodes in self._receive.items()}
        self.nodes_received += self.exchanged_node_count
        self.normals_received += self.exchanged_normal_count
        self.mpi.Request.Waitall(exchange.overflow)
        given = np.concatenate([np.zeros((0, 3)), *(n for _, _, _, n in received.values())])
        self._grow_caps(exchange.joined, {q: joining for q, (_, _, joining, _) in received.items()})
        motions = np.concatenate([np.zeros((0, _BODY)), *(m for _, m, _, _ in received.values())])
        first = self._ghost_firsts(motions[:, 0])
        breaks = (b for b, _, _, _ in received.values())
        ghost_breaks = np.concatenate([np.zeros((0, 2), np.int64), *breaks])
        return (
            self._node_map[ghost_breaks].astype(np.uint32),
            (first, np.ascontiguousarray(motions[:, 1:])),
            (self._faces_in, given),
        )

    def _joining(self, q: int, touched: NDArray[np.int64]) -> NDArray[np.int64]:
        """The own nodes that join the cap rank q receives in this step: the anchors now
        (core.contact_anchors, after this step's breaks) of its nodes among `touched` (those
        whose bonds broke in this step, which may have taken new anchors) that it lacks."""
        mine = touched[self._in_send[q][touched]]
        if len(mine) == 0:
            return mine
        anchors = np.asarray(self.local.core.contact_anchors(mine.tolist()), dtype=np.int64)
        return anchors[~self._in_send[q][anchors]]

    def _ghost_firsts(self, nodes: NDArray[np.float64]) -> NDArray[np.uint32]:
        """The local numbers of the ghost fragments' first nodes (`nodes`, global, as a step's
        messages carry them), as core.give_ghost_motions takes them. They change only when a
        grain breaks or the grains are distributed anew (_plan forgets it), so the last answer
        is kept."""
        if not np.array_equal(self._firsts_of, nodes):
            self._firsts = self._node_map[nodes.astype(np.int64)].astype(np.uint32)
            self._firsts_of = nodes.copy()
        return self._firsts

    def _grow_caps(
        self, sent: dict[int, NDArray[np.int64]], received: dict[int, NDArray[np.int64]]
    ) -> None:
        """The nodes that joined the caps in this step's messages (`sent`, `received`: local
        nodes per rank, in the order of the message) are in them from now on, at their ends,
        and the messages' buffers grow for them."""
        for q, joined in sent.items():
            if len(joined):
                self._send[q] = np.concatenate([self._send[q], joined])
                self._in_send[q][joined] = True
                self._outbox[q] = self._message_out(q)
        for q, joined in received.items():
            if len(joined):
                self._receive[q] = np.concatenate([self._receive[q], joined])
                self._inbox[q] = self._message_in(q)
                self.nodes_joined += len(joined)

    def _own_motions(
        self, measured: bool
    ) -> tuple[NDArray[np.float64], dict[int, NDArray[np.bool_]]]:
        """(bodies, 16): every fragment of the grains this rank sends, its first node (global)
        and its motion now (core.fragment_motions), with per receiving rank the rows of its
        grains; none unless `measured` (the step failed before)."""
        if not measured:
            return np.zeros((0, _BODY)), {q: np.zeros(0, bool) for q in self._send}
        nodes, numbers = self.local.core.fragment_motions(self._motion_particles)
        nodes = np.asarray(nodes, dtype=np.int64)
        particle = self._node_particle[nodes]
        motions = np.empty((len(nodes), _BODY))
        motions[:, 0] = self._to_global[nodes]
        motions[:, 1:] = np.asarray(numbers).reshape(-1, _BODY - 1)
        return motions, {q: mask[particle] for q, mask in self._particle_to.items()}

    def _unpack(
        self, q: int, nodes: NDArray[np.int64], fields: tuple[NDArray[np.float64], ...]
    ) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.int64], NDArray[np.float64]]:
        """Rank q's message of this step into the ghosts' `fields`, and the nodes joining its
        cap (local, their x and v into `fields` too); its breaks, (k, 2) global node pairs,
        bodies' motions, (k, 16) (with what the message had no room for, received now from the
        second message), the joining nodes, and its faces' normals, (k, 3)."""
        box = self._inbox[q]
        count = 6 * len(nodes)
        motion = box[:count].reshape(-1, 6)
        for k, field in enumerate(fields):
            field[nodes] = motion[:, 3 * k : 3 * k + 3]
        normals = box[count : count + 3 * len(self._receive_faces[q])].reshape(-1, 3)
        count += normals.size
        totals = [int(total) for total in box[count : count + len(_WIDTHS)]]
        kept = [min(total, room) for total, room in zip(totals, self._rooms_in[q], strict=True)]
        missing = [total - k for total, k in zip(totals, kept, strict=True)]
        rest = _NO_REST
        if any(missing):
            rest = np.empty(_numbers(missing))
            self.comm.Recv(rest, source=q, tag=_REST_TAG)
        breaks, bodies, joining = _sections(box[count + len(_WIDTHS) :], kept, rest, missing)
        joined = self._node_map[joining[:, 0].astype(np.int64)]
        for k, field in enumerate(fields):
            field[joined] = joining[:, 1 + 3 * k : 4 + 3 * k]
        return breaks.astype(np.int64), bodies, joined, normals

    def run(self, steps: int) -> None:
        """Advance every rank `steps` time steps, migrating grains before a step once a node
        may have moved a quarter of the margin, and picking the caps anew within a step whose
        drift took a node farther than half the cap margin from where it was when they were
        picked (_caps_hold). Raises InputError (on every rank) when a node may have moved
        more than half the margin: the ghosts would no longer be enough. An error in one
        rank's step ends every rank: that rank raises its own, the others RankFailed naming
        it (no rank is left waiting for a message)."""
        self._sim._ranks_ahead |= steps > 0  # rank 0's simulation until it takes the state
        for _ in range(steps):
            if self._migration_due:  # before the step, so the parts hold its evaluation after
                self.migrate()
            self._step()

    def refresh_caps(self) -> None:
        """Pick the caps anew (_exchange_caps) where the nodes are now, after making every
        ghost its owner's grain (_exchange_state); the travel since is measured afresh, and
        the farthest a node has moved since the grains were distributed, which the next
        migration waits for, exactly. Between steps, or within one after
        its drift (_caps_hold): the ghosts then take their owners' half-step velocities and
        last forces, which only their caps' motion reads before the next exchange."""
        start = time.perf_counter()
        self._exchange_state()
        self._travelled = self._travel_since_distributed()
        self._widen_cap_margin()
        self._exchange_caps()
        self.cap_refreshes += 1
        self.seconds["caps"] += time.perf_counter() - start

    def _step(self) -> None:
        """One step: its first half (core.begin_step), the exchange of the ghosts' motion and
        breaks posted, the bond forces (core.evaluate_bonds, which read no ghost) while it is
        under way, the exchange completed, the rest of the step (core.finish_step: the ghosts'
        breaks, contact) and the check. Every rank goes through the exchange and the check
        whatever failed, so that none waits for another."""
        core = self.local.core
        times = [time.perf_counter()]
        failure, broken = None, None
        try:
            broken = core.begin_step()
        except Exception as error:  # re-raised by the check, after the ranks agree to stop
            failure = error
        times.append(time.perf_counter())
        if self.caps_partial:
            self._caps_hold(failure is None)
        times.append(time.perf_counter())
        exchange = self._send_within_step(broken)
        times.append(time.perf_counter())
        messages = exchange.requests + exchange.overflow
        failure, testing = while_travelling(self.mpi, messages, core.evaluate_bonds, failure)
        times.append(time.perf_counter())
        ghost_breaks, motions, faces = self._receive_within_step(exchange)
        times.append(time.perf_counter())

        def finish() -> None:
            core.give_ghost_motions(*motions)
            core.give_ghost_surface_normals(*faces)
            core.finish_step(ghost_breaks)

        failure = attempt(finish, failure)
        times.append(time.perf_counter())
        farthest = self._check_step(int(core.step), failure)
        self._loaded_walls = None
        self._migration_due = self._migrates and self._travelled + farthest > 0.25 * self.margin
        if self._sim.load_balance.due(int(core.step)):
            self._check_balance()
        spans = np.diff(times)  # begin, caps' check, send, bonds, receive, finish
        self.seconds["steps"] += spans[0] + spans[3] - testing + spans[5]
        self.seconds["exchange"] += spans[2] + testing + spans[4]
        self.seconds["check"] += time.perf_counter() - times[-1]

    def _caps_hold(self, moved: bool) -> None:
        """Within a step, once its drift has moved the nodes (`moved`: begin_step did not
        fail): one reduction of the largest distance of a node from where it was when the caps
        were picked (core.largest_travel) and whether a rank's step failed; past half the cap
        margin, and none failed, the caps are picked anew here, before the step's exchange and
        contact (refresh_caps), so that a ghost node outside them never comes within the
        cutoff of an own node however far a step moves them."""
        start = time.perf_counter()
        first_failed, farthest = self._first_failed_and_farthest(not moved)
        self.seconds["check"] += time.perf_counter() - start
        if farthest > 0.5 * self.cap_margin and first_failed == self.comm.Get_size():
            self.refresh_caps()

    def _first_failed_and_farthest(self, failed: bool) -> tuple[int, float]:
        """One reduction: the first rank that `failed` (the number of ranks if none) and the
        largest core.largest_travel over the others [m]."""
        travel = 0.0 if failed else float(self.local.core.largest_travel)
        mine = np.array([self.comm.Get_rank() if failed else self.comm.Get_size(), -travel])
        least = np.empty(2)
        self.comm.Allreduce(mine, least, op=self.mpi.MIN)  # elementwise minima: both in one
        return int(least[0]), -float(least[1])

    def _check_step(self, step: int, failure: Exception | None) -> float:
        """One reduction after each step: the first rank whose step failed, and the largest
        distance of an own node from where it was when the caps were picked
        (core.largest_travel, measured once the step moved the nodes). Stops every rank on
        either, and when a node may have moved more than half the margin since the grains were
        distributed (at most that distance plus how far one was from there when the caps were
        picked); returns that distance [m]."""
        first_failed, farthest = self._first_failed_and_farthest(failure is not None)
        if failure is not None:
            raise failure
        if first_failed < self.comm.Get_size():
            raise RankFailed(f"step {step}: rank {first_failed} failed; every rank stops")
        travelled = self._travelled + farthest  # since the grains were distributed, at most
        if travelled > 0.5 * self.margin:
            advice = (
                "a node moved that far within one distribution of the grains; give "
                "DistributedRun a larger margin"
                if self._migrates
                else "grains migrate only with migrate=True; give DistributedRun a larger "
                "margin, or let it migrate"
            )
            raise InputError(
                f"step {step}: a node may have moved {travelled:.3g} m from where the grains "
                f"were distributed, more than half the ghost margin ({self.margin:.3g} m): "
                f"{advice}"
            )
        return farthest

    def _check_balance(self) -> None:
        """Whether the ranks' work (work_load.py: each rank's own nodes, intact bond copies and
        contact list entries; one allgather) has drifted out of balance: the most loaded rank
        over the simulation's load_balance.threshold times the mean, and over that times what
        the last cut left it (so that grains too heavy to share out do not cut again and
        again). Then the next step begins with a migration. Not without migrate, nor with one
        already due."""
        if not self._migrates or self._migration_due:
            return
        start = time.perf_counter()
        work = self.owned_work()
        loads = _weighed(self.comm.allgather((work, self._step_scale(work))))
        self.work_imbalance = imbalance(np.array(loads))
        self.balance_checks += 1
        limit = self._sim.load_balance.threshold * max(1.0, self._left_imbalance)
        self._rebalance_due = self.work_imbalance > limit
        self._migration_due = self._rebalance_due
        self._clock.restart(self.seconds["steps"], int(self.local.core.step), work)
        self.seconds["check"] += time.perf_counter() - start

    def owned_work(self) -> float:
        """This rank's work now: work_load.node_work summed over its own nodes."""
        return float(node_work(self.local.core, self._owned_nodes, self._sim.dimension).sum())

    def _step_scale(self, work: float) -> float | None:
        """Under LoadBalance(weight="time"), this rank's step seconds a step per unit of its
        work `work` (StepClock; None before a step was timed); None under weight "work"."""
        if self._sim.load_balance.weight != "time":
            return None
        return self._clock.scale(self.seconds["steps"], int(self.local.core.step), work)

    def _grain_work(self) -> tuple[NDArray[np.float64], float]:
        """Every grain's work now (work_load.node_work summed over its nodes; under
        LoadBalance(weight="time") times its rank's step seconds per unit of work), on every
        rank: each owner's grains (one allgather); and this rank's own work by the counts
        (owned_work)."""
        work = node_work(self.local.core, self._owned_nodes, self._sim.dimension)
        sizes = [self._slices[g].stop - self._slices[g].start for g in self._owned]
        mine = np.add.reduceat(work, np.cumsum([0, *sizes[:-1]]))
        own = float(mine.sum())
        parts = self.comm.allgather((self._owned, mine, self._step_scale(own)))
        weighed = _weighed([(theirs, scale) for _, theirs, scale in parts])
        weights = np.empty(len(self._slices))
        for (grains, _, _), theirs in zip(parts, weighed, strict=True):
            weights[grains] = theirs
        return weights, own

    def migrate(self) -> None:
        """Cut the assembly anew where the grains are now (recursive coordinate bisection of
        their current bounding spheres, weighted by their work: work_load.py), which also
        rebalances the ranks; a migration for the balance (_check_balance) does not widen the
        margin. A rank that now holds other grains than before, or owns one it held as a
        ghost, builds its part anew from the owners' states of them (transplant.py): of a
        ghost only the caps move with its owner (_exchange_caps), so its contacts with the
        other ghosts are not the serial run's. A rank that holds the same grains and owns no
        new one keeps its part; every ghost's positions, velocities and forces are made their
        owners' first, and the caps are picked anew. Either way the run goes on as the serial
        run, bit for bit."""
        start = time.perf_counter()
        for_balance, self._rebalance_due, self._migration_due = self._rebalance_due, False, False
        if not for_balance:
            self._widen_margin()
        self._exchange_state()
        before, owners_before = self._held_by_rank(), self.partition.owner
        positions = self.local.core.positions
        layout = self._gathered_layout(self._owned, lambda g: positions[self.local_slice(g)])
        self._weights, own_work = self._grain_work()
        self._clock.restart(self.seconds["steps"], int(self.local.core.step), own_work)
        held = self._distribute(*layout)
        self._left_imbalance = imbalance(self.partition.loads(self._weights))
        if for_balance:
            self.rebalance_steps.append(int(self.local.core.step))
        self.handed_over += int(np.count_nonzero(self.partition.owner != owners_before))
        after = self._held_by_rank()
        owner = self.partition.owner
        renewed = [  # a ghost that becomes owned needs its contacts with the other ghosts
            self.always_renew
            or not np.array_equal(old, new)
            or bool(np.any((owner[new] == q) & (owners_before[new] != q)))
            for q, (old, new) in enumerate(zip(before, after, strict=True))
        ]
        rank = self.comm.Get_rank()
        wanted = [
            np.intersect1d(after[q], self._owned) if renewed[q] else np.zeros(0, np.int64)
            for q in range(self.comm.Get_size())
        ]
        if any(renewed):
            self._hand_over(held, wanted, renewed[rank])
        else:
            self._plan(self._node_map)
        self._exchange_caps()
        self.migrations += 1
        self.seconds["migrate"] += time.perf_counter() - start

    def _travel_since_distributed(self) -> float:
        """The largest distance of a node from where it was when the grains were distributed
        [m], over every rank (one reduction)."""
        moved = self.local.core.positions[self._owned_nodes] - self._distributed_positions
        farthest = float(np.sqrt((moved**2).sum(axis=1).max(initial=0.0)))
        return float(self.comm.allreduce(farthest, op=self.mpi.MAX))

    def _widen_cap_margin(self) -> None:
        """The default cap margin doubled, up to the margin, when the caps being picked anew
        lasted fewer than short_cap_period steps (the same on every rank: the steps are)."""
        lasted = int(self.local.core.step) - self._caps_picked_at
        if self._adapt_caps and lasted < self.short_cap_period and self.cap_margin < self.margin:
            self.cap_margin = min(2 * self.cap_margin, self.margin)
            self.cap_margin_widenings += 1

    def _widen_margin(self) -> None:
        """The default margin doubled, up to widest_margin grain radii, when the grains' last
        distribution lasted fewer than short_distribution steps (the same on every rank: the
        steps are)."""
        lasted = int(self.local.core.step) - self._distributed_at
        if lasted < self.short_distribution and self.margin < self._widest:
            self.margin = min(2 * self.margin, self._widest)
            self.margin_widenings += 1

    def _held_by_rank(self) -> list[NDArray[np.int64]]:
        """The grains each rank holds (owned and ghosts), sorted."""
        return [
            np.union1d(self.partition.grains_of(q), self.ghosts[q])
            for q in range(self.comm.Get_size())
        ]

    def _gathered_layout(
        self, grains: NDArray[np.int64], nodes_of: Callable[[int], NDArray[np.float64]]
    ) -> tuple[Any, ...]:
        """What _distribute reads (_layout), on every rank: each grain measured by the one
        rank that has it among its `grains` (nodes_of(g): grain g's nodes' positions now),
        its bounding sphere and, with PeriDEM's damping, where its centre node is; then each
        large body's pairs found by that rank (two allgathers)."""
        dimension = self._sim.dimension
        mine = _spheres([nodes_of(int(g)) for g in grains], dimension)
        points = None
        if self._damped_centres is not None:
            points = [self._centre_point(int(g), nodes_of(int(g))) for g in grains]
        centres = np.empty((len(self._slices), dimension))
        radii = np.empty(len(self._slices))
        damped = None if points is None else np.empty((len(self._slices), dimension))
        for theirs, spheres, their_points in self.comm.allgather((grains, mine, points)):
            centres[theirs], radii[theirs] = spheres
            if damped is not None and len(theirs):
                damped[theirs] = their_points
        large = {int(g): nodes_of(int(g)) for g in np.intersect1d(self._large, grains)}
        everyone = self.comm.allgather(self._pairs_of_large(centres, radii, large))
        pairs = tuple(np.concatenate([theirs[k] for theirs in everyone]) for k in (0, 1))
        return centres, radii, damped, pairs

    def _hand_over(
        self, held: NDArray[np.int64], wanted: list[NDArray[np.int64]], renew: bool
    ) -> None:
        """Send each rank the states of the grains it `wanted` of this rank's own; with
        `renew`, build this rank's part of the grains it now `held` from the states received."""
        core = self.local.core
        giving = np.unique(np.concatenate(wanted))
        saved = dict(core.checkpoint()) if renew or len(giving) else {}
        owned = dict(zip(giving.tolist(), self.local_slices(giving), strict=True))
        states = grain_states(self.local, saved, self._to_global, owned) if owned else {}
        outgoing = [{int(g): states[int(g)] for g in grains} for grains in wanted]
        received: dict[int, GrainState] = {}
        for box in self.large.alltoall(outgoing):
            received |= box
        if not renew:
            together(self.comm, lambda: self._plan(self._node_map))
            return
        together(self.comm, lambda: self._rebuild(held, received, saved))
        self.renewals += 1

    def _rebuild(
        self, held: NDArray[np.int64], states: dict[int, GrainState], moment: dict[str, Any]
    ) -> None:
        """This rank's part made anew of the grains `held`, from their `states` at `moment`
        (the time, step and contact scalars of a checkpoint)."""
        with warnings.catch_warnings():  # the start checks were made when the run was set up
            warnings.simplefilter("ignore")
            local, node_map = self._sim._subdomain(
                held, dt=self._dt, skin=self._skin, initial_motion=False
            )
            restore_grains(local.core, [states[int(g)] for g in held], node_map, moment)
        self.local, self.held = local, held
        self._plan(node_map)

    def fingerprint(self) -> str:
        """The set-up's fingerprint (Simulation.fingerprint), on every rank: each rank hashes
        the grains it owns (fingerprints.grain_digest; one gather, once per run), rank 0 puts
        the digests together in grain order."""
        if self._setup_digest is None:
            slices = self.owned_slices()
            mine = (self._owned, fingerprints.model_grain_digests(self.local.model, slices))
            parts = self.comm.gather(mine, root=0)

            def digest() -> str:
                assert parts is not None
                size = fingerprints.GRAIN_DIGEST_BYTES
                every = np.empty((len(self._slices), size), np.uint8)
                for grains, digests in parts:
                    every[grains] = np.frombuffer(digests, np.uint8).reshape(-1, size)
                return fingerprints.set_up_digest(self._sim, every.tobytes())

            self._setup_digest = str(self.comm.bcast(on_root(self.comm, digest), root=0))
        return fingerprints.fingerprint(self._sim, self._setup_digest, self.dt)

    def checkpoint_part(self) -> tuple[dict[str, Any], dict[int, GrainState]]:
        """This rank's part of a checkpoint now (every rank together): the moment (the time,
        step and contact scalars, transplant.moment_of, with the whole run's wall reactions and
        deepest overlaps) and the states of the grains it owns."""
        saved = dict(self.local.core.checkpoint())
        saved["contact_wall_reactions"] = self.wall_reactions().ravel()  # the whole run's
        deepest = self.deepest_contact()
        saved["contact_overlaps"] = np.array(
            [deepest.deepest_overlap, deepest.half_overlap_step, deepest.full_overlap_step],
            dtype=float,
        )
        owned = dict(zip(self._owned.tolist(), self.owned_slices(), strict=True))
        return moment_of(saved), grain_states(self.local, saved, self._to_global, owned)

    def save_checkpoint(self, path: str | os.PathLike[str], outputs: Outputs | None = None) -> Path:
        """Write the run's checkpoint at `path` in pieces (checkpoint_pieces.py, with the
        bookkeeping of `outputs`): each rank its own grains' states, rank 0 the header. It
        restarts on any number of ranks (load_checkpoint), or serially, bit for bit. Every rank
        calls it; an error on one rank ends every rank. The path written, on every rank."""
        return checkpoint_pieces.save(self, path, outputs)

    def load_checkpoint(self, path: str | os.PathLike[str], outputs: Outputs | None = None) -> None:
        """Continue from a checkpoint of this set-up written by a run on any number of ranks, or
        by a serial run (else InputError on every rank). Rank 0 reads its header; of a
        checkpoint in pieces each rank reads some pieces, of a whole one (a serial run's) rank
        0 reads every grain. The grains are cut anew where they are, each goes to the ranks
        that hold it, and each rank builds its part of them; rank 0 then takes `outputs`'
        bookkeeping from it. Every rank calls it."""
        fingerprint = self.fingerprint()
        start = time.perf_counter()
        states: dict[int, GrainState] = {}

        def read() -> tuple[dict[str, Any], dict[str, Any], NDArray[np.int64] | None]:
            return self._read_checkpoint(path, fingerprint, states)

        header, moment, piece_of_grain = self.comm.bcast(on_root(self.comm, read), root=0)
        if piece_of_grain is not None:
            ranks, rank = self.comm.Get_size(), self.comm.Get_rank()
            mine = list(range(rank, header["pieces"]["count"], ranks))

            def read_mine() -> None:
                states.update(checkpoint_pieces.read_pieces(path, header, piece_of_grain, mine))

            together(self.comm, read_mine, "reading its pieces of the checkpoint")
        self._rebuild_from(states, moment)
        on_root(self.comm, lambda: checkpoints.resume_outputs(path, header, outputs))
        self._sim._ranks_ahead |= piece_of_grain is not None  # rank 0 read the header only
        self._exchange_caps()
        self._loaded_walls = np.asarray(moment["contact_wall_reactions"]).reshape(-1, 6)
        self._migration_due = False
        self._left_imbalance = 1.0  # cut by the work the grains had before
        self._check_balance()
        self.seconds["migrate"] += time.perf_counter() - start

    def _read_checkpoint(
        self, path: str | os.PathLike[str], fingerprint: str, states: dict[int, GrainState]
    ) -> tuple[dict[str, Any], dict[str, Any], NDArray[np.int64] | None]:
        """Rank 0: the checkpoint at `path`'s header, its moment (transplant.moment_of) and the
        piece of each grain; or, of a whole checkpoint (None for the pieces), every grain's
        state into `states`, through rank 0's whole simulation (which then holds it)."""
        state, header = checkpoints.read(path, fingerprint)
        if "pieces" in header:
            return header, moment_of(state), np.asarray(state["piece_of_grain"])
        sim = self._sim
        sim._ranks_ahead = False  # it takes the whole state itself
        with warnings.catch_warnings():  # the start checks were made when the run was set up
            warnings.simplefilter("ignore")
            sim.core.restore(state)
        sim.analysis.forget_fragments()
        sim._gathered = None  # the evaluation gathered before is not the checkpoint's
        saved = dict(sim.core.checkpoint())
        every = {g: self._slices[g] for g in range(len(self._slices))}
        states.update(grain_states(sim, saved, np.arange(self._node_count), every))
        return header, moment_of(saved), None

    def _rebuild_from(self, states: dict[int, GrainState], moment: dict[str, Any]) -> None:
        """Every rank: the grains cut anew where `states` (the grains' states this rank read,
        each grain's on one rank) put them, each state sent to the ranks that hold its grain
        (one all-to-all), and this rank's part built of them at `moment`."""
        grains = np.array(sorted(states), dtype=np.int64)
        held = self._distribute(*self._gathered_layout(grains, lambda g: states[g].positions))
        outgoing = [
            {int(g): states[int(g)] for g in np.intersect1d(held_there, grains)}
            for held_there in self._held_by_rank()
        ]
        states.clear()
        received: dict[int, GrainState] = {}
        for box in self.large.alltoall(outgoing):
            received |= box
        together(self.comm, lambda: self._rebuild(held, received, moment))

    def write_piece(self, folder: Path, fields: tuple[str, ...]) -> None:
        """This rank's piece of a frame in pieces (writers/vtu_frame.py): its own nodes now,
        with `fields`, numbered as the whole run numbers them, as folder/piece_<rank>.vtu."""
        numbering = (self._to_global, self.held)
        path = Path(folder) / f"piece_{self.comm.Get_rank()}.vtu"
        write_piece(path, self.local, fields, self._owned_nodes, numbering)

    def wall_reactions(self) -> NDArray[np.float64]:
        """(walls, 6): the force and torque on each wall from the last step [N, N m; per unit
        thickness in 2D], on every rank, the serial run's to the bit. Each term comes from the
        rank that owns its body or node (ContactModel::wall_slot_terms) and rank 0 sums them in
        the serial order: the dashpots' per slot in body order, less the rolling couples in the
        same order, plus the wall entries' reactions in node order."""
        if self._loaded_walls is not None:
            return self._loaded_walls.copy()
        core = self.local.core
        slots, terms, reactions = (np.asarray(a) for a in core.wall_reaction_terms())
        slots, terms = slots.reshape(-1, 2).astype(np.int64), terms.reshape(-1, 9)
        offsets, rows, keys = wall_lists(core)
        evaluated = len(terms) == len(slots) and len(reactions) == 6 * len(rows)
        if not self.comm.allreduce(evaluated, op=self.mpi.LAND):
            raise RuntimeError(
                "wall reactions are known once a step has evaluated them on the parts built in "
                "the last migration: run a step first"
            )
        first = body_first_nodes(self.local)[slots[:, 0]]
        mine = self._is_owned[first]
        kept = self._is_owned[rows]
        place = np.arange(len(rows)) - offsets[rows]  # an entry's place among its node's
        parts = self.large.gather(
            (
                np.column_stack([self._to_global[first[mine]], slots[mine, 1]]),
                terms[mine],
                np.column_stack([self._to_global[rows[kept]], place[kept], keys[kept, 0]]),
                reactions.reshape(-1, 6)[kept],
            ),
            root=0,
        )
        walls = len(core.wall_reactions())
        total = on_root(self.comm, lambda: _sum_wall_terms(parts, walls))
        return self.comm.bcast(total, root=0)

    def step_data(
        self, tracked: tuple[int, ...], frame: tuple[str, ...] | None = None
    ) -> StepData | None:
        """Every rank: the current output step made of what each rank measures of its own
        grains (step_parts.py), with the sums of the `tracked` grains and, for a frame of
        every node with the fields `frame`, each rank's rows of its own nodes, joined in node
        order (StepData.frame_rows); on rank 0 (None on the others): rank 0's simulation is
        not built for it."""
        start = time.perf_counter()
        walls = self.wall_reactions()
        broken = self.broken_bonds()
        part = together(self.comm, lambda: step_part(self, tracked), "measuring its grains")
        parts = self.comm.gather(part, root=0)
        rows = None if frame is None else self._frame_rows(frame)
        data = on_root(self.comm, lambda: step_data(self._sim, self, parts, broken, walls, rows))
        self.seconds["collect"] += time.perf_counter() - start
        return data

    def _frame_rows(self, fields: tuple[str, ...]) -> NodeRows | None:
        """Every rank: its own nodes' rows of a frame with `fields`, sent to rank 0, which
        joins them in node order (None on the others)."""
        numbering = (self._to_global, self.held)
        mine = together(
            self.comm,
            lambda: node_rows(self.local, fields, self._owned_nodes, numbering),
            "measuring its nodes",
        )
        parts = self.large.gather(mine, root=0)
        return on_root(self.comm, lambda: NodeRows.joined(parts, self._node_count))

    def collect(self, measures: bool = True) -> None:
        """Every rank: rank 0's simulation (the one the run was made of, built whole on the
        first call) takes every grain's state and the last step's contacts, contact energy
        and counts and wall reactions, in the serial order (whole_state.py): its outputs,
        measures and stop criteria are then the serial run's at this step. With `measures`
        (for outputs), each rank also measures its grains (damage, fragments, strain energy,
        motion: analysis.GivenMeasures), which rank 0's analysis then takes. An error on
        any rank (rank 0's whole simulation too large for its memory, say) ends every rank:
        InputError with the same message, else that rank's error and RankFailed."""
        start = time.perf_counter()
        walls = self.wall_reactions()
        part = together(self.comm, lambda: owned_part(self, measures), "measuring its grains")
        parts = self.large.gather(part, root=0)
        moment = (float(self.local.core.time), int(self.local.core.step))
        on_root(self.comm, lambda: install(self._sim, parts, moment, walls))
        self.seconds["collect"] += time.perf_counter() - start

    def deepest_contact(self) -> SimpleNamespace:
        """The deepest contact overlap (over the contact radius) of every rank so far, and the
        first steps at which any rank's passed 0.5 and 1 (0: not yet), as the core's
        contact_statistics name them (one reduction)."""
        statistics = self.local.core.contact_statistics
        never = float(2**53)
        mine = np.array(
            [
                -statistics.deepest_overlap,
                statistics.half_overlap_step or never,
                statistics.full_overlap_step or never,
            ]
        )
        least = np.empty(3)
        self.comm.Allreduce(mine, least, op=self.mpi.MIN)
        half, full = (int(step) if step < never else 0 for step in least[1:])
        return SimpleNamespace(
            deepest_overlap=-float(least[0]), half_overlap_step=half, full_overlap_step=full
        )

    def measures(self) -> RankMeasures:
        """What the stop criteria read (stopping.RunMeasures), from each rank's own grains."""
        return RankMeasures(self.comm, self.local, self._owned_nodes, self.held, self.broken_bonds)

    @property
    def bond_count(self) -> int:
        """Every grain's bonds, counted once per end (Simulation.bond_count), on every rank
        (counted when the run was made: bonds break, they never go)."""
        return self._bond_count

    def _count_bonds(self) -> int:
        """Every grain's bonds, counted once per end (one reduction)."""
        offsets = np.asarray(self.local.model.bond_offsets, dtype=np.int64)
        mine = sum(int(offsets[s.stop] - offsets[s.start]) for s in self.owned_slices())
        return int(self.comm.allreduce(mine))

    def broken_bonds(self) -> int:
        """The broken bonds of every grain, each counted once, on every rank (one reduction)."""
        core = self.local.core
        copies = sum(core.broken_bond_copies(s.start, s.stop) for s in self.owned_slices())
        return int(self.comm.allreduce(copies)) // 2

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
        parts = self.large.gather((self._owned, mine), root=root)
        if parts is None:
            return None
        whole = np.empty((self._node_count, 3))
        for grains, values in parts:
            whole[self._nodes_of(grains)] = values
        return whole


def contact_reads(core: Any, near: NDArray[np.int64]) -> NDArray[np.int64]:
    """The nodes whose positions and velocities the contact reads of the nodes `near` (within
    reach of another body, as the lists see them): those and their anchors now
    (core.contact_anchors); sorted, each once. What a cap holds (_exchange_caps); the surface
    normals of those within the normal reach, sums over their bonds, travel as normals."""
    read = (near, core.contact_anchors(near.tolist()))
    return np.unique(np.concatenate([np.asarray(r, dtype=np.int64) for r in read]))


def _faces(model: Any, normal: NDArray[np.int64], cap: NDArray[np.int64]) -> NDArray[np.int64]:
    """Of a cap's nodes within the normal reach, `normal`, those whose surface normals travel:
    the ones bonded to a node outside the `cap` (Model.bonded_beyond), whose sums over their
    bonds the holder cannot make; it makes the others'."""
    return np.asarray(model.bonded_beyond(normal.tolist(), cap.tolist()), dtype=np.int64)


def _joining_rows(
    to_global: NDArray[np.int64],
    joined: NDArray[np.int64],
    x: NDArray[np.float64],
    v: NDArray[np.float64],
) -> NDArray[np.float64]:
    """A step message's rows for the nodes `joined` (local) joining a cap: global number, x
    and v, (k, 7)."""
    if len(joined) == 0:
        return _NO_JOINING
    return np.hstack([to_global[joined, None], x[joined], v[joined]])


def _message(nodes: int, faces: int, rooms: NDArray[np.int64]) -> NDArray[np.float64]:
    """A buffer for the largest step message about `nodes` nodes and `faces` normals (_pack):
    their x and v, the normals, the sections' counts, and each section's `rooms` rows."""
    return np.empty(6 * nodes + 3 * faces + len(_WIDTHS) + _numbers(rooms))


def _pack(
    box: NDArray[np.float64],
    fields: tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]],
    sections: list[NDArray[Any]],
    rooms: NDArray[np.int64],
) -> tuple[int, NDArray[np.float64]]:
    """A step's message: the nodes' x and v (`fields`' first two, 6 numbers a node), the
    faces' normals (the third, (m, 3)), then each section's row count, then each section's
    rows (breaks, (k, 2); bodies, (k, 16); nodes joining the cap, (k, 7)), up to its room;
    the numbers written, and the rows with no room (every section's, flat, in order) for a
    second message."""
    x, v, normals = fields
    count = 6 * len(x)
    motion = box[:count].reshape(-1, 6)
    motion[:, :3], motion[:, 3:] = x, v
    box[count : count + normals.size] = normals.ravel()
    count += normals.size
    box[count : count + len(sections)] = [len(rows) for rows in sections]
    start, rest = count + len(sections), []
    for rows, room in zip(sections, rooms, strict=True):
        if len(rows) == 0:  # most steps' breaks and joining nodes
            continue
        kept = rows[:room].ravel()
        box[start : start + kept.size] = kept
        start += kept.size
        if len(rows) > room:
            rest.append(rows[room:].ravel().astype(float))
    return start, np.concatenate(rest) if rest else _NO_REST


def _sections(
    carried: NDArray[np.float64], kept: list[int], rest: NDArray[np.float64], missing: list[int]
) -> list[NDArray[np.float64]]:
    """The sections of a step's message as _pack wrote them: `kept` rows of each from the
    message (`carried`, after the counts), then `missing` rows of each from the second
    message (`rest`); each (rows, width)."""
    parts, here, there = [], 0, 0
    for n, m, width in zip(kept, missing, _WIDTHS, strict=True):
        rows = carried[here : here + n * width]
        if m:
            rows = np.concatenate([rows, rest[there : there + m * width]])
        parts.append(rows.reshape(-1, width))
        here, there = here + n * width, there + m * width
    return parts


def _numbers(rows: Sequence[int] | NDArray[np.int64]) -> int:
    """The numbers that `rows` rows of each section of a step's message take."""
    return int(sum(n * width for n, width in zip(rows, _WIDTHS, strict=True)))


def _mask(size: int, indices: NDArray[np.int64]) -> NDArray[np.bool_]:
    """(size,) True at `indices`."""
    mask = np.zeros(size, dtype=bool)
    mask[indices] = True
    return mask


def _weighed(parts: list[tuple[Any, float | None]]) -> list[Any]:
    """Each rank's work (a number, or its grains' array) times its step scale
    (DistributedRun._step_scale) when every rank has one and it is positive, else as it is:
    one rule for every rank, from the same allgathered parts."""
    scales = [scale for _, scale in parts]
    if any(scale is None or not scale > 0 for scale in scales):
        return [work for work, _ in parts]
    return [work * scale for work, scale in parts]


def _sum_wall_terms(parts: list[tuple[NDArray[Any], ...]], walls: int) -> NDArray[np.float64]:
    """The ranks' wall terms (slot keys (first node, wall), slot terms, entry keys (node,
    place, wall), entry reactions) summed per wall in the serial order, one term at a time."""
    slot_keys, slot_terms, entry_keys, entry_terms = (
        np.concatenate([part[k] for part in parts]) for k in range(4)
    )
    total = np.zeros((walls, 6))
    by_slot = np.lexsort((slot_keys[:, 1], slot_keys[:, 0]))
    for k in by_slot:
        total[slot_keys[k, 1]] += slot_terms[k, :6]
    for k in by_slot:
        total[slot_keys[k, 1], 3:] -= slot_terms[k, 6:]
    for k in np.lexsort((entry_keys[:, 1], entry_keys[:, 0])):
        total[entry_keys[k, 2]] += entry_terms[k]
    return total


def _coarsest_of_each_material(sim: Simulation) -> NDArray[np.int64]:
    """Each material's coarsest grain (the largest mesh size; the first of a tie). A rank's
    time-step probe holds them besides its own grains, so that it knows every material's
    contact laws and its largest contact radius (ContactModel's coarsest mesh size per
    material), as the whole run does."""
    coarsest: dict[int, int] = {}
    for body in sim.bodies:
        best = coarsest.get(id(body.material))
        if best is None or body.mesh_size > sim.bodies[best].mesh_size:
            coarsest[id(body.material)] = body.index
    return np.array(sorted(coarsest.values()), dtype=np.int64)


def _check_grains_for_ranks(grains: int, ranks: int) -> None:
    """InputError when there are fewer grains than ranks: a run with contact gives each rank
    whole grains (a body is cut at node level only when nothing touches: node_split)."""
    if ranks > grains:
        raise InputError(
            f"{ranks} ranks for {grains} grain(s): a run with contact gives each rank whole "
            f"grains, so run it on at most {grains} rank(s); a body is cut across ranks at node "
            "level only when nothing touches (contact: null, no walls), as contact of a split "
            "body is not built yet"
        )


def _material_numbers(sim: Simulation) -> dict[int, int]:
    """The run's materials (by identity) numbered in the order its bodies first use them."""
    return {id(m): k for k, m in enumerate(materials_in_core_order(sim.bodies))}


def _built(part: Simulation) -> Simulation:
    """`part` with its core built."""
    part._build()
    return part


def _largest_free_radius(sim: Simulation, radii: NDArray[np.float64]) -> float:
    """The largest of `radii` (one per grain) of a grain none of whose nodes is prescribed (a
    wall particle's nodes move as they are told), or of all when every grain has such nodes."""
    held = sim._loading.prescribed()
    free = [body.index for body in sim.bodies if not held[body.node_slice].any()]
    return float((radii[free] if free else radii).max())


def _start_positions(sim: Simulation) -> Sequence[NDArray[np.float64]]:
    """Each grain's nodes' positions at the start: its start state when one is set, else the
    set-up's (Assembly.positions, a placed grain's computed when asked: neither joined into
    one array nor all kept at once, which would be 24 bytes a node of the whole run on every
    rank)."""
    if sim._start is not None:
        return [sim._start[0][body.node_slice] for body in sim.bodies]
    return sim._assembly.positions


def _spheres(
    grains: Sequence[NDArray[np.float64]], dimension: int
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Per grain (its nodes' positions) the centre of their box (its first `dimension`
    coordinates) and the radius of the sphere about it that holds them [m]."""
    centres = np.empty((len(grains), dimension))
    radii = np.empty(len(grains))
    for k, nodes in enumerate(grains):
        centre = 0.5 * (nodes.min(axis=0) + nodes.max(axis=0))
        centres[k], radii[k] = centre[:dimension], np.linalg.norm(nodes - centre, axis=1).max()
    return centres, radii
