"""Run under `mpiexec -n K python tests/mpi_check.py DIMENSION STEPS` (tests/test_mpi.py does):
the locality test's assembly (tests/assemblies.py: grains pressed into each other and thrown
at each other, friction, damping, the surface law), here also under gravity on a floor, run
serially on rank 0 (the others wait asleep: rank_zero.py) and distributed over the K ranks
(granulate.parallel.DistributedRun). Rank 0 compares the two bit for bit and prints one line;
the exit status is non-zero on any difference.

`... drum VARIANT STEPS [renew]` runs the checkpoint tests' tumbling drum (tests/assemblies.py:
four grains tumbling and breaking in a rotating drum with a lifter; VARIANT lattice, grid,
surface or rolling) the same way: the grains move far, so the ranks migrate them many times,
handing grains over with their bonds, collisions and friction springs (with `renew`, every
rank builds its part anew from the owners' states at every migration, rather than only when
the grains it holds change).

`... api VARIANT STEPS` sets the drum up with Simulation(comm=...) and runs it with its
outputs, checkpoints and a stop check, comparing the output folder and rank 0's simulation
with the serial run's, and continuing serially from the distributed checkpoint.

`... restart VARIANT STEPS` runs the drum on the K ranks to half the steps, saves a
checkpoint, and continues from it on K - 1 ranks (one rank fewer: a checkpoint restarts on
another number of ranks) and serially, comparing both ends with the serial run's bit for bit.

`... balance STEPS` compares discs at rest whose left half has more bonds a node
(uneven_horizons), which the ranks cut anew by their work before the first step.

`... fine STEPS MARGIN CAP_MARGIN [peridem]` compares finely meshed brittle discs (fine_discs)
thrown at each other, whose ghosts' caps are a small part of them, with those margins [m]
(with `peridem`, under PeriDEM's damping, on a slab that is a PeriDEM wall).

`... DIMENSION STEPS MARGIN compare` compares as the first form does, with that ghost margin
[m] and every rank building its part anew at every migration (a small margin: many).

`... DIMENSION STEPS MARGIN [migrate]` instead runs the distributed run alone with that ghost
margin [m], without migrating grains (or with), expecting every rank to stop with the
InputError that says the grains moved too far for it;
`... DIMENSION STEPS fail` blows up one rank's step and expects every rank to stop;
`... DIMENSION STEPS fail-start` (`fail-migration`) makes the last rank fail to build its part
at the start with a user's error (in a migration with a bug) and expects every rank to stop;
`... DIMENSION STEPS fail-whole` leaves rank 0 too little memory to build its whole simulation
when the ranks first gather the state into it, and expects every rank to stop with rank 0's
InputError; `... DIMENSION STEPS fail-room` makes rank 0's memory check of the whole model
fail when the drum set up with Simulation(comm=...) starts its run, and expects every rank to
stop with its InputError before the first step; `... DIMENSION STEPS fail-frame-room` does
so with rank 0's memory check of the frames of every node it joins of the ranks' rows;
`... DIMENSION STEPS fail-progress` gives the
drum's run a progress function that reads rank 0's simulation mid-run, and expects every rank
to stop with the InputError rank 0's simulation raises."""

from __future__ import annotations

import functools
import shutil
import sys
import tempfile
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from mpi4py import MPI

sys.path.insert(0, str(Path(__file__).parent))
import granulate as gr
from assemblies import RADIUS, assembly, layout, rock, tumbling_drum
from granulate import checkpoints, core_model, resources
from granulate.parallel import DistributedRun
from rank_zero import on_rank_0, wait_asleep
from run_folders import SEARCHES, differing, history


def set_up(dimension: int) -> gr.Simulation:
    """The locality assembly under gravity, on a floor just below its lowest grains."""
    centres, _ = layout(dimension)
    sim = assembly(dimension, np.arange(len(centres)))
    sim.gravity = (0.0, -9.81, 0.0)
    floor = centres[:, 1].min() - 0.99 * RADIUS
    sim.add_wall(gr.Wall(gr.Plane((0.0, floor, 0.0), (0.0, 1.0, 0.0))), name="floor")
    return sim


