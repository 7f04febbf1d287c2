"""Distributed runs against the serial run, bit for bit, on 2 and 3 MPI ranks (3 ranks
oversubscribe 2 cores: correctness, not speed). Each case runs tests/mpi_check.py under the
mpiexec of the MPI installed with mpi4py (`pip install ".[test]"` brings both from PyPI)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

CHECK = Path(__file__).with_name("mpi_check.py")


def mpiexec() -> str:
    """The mpiexec beside this Python (the mpich wheel's), else the one on PATH."""
    beside = Path(sys.executable).with_name("mpiexec")
    found = str(beside) if beside.exists() else shutil.which("mpiexec")
    if found is None:
        raise RuntimeError('no mpiexec: install the test extras, pip install ".[test]"')
    return found


def run_ranks(
    ranks: int, *arguments: str, script: Path = CHECK
) -> subprocess.CompletedProcess[str]:
    """`script` (mpi_check.py) on `ranks` ranks, one thread each; a hang fails the test after 5
    minutes."""
    environment = {**os.environ, "OMP_NUM_THREADS": "1"}
    command = [mpiexec(), "-n", str(ranks), sys.executable, str(script), *arguments]
    return subprocess.run(command, capture_output=True, text=True, timeout=300, env=environment)


def sent_shares(stdout: str) -> list[float]:
    """Per rank, the ghost nodes sent a step over those held, from mpi_check.py's line."""
    held = stdout.split("sent a step per rank [")[1].split("]")[0]
    pairs = (map(int, pair.strip("() ").split(",")) for pair in held.split("), ("))
    return [sent / ghosts for ghosts, sent in pairs]


@pytest.mark.full_only
@pytest.mark.parametrize(("ranks", "dimension", "steps"), [(3, 2, 200), (2, 3, 60)])
def test_a_distributed_run_is_the_serial_run_bit_for_bit(
    ranks: int, dimension: int, steps: int
) -> None:
    """Every node's position, velocity and force and the floor's reaction (summed on rank 0
    in the serial order) after `steps` steps. Only --full runs it: the default suite's drums
    below compare 2D runs on 2 and 3 ranks with a floor (the drum's wall) in the same way, and
    the 3D migrations a 3D run on 3 ranks, whose steps between migrations are these."""
    done = run_ranks(ranks, str(dimension), str(steps))
    assert done.returncode == 0, done.stdout + done.stderr
    assert f"ranks {ranks}, {dimension}D" in done.stdout
    assert "'positions': 0.0, 'velocities': 0.0, 'forces': 0.0, 'walls': 0.0}" in done.stdout


@pytest.mark.parametrize(
    ("ranks", "variant", "renew"),
    [
        (3, "surface", False),
        pytest.param(2, "grid", True, marks=pytest.mark.full_only),
        (2, "lattice", False),
        pytest.param(2, "surface", True, marks=pytest.mark.full_only),
        (2, "rolling", True),
    ],
)
def test_grains_migrating_between_ranks_keep_the_serial_run_bit_for_bit(
    ranks: int, variant: str, renew: bool
) -> None:
    """1,500 steps of four grains tumbling and breaking in a rotating drum (1,103 bonds break
    under the surface law, 1,113 in 3,000 steps): the ranks cut the drum anew 15-17 times
    (28-32 in 3,000 steps), and on 3 ranks hand grains over. A rank whose grains change builds
    its part anew from the owners' states (broken bonds, collisions in progress, friction
    springs; under the surface law, the new anchors of surface nodes whose bonds broke); with
    `renew` every rank does so at every migration, the others keep their part. Between
    migrations the ranks pick the ghost nodes they exchange anew (refresh_caps) within the
    steps that take a node past half the cap margin, which starts at half the mesh size and
    widens as the caps last only a few dozen steps. Three ranks run the surface law (the
    default), whose parts are built anew from the owners' states when grains are handed over;
    the node spheres' lattice and the renewing variants run on 2 ranks, which cost a third to
    a half of 3 on the CI's 2 cores. The grid and surface variants that renew only run with
    --full: the surface variants all search by grid, and the rolling one renews (as the 3D
    migrations do, under the surface law)."""
    done = run_ranks(ranks, "drum", variant, "1500", *(["renew"] if renew else []))
    assert done.returncode == 0, done.stdout + done.stderr
    assert "'positions': 0.0, 'velocities': 0.0, 'forces': 0.0, 'walls': 0.0}" in done.stdout
    migrations = int(done.stdout.split("migrations ")[1].split(",")[0])
    handed = int(done.stdout.split("grains handed over ")[1].split(",")[0])
    renewals = done.stdout.split("parts built anew per rank [")[1].split("]")[0]
    assert migrations >= 12
    assert int(done.stdout.split("caps picked anew ")[1].split(",")[0]) >= 5
    assert int(done.stdout.split("cap margin widened ")[1].split(" ")[0]) >= 2
    assert handed > 0 or ranks == 2
    every_migration, none = (", ".join([str(n)] * ranks) for n in (migrations, 0))
    assert renewals == every_migration if renew else renewals != none


def test_ranks_cut_by_their_work_keep_the_serial_run_bit_for_bit() -> None:
    """40 discs at rest, the left half with 2.25 times the bonds a node of the right
    (mpi_check.uneven_horizons), on 3 ranks: cut by nodes at the start, the most loaded rank
    has 1.14 times the mean work (parallel/work_load.py: nodes, intact bond copies, contact
    list entries); the first check cuts the grains anew by their work before the first step,
    after which the check at step 100 finds 1.03 (asserted: above 1.1, then below 1.05).
    Every node ends as in the serial run. Before 2026-12-07 the cut by work left rank 0 only
    wide-horizon discs, and their bond sums took their terms in another order than serially
    (Model::cut_bond_blocks cut a particle by the model's bonds): forces 5.8e-11 apart after
    200 steps. The simulation's load_balance is followed: with every=0 the ranks compare
    their work only at the start (cut anew before step 0, the start's 1.14 the last measure);
    with threshold=inf they compare it every 100 steps and never cut anew (1.14 at step 200).
    Under weight="time", with the left discs made to cost 10 us a node a step more than their
    counts say (mpi_check.CostlyLeftGrains), the ranks' step seconds at step 100 are 1.60-1.61
    times the mean (asserted above 1.3): they cut anew, giving the ranks of left discs fewer
    nodes (1,456 each against 5,408), and at step 200 are 1.03-1.04 (asserted below 1.3; five
    runs, three beside a busy process). Each run ends as the serial run does."""
    done = run_ranks(3, "balance", "200")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "'positions': 0.0, 'velocities': 0.0, 'forces': 0.0, 'walls': 0.0}" in done.stdout
    assert "rebalanced before steps [0] " in done.stdout, done.stdout
    start, last = done.stdout.split("work over the mean ")[1].split(", ")[:2]
    assert float(start.split()[0]) > 1.1 and float(last.split()[0]) < 1.05, done.stdout
    first = start.split()[0]
    unbalanced = f"work over the mean {first} at the start, {first} at the last check"
    assert (
        f"LoadBalance(every=0, threshold=1.1, weight='work'): rebalanced before steps [0], "
        f"{unbalanced}; largest difference in positions 0.0"
    ) in done.stdout, done.stdout
    assert (
        f"LoadBalance(every=100, threshold=inf, weight='work'): rebalanced before steps [], "
        f"{unbalanced}; largest difference in positions 0.0"
    ) in done.stdout, done.stdout
    timed = done.stdout.split("time weights, left discs costlier: ")[1].splitlines()[0]
    steps = timed.split("rebalanced before steps [")[1].split("]")[0]
    assert steps == "0, 100", timed  # a cut due at step 200 would come after the run
    checks = [float(x) for x in timed.split("at the checks [")[1].split("]")[0].split(", ")]
    assert checks[0] > 1.3 and checks[1] < 1.3, timed
    owned = [int(x) for x in timed.split("own nodes per rank [")[1].split("]")[0].split(", ")]
    assert max(owned) > 2 * min(owned), timed
    assert timed.endswith("largest difference in positions 0.0"), timed


def test_a_splittable_grain_breaking_among_others_keeps_the_serial_run_bit_for_bit() -> None:
    """A disc of 4,301 nodes (a splittable particle: its bodies' rigid motion and the sums of
    the slots it takes part in are block sums added exactly) struck by three coarser discs
    (R/h = 8) and breaking (11,149 bonds in 450 steps, 39 pieces), whole grains on 2 ranks:
    the rank holding it as a ghost sums the slots with it over the nodes of its caps, its
    owner sends its fragments' motions. Every node ends as in the serial run."""
    done = run_ranks(2, "splittable", "450")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "'positions': 0.0, 'velocities': 0.0, 'forces': 0.0, 'walls': 0.0}" in done.stdout
    assert int(done.stdout.split("bonds broken ")[1].split(",")[0]) > 5000


def test_the_default_margin_widens_when_grains_migrate_often() -> None:
    """The drum's grains cross a quarter of the default margin (the largest grain's radius)
    within a few dozen steps: after such short distributions the ranks double the margin, up
    to four grain radii, and migrate less; the run stays the serial one, bit for bit."""
    done = run_ranks(2, "drum", "lattice", "1500", "widen")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "'positions': 0.0, 'velocities': 0.0, 'forces': 0.0, 'walls': 0.0}" in done.stdout
    widened = int(done.stdout.split("margin widened ")[1].split(" ")[0])
    migrations = int(done.stdout.split("migrations ")[1].split(",")[0])
    assert widened == 2  # twice the radius, then four times: the widest
    assert 0 < migrations < 12  # 6; at least 12 without (the test above: 16)


def test_ghosts_exchanged_as_caps_keep_the_serial_run_bit_for_bit() -> None:
    """Finely meshed brittle discs (R/h = 12, 50 of them) thrown at each other on 3 ranks, with
    a cap margin of 2e-5 m: each step sends about a tenth of the ghost nodes held (the caps: a
    third while they took every bonded neighbour), the others stay where they were; the ranks
    pick the caps anew 47 times, within the steps whose drift, or whose breaks, took a node or
    where the lists see it past half the cap margin, and cut the grains anew once while the
    discs shatter (4,063 bonds in 350 steps), the messages with room for one break and one body
    per grain (260 second messages), and nodes join the caps within steps as the nodes of a
    cap take new anchors when their bonds break (DistributedRun._joining; 9 nodes). Every node
    ends as in the serial run. (With the layout's 90 discs: 51 picks, 680 second messages, 10
    nodes joining, 8,424 bonds; twice the time.)"""
    done = run_ranks(3, "fine", "350", "4e-4", "2e-5")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "'positions': 0.0, 'velocities': 0.0, 'forces': 0.0, 'walls': 0.0}" in done.stdout
    assert int(done.stdout.split("nodes joining caps ")[1].split(",")[0]) > 0
    assert int(done.stdout.split("caps picked anew ")[1].split(",")[0]) >= 20
    assert int(done.stdout.split("second messages ")[1].split(",")[0]) >= 100
    assert int(done.stdout.split("bonds broken ")[1].split(",")[0]) > 2000
    assert all(share < 0.25 for share in sent_shares(done.stdout))


def test_caps_without_bonded_neighbours_under_peridems_node_pairs_keep_the_serial_run() -> None:
    """The fine discs under PeriDEM's node-pair law, whose contact reads a ghost node alone
    (no surface normal, no anchors: core.contact_surface_normal_reach 0), on 2 ranks with the
    default cap margin (half a mesh size, widened as the discs fly): the caps are the nodes
    within reach, without the horizon of bonded neighbours, so each step sends about a tenth
    of the ghost nodes held (a fifth with the neighbours), and the caps are picked anew twice.
    Every node ends as in the serial run while 54,200 bonds break in 200 steps (with the
    layout's 90 discs: 54,271, and 3 picks; on 3 ranks, the same picks and shares)."""
    done = run_ranks(2, "fine", "200", "4e-4", "default", "node-pairs")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "'positions': 0.0, 'velocities': 0.0, 'forces': 0.0, 'walls': 0.0}" in done.stdout
    assert int(done.stdout.split("caps picked anew ")[1].split(",")[0]) >= 1
    assert all(0 < share < 0.15 for share in sent_shares(done.stdout))


def test_peridem_damping_on_ranks_keeps_the_serial_run_bit_for_bit() -> None:
    """PeriDEM's damping (--peridem-compat decks) between the fine discs, which acts between
    the particles' centre nodes, and from a PeriDEM wall (a fixed slab under them, a large
    body: paired with the discs its nodes come near, by its owner at each migration), on 3
    ranks whose caps are a small part of their ghosts, with a ghost margin of 2e-5 m (5
    migrations in 150 steps): the caps take every ghost's centre node (without, at a margin of
    4e-4 m, the forces differed by 2e5 N/m^3 after 150 steps; without the slab's pairs found
    at migrations, by 3.5e8; both measured with the layout's 90 discs, before the 50). Every
    node ends as in the serial run."""
    done = run_ranks(3, "fine", "150", "2e-5", "2e-5", "peridem")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "'positions': 0.0, 'velocities': 0.0, 'forces': 0.0, 'walls': 0.0}" in done.stdout
    assert int(done.stdout.split("migrations ")[1].split(",")[0]) >= 3
    assert all(share < 0.5 for share in sent_shares(done.stdout))


def test_grains_migrating_in_3d_under_the_surface_law_keep_the_serial_run_bit_for_bit() -> None:
    """The 3D locality assembly (spheres pressed and thrown, the surface law by default) with a
    ghost margin of 2e-5 m: a migration every few steps (6 in 40 steps, handing 62 grains
    over; 10 in 60), every part built anew each time."""
    done = run_ranks(3, "3", "40", "2e-5", "compare")
    assert done.returncode == 0, done.stdout + done.stderr
    assert int(done.stdout.split("migrations ")[1].split(",")[0]) >= 4
    assert "'positions': 0.0, 'velocities': 0.0, 'forces': 0.0, 'walls': 0.0}" in done.stdout


@pytest.mark.parametrize("ranks", [pytest.param(2, marks=pytest.mark.full_only), 3])
def test_a_distributed_checkpoint_restarts_on_fewer_ranks_bit_for_bit(ranks: int) -> None:
    """The surface-law drum saved at step 750 on `ranks` ranks and continued on one rank
    fewer (on 2 ranks: on one, which only --full runs) ends at step 1,500 as the serial run
    does, and so does a serial run continued from the same checkpoint (one format for both);
    a checkpoint of another set-up is refused with one message on every rank."""
    done = run_ranks(ranks, "restart", "surface", "1500")
    assert done.returncode == 0, done.stdout + done.stderr
    assert f"on {ranks} ranks, continued on {ranks - 1} to step 1500" in done.stdout
    assert "'positions': 0.0, 'velocities': 0.0, 'forces': 0.0, 'walls': 0.0}" in done.stdout
    assert "serially: {'positions': 0.0, 'velocities': 0.0, 'forces': 0.0}" in done.stdout


CHECKPOINT_CHECK = Path(__file__).with_name("mpi_checkpoint_check.py")


@pytest.mark.parametrize("ranks", [pytest.param(2, marks=pytest.mark.full_only), 3])
def test_a_distributed_checkpoint_is_a_header_and_a_piece_per_rank(ranks: int) -> None:
    """Written on one rank fewer, each rank its own grains' states, and continued on `ranks`
    ranks (more than wrote it) bit for bit as the serial run; rank 0 never builds the whole
    simulation; the next checkpoint at the path leaves only its own pieces. (Written on one
    rank and continued on 2: only with --full.)"""
    done = run_ranks(ranks, "pieces", script=CHECKPOINT_CHECK)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "rank 0 built the whole: False" in done.stdout
    assert "'positions': True, 'velocities': True, 'forces': True}" in done.stdout


def test_a_checkpoint_missing_a_piece_or_with_a_foreign_one_is_refused_on_every_rank() -> None:
    """One InputError on every rank naming the piece; history.csv is left as it was."""
    done = run_ranks(2, "damaged", script=CHECKPOINT_CHECK)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "is missing its piece" in done.stdout and "history.csv kept True" in done.stdout


@pytest.mark.parametrize("case", ["cli", "cli-one-file"])
def test_granulate_run_never_builds_the_whole_model_on_rank_0(case: str) -> None:
    """The drum case on 2 ranks, its frames in pieces or each in one file (joined on rank 0
    from the ranks' rows), cut short at step 850 and resumed to 1,500 from its checkpoint in
    pieces: rank 0's whole simulation is never built."""
    done = run_ranks(2, case, script=CHECKPOINT_CHECK)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "exit codes [0, 0]; rank 0's whole builds []" in done.stdout


def test_a_piece_on_a_disk_rank_0_does_not_see_is_refused_before_the_header() -> None:
    """The last of 3 ranks writes its piece to a disk of its own (a node's local disk): every
    rank stops with one InputError that says the checkpoint must be on a shared file system,
    no header names the piece, and the checkpoint before is left whole."""
    done = run_ranks(3, "unshared", script=CHECKPOINT_CHECK)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "on a file system every rank shares" in done.stdout
    assert "checkpoint kept True" in done.stdout


def test_a_rank_failing_to_write_its_piece_leaves_the_last_checkpoint_whole() -> None:
    """The last of 3 ranks cannot write (a full disk): every rank stops, the checkpoint before
    keeps its header and pieces, and a run continues from it."""
    done = run_ranks(3, "write-fail", script=CHECKPOINT_CHECK)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "No space left on device" in done.stdout and "checkpoint kept True" in done.stdout


@pytest.mark.parametrize(
    ("ranks", "variant"), [(3, "surface"), pytest.param(2, "rolling", marks=pytest.mark.full_only)]
)
def test_a_simulation_given_a_communicator_writes_the_serial_outputs(
    ranks: int, variant: str
) -> None:
    """gr.Simulation(comm=...) with outputs every 250 steps, checkpoints every 1,000 and a stop
    check every 500, over 1,000 steps: the drum's output folder is the serial run's byte for
    byte (but run.json, the checkpoint and history.csv's list_rebuilds); rank 0's simulation
    holds the serial run's nodes, contact table and wall reactions, the other ranks refuse to
    give results, and a serial run continues from the distributed checkpoint bit for bit.
    (The rolling drum on 2 ranks: only with --full.)"""
    done = run_ranks(ranks, "api", variant, "1000")
    assert done.returncode == 0, done.stdout + done.stderr
    assert f"api {variant} on {ranks} ranks: 30 files, differing []" in done.stdout
    assert "list_rebuilds True (5 rows)" in done.stdout and "resumed serially True" in done.stdout


@pytest.mark.parametrize("migrate", [False, True])
def test_grains_moving_past_the_ghost_margin_stop_every_rank_with_the_reason(
    migrate: bool,
) -> None:
    """1e-6 m of margin: the grains, thrown at up to 0.5 m/s, move more than half of it in
    one step, which no migration can follow."""
    done = run_ranks(2, "2", "50", "1e-6", *(["migrate"] if migrate else []))
    assert done.returncode == 0, done.stdout + done.stderr
    assert "more than half the ghost margin" in done.stdout
    assert ("larger margin" in done.stdout) and (("let it migrate" in done.stdout) != migrate)


def test_a_blow_up_on_one_rank_ends_every_rank_without_a_hang() -> None:
    """The last of 3 ranks blows up one of its nodes: it raises the InstabilityError, naming
    the node and grain as the serial run numbers them, the others RankFailed naming it."""
    done = run_ranks(3, "2", "20", "fail")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "rank 2 failed" in done.stdout and "InstabilityError" in done.stdout


def test_rank_0_failing_to_take_the_whole_state_ends_every_rank_without_a_hang() -> None:
    """Rank 0's whole simulation too large for the memory left (the memory check, forced): every
    rank stops with rank 0's InputError when the state is gathered, none waits for it."""
    done = run_ranks(2, "2", "10", "fail-whole")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "whole ['InputError: " in done.stdout and "of memory" in done.stdout


def test_rank_0_without_room_for_the_whole_model_stops_every_rank_at_the_start() -> None:
    """Rank 0's memory check of the whole model failing (forced) when Simulation(comm=...)
    starts its run: every rank stops with its InputError, which says why, before a step."""
    done = run_ranks(2, "2", "10", "fail-room")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "room ['InputError: the model would need about 9 TB" in done.stdout


def test_rank_0_without_room_for_one_file_frames_stops_every_rank_at_the_start() -> None:
    """Rank 0 joins each frame of every node from the ranks' rows; without the memory for them
    (forced), every rank stops with its InputError, which says to write the frames in
    pieces, before a step."""
    done = run_ranks(2, "2", "10", "fail-frame-room")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "steps taken 0" in done.stdout


def test_a_progress_function_failing_on_rank_0_ends_every_rank_without_a_hang() -> None:
    """A progress function reading rank 0's simulation mid-run, which refuses (the ranks are
    ahead of it): every rank stops with that InputError, none waits for the next chunk."""
    done = run_ranks(2, "2", "400", "fail-progress")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "progress [\"InputError: rank 0's simulation does not hold" in done.stdout


@pytest.mark.parametrize("during", ["start", "migration"])
def test_a_failure_building_one_ranks_part_ends_every_rank_without_a_hang(during: str) -> None:
    """At the start a user's error on the last rank, which every rank raises; in a migration a
    bug there, which the others report as that rank's failure."""
    done = run_ranks(3, "2", "0", f"fail-{during}")
    assert done.returncode == 0, done.stdout + done.stderr
    if during == "start":
        assert "['InputError: an injected failure', 'InputError: an injected" in done.stdout
    else:
        assert "rank 2 failed while building its part" in done.stdout


SPLIT_CHECK = Path(__file__).with_name("mpi_split_check.py")


@pytest.mark.parametrize(
    ("ranks", "shape", "model", "steps"),
    [(2, "plate", "lps", 300), (3, "strip", "pmb", 300), (3, "block", "lps", 200)],
)
def test_a_body_split_at_node_level_is_the_serial_run_bit_for_bit(
    ranks: int, shape: str, model: str, steps: int
) -> None:
    """A notched body cut across the ranks (granulate.parallel.node_split), stretched until it
    cracks: every node's position, velocity, force and dilatation after `steps` steps, and the
    bonds broken, as serially; the fragment labels the ranks find together, and the output
    step made of their measures (totals, fragment and particle tables), bit for bit."""
    done = run_ranks(ranks, shape, model, str(steps), script=SPLIT_CHECK)
    assert done.returncode == 0, done.stdout + done.stderr
    zero = "{'positions': 0.0, 'velocities': 0.0, 'forces': 0.0, 'dilatation': 0.0}"
    assert f"ranks {ranks}, {shape} {model}, {steps} steps: {zero}" in done.stdout
    broken = done.stdout.split("bonds broken ")[1].split()
    assert int(broken[0]) == int(broken[2]) > 100
    assert "fragment labels as serially: True" in done.stdout
    assert "step data as serially: True" in done.stdout


STOP_CHECK = Path(__file__).with_name("mpi_stop_check.py")


@pytest.mark.parametrize(("ranks", "engine", "steps"), [(2, "grains", 600), (3, "split", 400)])
def test_stop_criteria_read_the_ranks_measures_and_stop_at_the_serial_step(
    ranks: int, engine: str, steps: int
) -> None:
    """The measures the stop criteria read (parallel/run_measures.py), every 100 steps of the
    drum (whole grains) and of the pulled plate (cut at node level), equal the serial run's to
    the bit, particles fully broken by hand included (of a body cut among ranks, for the
    plate); runs with a threshold one float past a serial check's value stop at that check,
    with the serial reason, and gather the state on rank 0 only at the end; a criterion of a
    user's own that reads the simulation stops with the serial reason, its every check
    gathering the state. The drum's outputs
    in pieces (a tracked grain's columns among them) are the serial run's, every output step
    made of the ranks' measures (the state gathered only at the end), and with a history
    section of a user's own that reads the simulation, every output step gathers it; run with
    gather=False, never, and rank 0 needs no room for the whole model (its check made to
    fail), refuses to give the nodes after, and sim.measures() is the serial run's."""
    done = run_ranks(ranks, engine, str(steps), script=STOP_CHECK)
    assert done.returncode == 0, done.stdout + done.stderr
    assert f"measures {engine} on {ranks} ranks: equal True" in done.stdout
    broken = {"grains": "2 particles fully broken by hand (serially 2)", "split": "1 particles"}
    assert broken[engine] in done.stdout
    stops = [line for line in done.stdout.splitlines() if line.startswith("stop ")]
    assert len(stops) == 4 and all("the state gathered 1 times" in line for line in stops[:3])
    assert "LargestSpeedAt(step=300)" in stops[3] and "the state gathered 4 times" in stops[3]
    if engine == "grains":
        assert (
            f"outputs grains on {ranks} ranks: 30 files but frames, differing []; history equal "
            "but list searches True (7 rows, 31 columns); the state gathered 1 times"
        ) in done.stdout
        assert (
            f"outputs with a section of its own on {ranks} ranks: 30 files but frames, "
            "differing []; history equal but list searches True (7 rows, 32 columns); the state "
            "gathered 8 times"
        ) in done.stdout
        assert (
            f"outputs grains without gathering on {ranks} ranks: 30 files but frames, differing "
            "[]; history equal but list searches True (7 rows, 31 columns); the state gathered "
            "0 times; rank 0: \"rank 0's simulation does not hold the run's state at step 600"
        ) in done.stdout
        assert "built False; measured as serially True" in done.stdout


THREADS_CHECK = Path(__file__).with_name("mpi_threads_check.py")


@pytest.mark.parametrize("given", [None, "2"])
def test_each_rank_takes_its_share_of_the_cores_unless_told(given: str | None) -> None:
    """Ranks on one machine left at OpenMP's default thread count each use their share of the
    CPUs (parallel/rank_threads.py: at least 1); OMP_NUM_THREADS is used as given."""
    environment = {k: v for k, v in os.environ.items() if k != "OMP_NUM_THREADS"}
    if given is not None:
        environment["OMP_NUM_THREADS"] = given
    command = [mpiexec(), "-n", "2", sys.executable, str(THREADS_CHECK)]
    done = subprocess.run(command, capture_output=True, text=True, timeout=300, env=environment)
    assert done.returncode == 0, done.stdout + done.stderr
    rows = done.stdout.split("threads and CPUs per rank [")[1].split("]")[0]
    pairs = [tuple(map(int, pair.strip("() ").split(","))) for pair in rows.split("), (")]
    expected = int(given) if given else max(1, pairs[0][1] // 2)
    assert [threads for threads, _ in pairs] == [expected, expected]