#: The fine discs: the 2D layout's first five rows of ten (of nine rows: half the time, with
#: every count tests/test_mpi.py asserts still past its bound).
FINE_GRAINS = 50


def fine_discs(peridem: bool = False, node_pairs: bool = False) -> gr.Simulation:
    """The 2D locality layout's first FINE_GRAINS grains as discs meshed finely (R/h = 12,
    horizon 3h: a ghost's caps are a small part of it), brittle, thrown at each other under
    gravity on a floor, placed 2.02 mm apart (the layout's pressed grains would overlap at
    this mesh). With
    `peridem`, PeriDEM's damping (--peridem-compat decks) acts between them, and the floor is
    a PeriDEM wall: a fixed slab of nodes that damps the grains near it. With `node_pairs`,
    PeriDEM's node-pair contact law (whose contact reads a node alone, not its bonded
    neighbours)."""
    centres, rows = layout(2)
    centres, rows = centres[:FINE_GRAINS] * (2.02 / 1.9), rows[:FINE_GRAINS]
    h = RADIUS / 12
    brittle = rock(3 * h, fracture_energy=0.01)
    sim = gr.Simulation(2, gravity=(0.0, -9.81, 0.0))
    law = "peridem" if node_pairs else "surface"
    sim.contact = gr.Contact(restitution=0.6, friction=0.5, pair_law=law)
    for centre, row in zip(centres, rows, strict=True):
        sim.add_body(gr.Disc(tuple(centre), row[0]), brittle, h, velocity=row[1:])
    floor = centres[:, 1].min() - 0.99 * RADIUS
    if not peridem:
        sim.add_wall(gr.Wall(gr.Plane((0.0, floor, 0.0), (0.0, 1.0, 0.0))), name="floor")
        return sim
    left, right = centres[:, 0].min() - RADIUS, centres[:, 0].max() + RADIUS
    slab = sim.add_body(gr.Rectangle((left, floor - 4 * h), (right, floor)), brittle, h)
    sim.fix(sim.select(body=slab))
    sim.set_peridem_damping(brittle, brittle, epsilon=0.9, beta_factor=100)
    sim.set_peridem_walls([slab])
    return sim


def uneven_horizons() -> gr.Simulation:
    """40 discs (0.99 mm, h = R/8) at rest on a floor, in rows of 10 on a hexagonal lattice
    2 mm apart: the left half of horizon 4.5 h, the right 3 h (2.25 times fewer bonds a node).
    Cut by nodes, the left half's rank has the more work (parallel/work_load.py)."""
    h = RADIUS / 8
    sim = gr.Simulation(2, gravity=(0.0, -9.81, 0.0))
    sim.contact = gr.Contact(restitution=0.5, friction=0.5)
    for k in range(40):
        row, column = divmod(k, 10)
        centre = (2 * RADIUS * (column + 0.5 * (row % 2)), np.sqrt(3) * RADIUS * row)
        horizon = (4.5 if column < 5 else 3.0) * h
        sim.add_body(gr.Disc(centre, 0.99 * RADIUS), rock(horizon), h)
    sim.add_wall(gr.Wall(gr.Plane((0.0, -0.99 * RADIUS, 0.0), (0.0, 1.0, 0.0))), name="floor")
    return sim


def splittable_grain() -> gr.Simulation:
    """A brittle disc of 4,301 nodes (R/h = 37: a splittable particle, whose contact sums are
    block sums added exactly) resting on a floor, struck by three discs of R/h = 8 at 6 m/s,
    two of them from the sides: it cracks (11,149 bonds break in 450 steps, 39 pieces), and its
    fragments touch the floor, the discs and each other."""
    h = RADIUS / 37
    brittle = rock(3 * h, fracture_energy=0.2)
    sim = gr.Simulation(2, gravity=(0.0, -9.81, 0.0))
    sim.contact = gr.Contact(restitution=0.5, friction=0.5)
    sim.add_body(gr.Disc((0.0, 0.0), RADIUS), brittle, h, discretization="conforming")
    small = RADIUS / 8
    for x, y, vx, vy in ((0.0, 2.02, 0.0, -6.0), (-2.02, 0.3, 6.0, 0.0), (2.02, 0.3, -6.0, 0.0)):
        centre = (x * RADIUS, y * RADIUS)
        sim.add_body(gr.Disc(centre, RADIUS), rock(3 * small), small, velocity=(vx, vy))
    floor = -RADIUS - 0.3 * h
    sim.add_wall(gr.Wall(gr.Plane((0.0, floor, 0.0), (0.0, 1.0, 0.0))), name="floor")
    return sim


DRUMS: dict[str, dict[str, Any]] = {
    "lattice": {},
    "grid": {"grid": True},
    "surface": {"grid": True, "law": "surface"},
    "rolling": {"rolling": 0.3},
}


def drum(variant: str, folder: Path) -> gr.Simulation:
    """The tumbling drum of tests/assemblies.py (its outputs planned in `folder`, not
    written: the runs here call the core)."""
    return tumbling_drum(folder, **DRUMS[variant])


def main() -> int:
    comm = MPI.COMM_WORLD
    warnings.filterwarnings("ignore", message="contact.*bodies pressed")  # placed pressed
    if sys.argv[1] == "restart":
        variant, steps = sys.argv[2], int(sys.argv[3])
        with tempfile.TemporaryDirectory() as folder:
            return check_restart(functools.partial(drum, variant, Path(folder)), steps, comm)
    if sys.argv[1] == "api":
        return check_api(sys.argv[2], int(sys.argv[3]), comm)
    if sys.argv[1] == "fine":
        steps, margin = int(sys.argv[2]), float(sys.argv[3])
        cap_margin = None if sys.argv[4] == "default" else float(sys.argv[4])
        peridem, node_pairs = "peridem" in sys.argv[5:], "node-pairs" in sys.argv[5:]
        return compare(
            functools.partial(fine_discs, peridem, node_pairs),
            " ".join(["fine", *sys.argv[5:]]),
            steps,
            comm,
            margin=margin,
            cap_margin=cap_margin,
            narrow=True,
        )
    if sys.argv[1] == "splittable":
        return compare(splittable_grain, "splittable grain", int(sys.argv[2]), comm)
    if sys.argv[1] == "balance":
        steps = int(sys.argv[2])
        serial = on_rank_0(comm, lambda: run_serially(uneven_horizons, steps))
        balanced = compare(uneven_horizons, "uneven horizons", steps, comm, serial=serial)
        settings = check_balance_settings(serial, steps, comm)
        return balanced | settings | check_time_weights(serial, steps, comm)
    if sys.argv[1] == "drum":
        variant, steps = sys.argv[2], int(sys.argv[3])
        renew, widen = sys.argv[4:] == ["renew"], sys.argv[4:] == ["widen"]
        with tempfile.TemporaryDirectory() as folder:
            make = functools.partial(drum, variant, Path(folder))
            return compare(make, f"drum {variant}", steps, comm, renew, widen=widen)
    dimension, steps = int(sys.argv[1]), int(sys.argv[2])
    if len(sys.argv) > 3 and sys.argv[3] == "fail":
        return check_failure(dimension, steps, comm)
    if len(sys.argv) > 3 and sys.argv[3] == "fail-room":
        return check_room_failure(steps, comm)
    if len(sys.argv) > 3 and sys.argv[3] == "fail-frame-room":
        return check_frame_room_failure(steps, comm)
    if len(sys.argv) > 3 and sys.argv[3] == "fail-progress":
        return check_progress_failure(steps, comm)
    if len(sys.argv) > 3 and sys.argv[3] == "fail-whole":
        return check_whole_failure(dimension, steps, comm)
    if len(sys.argv) > 3 and sys.argv[3] in ("fail-start", "fail-migration"):
        return check_build_failure(dimension, sys.argv[3].removeprefix("fail-"), comm)
    if len(sys.argv) > 4 and sys.argv[4] == "compare":
        make = functools.partial(set_up, dimension)
        return compare(make, f"{dimension}D", steps, comm, True, float(sys.argv[3]))
    if len(sys.argv) > 3:
        migrate = len(sys.argv) > 4 and sys.argv[4] == "migrate"
        return check_margin(dimension, steps, float(sys.argv[3]), migrate, comm)
    return compare(lambda: set_up(dimension), f"{dimension}D", steps, comm)


class NarrowMessages(DistributedRun):
    """A distributed run whose steps' messages carry one bond break each and one body's motion
    per grain sent, the rest sent in a second message (DistributedRun.break_slots and
    body_slots)."""

    break_slots = 1
    body_slots = 0


#: compare's default: the serial reference is run there.
RUN_HERE = object()


def compare(
    make: Callable[[], gr.Simulation],
    name: str,
    steps: int,
    comm: MPI.Comm,
    renew: bool = False,
    margin: float | None = None,
    cap_margin: float | None = None,
    narrow: bool = False,
    widen: bool = False,
    *,
    serial: Any = RUN_HERE,
) -> int:
    """0 when `steps` steps of make() distributed over the ranks end with every node's
    position, velocity and force equal to the serial run's, at the same dt. `renew`: every
    rank builds its part anew from the owners' states at every migration, and narrow messages;
    `margin`, `cap_margin`: the ghost and cap margins [m] (default DistributedRun's);
    `narrow`: a step's message carries one break and one body per grain at most (the others go
    in a second message, NarrowMessages); `widen`: the default margin widens after short
    distributions, as in a run (else it stays, so that the grains migrate often); `serial`:
    the serial reference already run (rank 0's, None on the others), else run here."""
    if serial is RUN_HERE:
        serial = on_rank_0(comm, lambda: run_serially(make, steps))
    kind = NarrowMessages if renew or narrow else DistributedRun
    distributed = kind(make(), comm, margin=margin, cap_margin=cap_margin)
    distributed.always_renew = renew
    if not widen:
        distributed.short_distribution = 0
    first_imbalance = distributed.work_imbalance  # the start's check, of the cut by nodes
    distributed.run(steps)
    fields = {name: distributed.gather(name) for name in ("positions", "velocities", "forces")}
    walls = distributed.wall_reactions()
    renewals = comm.gather(distributed.renewals, root=0)
    held = comm.gather((distributed.ghost_node_count, distributed.exchanged_node_count), root=0)
    seconds = comm.allreduce(distributed.second_messages)
    joined = comm.allreduce(distributed.nodes_joined)
    if serial is None:
        return 0
    worst = {name: float(np.abs(fields[name] - getattr(serial, name)).max()) for name in fields}
    worst["walls"] = wall_difference(walls, serial)
    same_dt = distributed.dt == serial.dt
    ghosts = [len(g) for g in distributed.ghosts]
    print(
        f"ranks {comm.Get_size()}, {name}, {steps} steps, dt equal {same_dt}, ghosts per "
        f"rank {ghosts}, migrations {distributed.migrations}, margin widened "
        f"{distributed.margin_widenings} times to {distributed.margin:.3g} m, grains handed over "
        f"{distributed.handed_over}, parts built anew per rank {renewals}, caps picked anew "
        f"{distributed.cap_refreshes}, rebalanced before steps {distributed.rebalance_steps} "
        f"(work over the mean {first_imbalance:.3f} at the start, "
        f"{distributed.work_imbalance:.3f} at the last check), "
        f"cap margin widened "
        f"{distributed.cap_margin_widenings} times to {distributed.cap_margin:.3g} m, ghost "
        f"nodes held and sent a step per rank {held}, second messages {seconds}, nodes joining "
        f"caps {joined}, bonds broken "
        f"{serial.broken_bonds()}, largest differences {worst}"
    )
    return 0 if same_dt and not any(worst.values()) else 1


def check_balance_settings(serial: gr.Simulation | None, steps: int, comm: MPI.Comm) -> int:
    """The uneven horizons' run under two settings of sim.load_balance, each printed with
    the steps the ranks rebalanced before, the work over the mean at the start's check and at
    the last one, and the largest differences from the serial run: a check only at the start
    (every=0) and no cut for the balance (threshold=inf). 0 when both are the serial run
    (`serial`, on rank 0)."""
    failed = 0
    for balance in (gr.LoadBalance(every=0), gr.LoadBalance(threshold=float("inf"))):
        sim = uneven_horizons()
        sim.load_balance = balance
        distributed = DistributedRun(sim, comm)
        first_imbalance = distributed.work_imbalance
        distributed.run(steps)
        positions = distributed.gather("positions")
        if serial is not None:
            worst = float(np.abs(positions - serial.positions).max())
            failed |= worst != 0.0
            print(
                f"{balance}: rebalanced before steps {distributed.rebalance_steps}, work over "
                f"the mean {first_imbalance:.3f} at the start, {distributed.work_imbalance:.3f} "
                f"at the last check; largest difference in positions {worst}"
            )
    return int(comm.bcast(failed, root=0))


class CostlyLeftGrains(DistributedRun):
    """The uneven horizons' left half (its wide-horizon discs) costs 10 us a node more each
    step than the counts say: each rank's step seconds (which LoadBalance(weight="time")
    reads) are counted that much longer for the left discs it owns, as for a cost the counts
    miss (contact costlier than its entries, breaking bonds)."""

    extra = 1e-5  # [s] a node of a left disc, a step

    def __init__(self, sim: gr.Simulation, comm: MPI.Comm) -> None:
        self._left = {k for k in range(len(sim.bodies)) if k % 10 < 5}
        self._node_counts = [body.node_count for body in sim.bodies]
        super().__init__(sim, comm)

    def _step(self) -> None:
        super()._step()
        grains = self.partition.grains_of(self.comm.Get_rank())
        left = sum(self._node_counts[g] for g in grains if g in self._left)
        self.seconds["steps"] += self.extra * left


def check_time_weights(serial: gr.Simulation | None, steps: int, comm: MPI.Comm) -> int:
    """The uneven horizons under LoadBalance(weight="time") with their left discs costlier
    than counted (CostlyLeftGrains): printed, the steps the ranks rebalanced before, the
    most loaded rank's step seconds over the mean at each check, each rank's own nodes at
    the end and the largest difference from the serial run. 0 when it is the serial run
    (`serial`, on rank 0)."""
    sim = uneven_horizons()
    sim.load_balance = gr.LoadBalance(weight="time")
    distributed = CostlyLeftGrains(sim, comm)
    imbalances = []
    for _ in range(steps // 100):
        distributed.run(100)
        imbalances.append(round(distributed.work_imbalance, 3))
    owned = comm.gather(len(distributed.owned_nodes), root=0)
    positions = distributed.gather("positions")
    if serial is None:
        return int(comm.bcast(None, root=0))
    worst = float(np.abs(positions - serial.positions).max())
    print(
        f"time weights, left discs costlier: rebalanced before steps "
        f"{distributed.rebalance_steps}, step seconds over the mean at the checks {imbalances}, "
        f"own nodes per rank {owned}; largest difference in positions {worst}"
    )
    return int(comm.bcast(worst != 0.0, root=0))


def run_serially(make: Callable[[], gr.Simulation], steps: int) -> gr.Simulation:
    """make() after `steps` steps of its core: the serial reference."""
    serial = make()
    serial.core.run(steps)
    return serial


def wall_difference(walls: np.ndarray, serial: gr.Simulation) -> float:
    """The largest difference of the walls' forces and torques from the serial run's (0 for
    no wall)."""
    expected = np.array(serial.core.wall_reactions()).reshape(-1, 6)
    return float(np.abs(walls - expected).max(initial=0.0))


def check_restart(make: Callable[[], gr.Simulation], steps: int, comm: MPI.Comm) -> int:
    """0 when a run on all K ranks that saves a checkpoint half way, continued from it on K - 1
    ranks, ends bit for bit where the serial run does; and a checkpoint of another set-up is
    refused on every rank."""
    serial = on_rank_0(comm, lambda: run_serially(make, steps))
    first = DistributedRun(make(), comm)
    first.run(steps // 2)
    folder = Path(tempfile.gettempdir()) if comm.Get_rank() else Path(tempfile.mkdtemp())
    path = comm.bcast(folder / "distributed.npz")
    first.save_checkpoint(path)
    fewer = comm.Split(0 if comm.Get_rank() < comm.Get_size() - 1 else 1, comm.Get_rank())
    if comm.Get_rank() == comm.Get_size() - 1:
        wait_asleep(comm)
        return 0
    second = DistributedRun(make(), fewer)
    second.load_checkpoint(path)
    second.run(steps - steps // 2)
    fields = {name: second.gather(name) for name in ("positions", "velocities", "forces")}
    walls = second.wall_reactions()
    other = set_up(2)  # the locality assembly: other grains
    try:
        DistributedRun(other, fewer).load_checkpoint(path)
        refused = ""
    except gr.InputError as error:
        refused = str(error)
    refusals = fewer.gather(refused, root=0)
    resumed = on_rank_0(comm, lambda: continued_serially(make, path, steps - steps // 2))
    if resumed is None:
        return 0
    shutil.rmtree(folder)
    worst = {name: float(np.abs(fields[name] - getattr(serial, name)).max()) for name in fields}
    worst["walls"] = wall_difference(walls, serial)
    alone = {
        name: float(np.abs(getattr(resumed, name) - getattr(serial, name)).max()) for name in fields
    }
    print(
        f"saved at step {steps // 2} on {comm.Get_size()} ranks, continued on "
        f"{fewer.Get_size()} to step {second.local.core.step}: largest differences {worst}; "
        f"continued serially: {alone}; another set-up: {refusals[0]}"
    )
    same = not any(worst.values()) and not any(alone.values()) and second.local.core.step == steps
    return 0 if same and all("different set-up" in r for r in refusals) else 1


def continued_serially(make: Callable[[], gr.Simulation], path: Path, steps: int) -> gr.Simulation:
    """make() continued serially from the checkpoint at `path` for `steps` steps."""
    resumed = make()
    checkpoints.load(resumed, path, None)
    resumed.core.run(steps)
    return resumed


def check_api(variant: str, steps: int, comm: MPI.Comm) -> int:
    """0 when the drum set up with Simulation(comm=...) and run with outputs (every 250 steps),
    checkpoints (every 1,000) and a stop check writes the serial run's output folder (all but
    run.json, the checkpoint and history.csv's list_rebuilds, byte for byte), rank 0's
    simulation then holds the serial state (nodes, contact table, wall reactions; read-only),
    the other ranks' refuse to give results, and the checkpoint continues a serial run."""
    folder = Path(comm.bcast(tempfile.mkdtemp() if comm.Get_rank() == 0 else None, root=0))
    stop = [gr.stopping.BrokenBonds(10**6)]  # never met: the checks gather the state
    if comm.Get_rank() == 0:
        serial = tumbling_drum(folder / "serial", **DRUMS[variant])
        serial.run(steps, stop=stop, check_every=500)
    wait_asleep(comm)
    sim = tumbling_drum(folder / "ranks", comm=comm, **DRUMS[variant])
    sim.run(steps, stop=stop, check_every=500)
    if comm.Get_rank() != 0:
        try:
            np.asarray(sim.positions)
            return 1
        except gr.InputError as error:
            return 0 if "whole state is on rank 0" in str(error) else 1
    try:  # rank 0's copy of the state: writing it would change nothing in the run
        sim.velocities[0, 0] = 1.0
        return 1
    except ValueError:
        pass
    files = sum(1 for p in (folder / "serial").rglob("*") if p.is_file())
    differ = differing(folder / "serial", folder / "ranks")
    rows = [history(folder / name) for name in ("serial", "ranks")]
    for row in (*rows[0], *rows[1]):
        del row[SEARCHES]  # each rank counts its own part's searches
    fields = ("positions", "velocities", "forces")
    nodes = {n: bool(np.array_equal(getattr(sim, n), getattr(serial, n))) for n in fields}
    table, expected = sim.contact_table(), serial.contact_table()
    contacts = all(np.array_equal(table[k], expected[k]) for k in expected)
    walls = np.array_equal(sim.wall_reactions()["drum"], serial.wall_reactions()["drum"])
    resumed = tumbling_drum(folder / "resumed", **DRUMS[variant])
    checkpoints.load(resumed, folder / "ranks" / "checkpoint.npz", None)
    resumed.core.run(500)  # from the last checkpoint, the run's end
    serial.core.run(500)
    same_after = bool(np.array_equal(resumed.positions, serial.positions))
    shutil.rmtree(folder)
    print(
        f"api {variant} on {comm.Get_size()} ranks: {files} files, differing {differ}; "
        f"history equal but list_rebuilds {rows[0] == rows[1]} ({len(rows[0])} rows); "
        f"nodes {nodes}; contacts {contacts} ({len(expected['wall'])}); walls {walls}; "
        f"resumed serially {same_after}"
    )
    ok = not differ and rows[0] == rows[1] and all(nodes.values()) and contacts and walls
    return 0 if ok and same_after else 1


def stop_messages(action: Callable[[], object], comm: MPI.Comm) -> list[str] | None:
    """action() on every rank; on rank 0 each rank's "ErrorType: message" (empty if it
    finished)."""
    try:
        action()
        message = ""
    except (gr.InputError, RuntimeError) as error:  # InstabilityError is a RuntimeError
        message = f"{type(error).__name__}: {error}"
    return comm.gather(message, root=0)


def check_margin(dimension: int, steps: int, margin: float, migrate: bool, comm: MPI.Comm) -> int:
    """0 when every rank raised the margin's InputError within `steps` steps (with or
    without migrating grains)."""
    run = DistributedRun(set_up(dimension), comm, margin=margin, migrate=migrate)
    messages = stop_messages(lambda: run.run(steps), comm)
    if messages is None:
        return 0
    print(messages[0])
    return 0 if all("ghost margin" in m for m in messages) else 1


def check_failure(dimension: int, steps: int, comm: MPI.Comm) -> int:
    """0 when a blow-up on the last rank alone ends every rank: it with its InstabilityError,
    naming the node and grain as the serial run numbers them and quoting the serial run's
    stable time-step estimate (not its part's), the others with the RuntimeError naming the
    rank."""
    run = DistributedRun(set_up(dimension), comm)
    last = comm.Get_size() - 1
    node = run.owned_nodes[0]
    if comm.Get_rank() == last:
        run.local.velocities[node] = 1e6  # moves a mesh size in a step
    named = comm.bcast(f"node {run.global_nodes(node)} of particle {run.owned[0]} moves", root=last)
    estimate = f"the stable estimate is {set_up(dimension).core.stable_time_step:.6g} s"
    messages = stop_messages(lambda: run.run(steps), comm)
    if messages is None:
        return 0
    print(messages)
    others = all(f"rank {last} failed" in m for m in messages[:last])
    blown = messages[last].startswith("InstabilityError") and named in messages[last]
    return 0 if others and blown and estimate in messages[last] else 1


def check_build_failure(dimension: int, during: str, comm: MPI.Comm) -> int:
    """0 when an error while the last rank builds its part ends every rank: at the start a
    user's error (InputError), which every rank raises with its message (rank 0 reports it);
    in a migration a bug (RuntimeError), which that rank raises, the others RankFailed naming
    it."""
    last = comm.Get_size() - 1
    sim = set_up(dimension)

    def broken(*_: object, **__: object) -> None:
        if during == "start":
            raise gr.InputError("an injected failure")
        raise RuntimeError("an injected bug")

    def build_and_migrate() -> None:
        if during == "start" and comm.Get_rank() == last:
            sim._subdomain = broken  # type: ignore[method-assign]
        run = DistributedRun(sim, comm)
        if during == "migration":
            if comm.Get_rank() == last:
                sim._subdomain = broken  # type: ignore[method-assign]
            run.always_renew = True
            run.migrate()

    messages = stop_messages(build_and_migrate, comm)
    if messages is None:
        return 0
    print(during, messages)
    if during == "start":
        return 0 if set(messages) == {"InputError: an injected failure"} else 1
    others = all(f"rank {last} failed while building" in m for m in messages[:last])
    return 0 if others and messages[last] == "RuntimeError: an injected bug" else 1


def check_whole_failure(dimension: int, steps: int, comm: MPI.Comm) -> int:
    """0 when rank 0, with too little memory left for its whole simulation (the memory check
    of core_model), fails to take the gathered state, and every rank stops with its
    InputError rather than waiting for it."""
    run = DistributedRun(set_up(dimension), comm)
    run.run(steps)
    if comm.Get_rank() == 0:
        resources.available_memory = lambda: 1000
    messages = stop_messages(run.collect, comm)
    if messages is None:
        return 0
    print("whole", messages)
    same = len(set(messages)) == 1 and messages[0].startswith("InputError")
    return 0 if same and "of memory" in messages[0] else 1


def check_room_failure(steps: int, comm: MPI.Comm) -> int:
    """0 when rank 0's memory check of the whole model (whole_state.require_room), failing on
    rank 0 alone, stops every rank with its InputError before the drum's run (Simulation(comm=
    ...)) takes a step: the first run that gathers, after one that did not (and so was not
    checked)."""
    sim = tumbling_drum(Path("unused"), comm=comm, outputs=False)
    sim.run(steps, gather=False)  # nothing for rank 0 to hold: not checked
    if comm.Get_rank() == 0:

        def full(*_: object) -> None:
            raise gr.InputError("the model would need about 9 TB of memory")

        core_model.require_memory_for = full
    messages = stop_messages(lambda: sim.run(steps), comm)
    if messages is None:
        return 0
    step = int(sim._distributed.local.core.step)
    print("room", messages, "steps taken", step)
    reason = "rank 0 holds the whole model at the end of a run"
    return 0 if len(set(messages)) == 1 and reason in messages[0] and step == steps else 1


def check_frame_room_failure(steps: int, comm: MPI.Comm) -> int:
    """0 when rank 0, too short of memory for the frames of every node it joins of the
    ranks' rows (vtu_frame.require_room_for_frames: 1 kB free, forced once the ranks have
    built their parts), stops every rank with its InputError before the drum's run
    (Simulation(comm=...), frames in one file, run(gather=False)) takes a step."""
    folder = Path(comm.bcast(tempfile.mkdtemp() if comm.Get_rank() == 0 else None, root=0))
    sim = tumbling_drum(folder, comm=comm)
    sim._distributed_run()  # the ranks' parts, built with the memory the machine has
    if comm.Get_rank() == 0:
        resources.available_memory = lambda: 10**3
    messages = stop_messages(lambda: sim.run(steps, gather=False), comm)
    if messages is None:
        return 0
    shutil.rmtree(folder)
    print("frame room", messages, "steps taken", sim._distributed.local.core.step)
    reason = "Rank 0's frames of all 184 nodes in one file would need about 62.2 kB"
    stopped = len(set(messages)) == 1 and reason in messages[0] and "in pieces" in messages[0]
    return 0 if stopped and sim._distributed.local.core.step == 0 else 1


def check_progress_failure(steps: int, comm: MPI.Comm) -> int:
    """0 when a progress function reading rank 0's simulation during the drum's run (which
    it refuses: the ranks are ahead of it) stops every rank with that InputError, none left
    waiting for the next chunk."""
    sim = tumbling_drum(Path("unused"), comm=comm, outputs=False)

    def watch(report: gr.Progress) -> None:
        if comm.Get_rank() == 0:
            np.asarray(sim.positions)

    messages = stop_messages(lambda: sim.run(steps, progress=watch), comm)
    if messages is None:
        return 0
    print("progress", messages)
    reason = "rank 0's simulation does not hold the run's state"
    return 0 if len(set(messages)) == 1 and reason in messages[0] else 1


if __name__ == "__main__":
    code = main()
    wait_asleep(MPI.COMM_WORLD)  # while rank 0 compares
    sys.exit(code)
