"""`mpiexec -n K granulate run case.yaml` against `granulate run case.yaml`: the same output
folder, byte for byte, on 2 and 3 ranks (3 oversubscribe 2 cores: correctness, not speed), and
across restarts on another number of ranks; errors reported once, every rank ending.

The case (tests/cases/drum_mpi.yaml) is the checkpoint tests' drum: four grains tumbling and
breaking in a turning drum with a lifter, the surface law, friction, a moving wall; its grains
migrate between the ranks many times in its 1,500 steps. Also: its frames in pieces, the
example pile (grains of many sizes) and PeriDEM's compression deck under --peridem-compat."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from granulate.io.vtu import read_vtu_point_data
from granulate.load_balance import LoadBalance
from peridem_decks import broken_deck
from run_folders import SEARCHES, differing, history, outputs
from test_mpi import mpiexec

CASE = Path(__file__).parent / "cases" / "drum_mpi.yaml"


def granulate(
    folder: Path, *arguments: str, ranks: int = 1, case: Path = CASE
) -> subprocess.CompletedProcess[str]:
    """`granulate run case` in `folder` (its outputs in folder/out/...), on `ranks` MPI ranks;
    a hang fails the test after 5 minutes."""
    environment = {**os.environ, "OMP_NUM_THREADS": "1"}
    command = [sys.executable, "-m", "granulate", "run", str(case), "--quiet", *arguments]
    if ranks > 1:
        command = [mpiexec(), "-n", str(ranks), *command]
    return subprocess.run(
        command, cwd=folder, capture_output=True, text=True, timeout=300, env=environment
    )


def assert_same_run(
    serial: Path, distributed: Path, row_count: int = 13, searches_within: float | None = 0.2
) -> None:
    """The frames, tables and PVD series byte for byte, and history.csv as assert_same_history
    says."""
    assert len(outputs(serial)) > 10
    assert differing(serial, distributed) == []
    assert_same_history(serial, distributed, row_count, searches_within)


def assert_same_history(
    serial: Path, distributed: Path, row_count: int = 13, searches_within: float | None = 0.2
) -> None:
    """history.csv's every column's text equal, but the searches, which each rank makes for
    its own part (whose nodes and cap nodes, fewer than the run's, call for a search less
    often): they lie between half the serial run's and `searches_within` (20 %) more, or within
    5 (None: not compared); the drum cut short and resumed on other numbers of ranks made 106
    against 135 once the caps held only the anchors (over 3,000 steps). `row_count` rows (13:
    steps 0, 125, ..., 1500)."""
    rows, serial_rows = history(distributed), history(serial)
    assert len(rows) == len(serial_rows) == row_count
    for row, serial_row in zip(rows, serial_rows, strict=True):
        searches, serial_searches = int(row.pop(SEARCHES)), int(serial_row.pop(SEARCHES))
        assert row == serial_row
        if searches_within is not None:
            assert serial_searches - max(5, serial_searches / 2) <= searches
            assert searches <= serial_searches + max(5, searches_within * serial_searches)


@pytest.fixture(scope="module")
def serial_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The case's serial run: its output folder (and its warnings, in warnings.txt beside)."""
    folder = tmp_path_factory.mktemp("serial")
    done = granulate(folder, "--out", "out")
    assert done.returncode == 0, done.stderr
    (folder / "warnings.txt").write_text(done.stderr)
    return folder / "out"


@pytest.mark.parametrize("ranks", [pytest.param(2, marks=pytest.mark.full_only), 3])
def test_a_case_on_k_ranks_writes_the_serial_runs_outputs(
    ranks: int, serial_run: Path, tmp_path: Path
) -> None:
    """Frames (.vtu), particle, fragment and contact tables, PVD series and history.csv as the
    serial run writes them; rank 0 alone prints, and warns as the serial run does (of the
    grains pressed into each other, the deepest over every rank's part). On 2 ranks only with
    --full: the default suite's restarts write most of the drum's run on 2 ranks (steps 600 to
    1,500 below; 850 to 1,500 in the frames in pieces)."""
    done = granulate(tmp_path, "--out", "out", ranks=ranks)
    assert done.returncode == 0, done.stderr
    assert done.stdout.count("finished at step 1500") == 1
    assert "bodies pressed" in done.stderr
    assert done.stderr == (serial_run.parent / "warnings.txt").read_text()
    assert_same_run(serial_run, tmp_path / "out")


def test_a_serial_run_restarts_on_ranks(serial_run: Path, tmp_path: Path) -> None:
    """Cut short serially at step 600 and resumed on 2 ranks: the folder ends as the
    uninterrupted serial run's. (Ranks to fewer ranks: the frames in pieces' test; serially
    to 3 ranks: the node-level cut's.)"""
    cut = granulate(tmp_path, "--out", "out", "--steps", "600")
    assert cut.returncode == 0, cut.stderr
    resumed = granulate(tmp_path, "--out", "out", "--resume", ranks=2)
    assert resumed.returncode == 0, resumed.stderr
    assert "resuming from step 600" in resumed.stdout
    assert_same_run(serial_run, tmp_path / "out")


def test_an_input_error_on_k_ranks_is_reported_once_and_ends_every_rank(tmp_path: Path) -> None:
    """A folder that holds a run (refused on rank 0, which writes): one message, exit code 2
    from every rank (mpiexec passes the first non-zero), no hang, the old run intact."""
    first = granulate(tmp_path, "--out", "out", "--steps", "10")
    assert first.returncode == 0, first.stderr
    before = outputs(tmp_path / "out")
    done = granulate(tmp_path, "--out", "out", ranks=3)
    assert done.returncode == 2, done.stdout + done.stderr
    assert done.stderr.count("already holds a run") == 1, done.stderr
    assert "Traceback" not in done.stderr
    assert outputs(tmp_path / "out") == before


def test_a_time_step_above_the_stable_estimate_is_warned_of_once(tmp_path: Path) -> None:
    """dt 1.2e-6 s against the drum's stable estimate 1.081e-6 s, on 3 ranks: one warning (from
    rank 0, with the whole assembly's estimate), not one per rank and part, and the run goes
    on."""
    case = tmp_path / "drum_dt.yaml"
    case.write_text(
        CASE.read_text().replace("time: {steps: 1500}", "time: {steps: 20, dt: 1.2e-6}")
    )
    done = granulate(tmp_path, "--out", "out", ranks=3, case=case)
    assert done.returncode == 0, done.stderr
    assert done.stderr.count("exceeds the stable estimate 1.081e-06 s") == 1, done.stderr


def test_the_steps_contact_gave_way_are_the_serial_runs(tmp_path: Path) -> None:
    """The fourth grain thrown at 300 m/s: its contact gives way at the same steps on 3 ranks
    as serially, though the ranks holding the pair rebuild their parts in migrations (whose
    overlaps the checkpointed state does not keep; the rank keeps them). The percentages
    printed are those at the end of the chunk that saw it, which depends on timing."""
    case = tmp_path / "drum_fast.yaml"
    text = CASE.read_text().replace("velocity: [0.3, -4.0]}", "velocity: [300.0, -4.0]}")
    case.write_text(text.replace("time: {steps: 1500}", "time: {steps: 300}"))
    said = []
    for ranks, name in ((1, "serial"), (3, "ranks")):
        done = granulate(tmp_path, "--out", name, ranks=ranks, case=case)
        assert done.returncode == 0, done.stderr
        said.append(re.findall(r"past \d+% at step \d+", done.stderr))
    assert said[0] == said[1] == ["past 50% at step 6", "past 100% at step 23"]


def test_a_case_restarting_from_a_frame_runs_on_ranks(serial_run: Path, tmp_path: Path) -> None:
    """`restart:` (positions and velocities of the serial run's frame at step 1,000, bonds
    intact) on 2 ranks writes what the same case writes serially, from step 1,000 on."""
    frame = serial_run / "frames" / "frame_000008.vtu"
    case = tmp_path / "drum_restart.yaml"
    text = CASE.read_text().replace("time: {steps: 1500}", "time: {steps: 1250}")
    case.write_text(text + f"restart: {{file: {frame}, step: 1000}}\n")
    for ranks, name in ((1, "serial"), (2, "ranks")):
        done = granulate(tmp_path, "--out", name, ranks=ranks, case=case)
        assert done.returncode == 0, done.stderr
    assert [row["step"] for row in history(tmp_path / "serial")] == ["1000", "1125", "1250"]
    assert_same_run(tmp_path / "serial", tmp_path / "ranks", row_count=3)


def test_frames_in_pieces_join_to_the_serial_runs_frames(serial_run: Path, tmp_path: Path) -> None:
    """`output: {pieces: true}`, cut short on 3 ranks at step 850 and resumed on 2: each frame
    a .pvtu over one piece per rank (3 up to step 750, then 2), each of the nodes that rank
    owns (every node in one piece, its number the serial run's), which joined
    (read_vtu_point_data, as Results reads them) are the uninterrupted serial run's one-file
    frames bit for bit; the other files and history.csv are the serial run's."""
    case = tmp_path / "drum_pieces.yaml"
    case.write_text(
        CASE.read_text().replace("output: {every: 125}", "output: {every: 125, pieces: true}")
    )
    cut = granulate(tmp_path, "--out", "out", "--steps", "850", ranks=3, case=case)
    assert cut.returncode == 0, cut.stderr
    resumed = granulate(tmp_path, "--out", "out", "--resume", ranks=2, case=case)
    assert resumed.returncode == 0, resumed.stderr
    assert "resuming from step 850" in resumed.stdout
    frames = tmp_path / "out" / "frames"
    for k in range(13):
        expected = read_vtu_point_data(serial_run / "frames" / f"frame_{k:06d}.vtu")
        joined = read_vtu_point_data(frames / f"frame_{k:06d}.pvtu")
        np.testing.assert_array_equal(joined[0], expected[0])
        assert joined[1].keys() == expected[1].keys()
        for field, values in expected[1].items():
            np.testing.assert_array_equal(joined[1][field], values)
    for k, ranks in ((6, 3), (12, 2)):
        pieces = sorted((frames / f"frame_{k:06d}").iterdir())
        assert [p.name for p in pieces] == [f"piece_{r}.vtu" for r in range(ranks)]
        numbers = [read_vtu_point_data(p)[1]["Node_ID"] for p in pieces]
        assert all(len(n) > 0 for n in numbers)
        assert sorted(np.concatenate(numbers)) == list(range(len(expected[0])))
    assert [p for p in differing(serial_run, tmp_path / "out") if "frame_" not in p] == [
        "simulation.pvd"
    ]
    assert_same_history(serial_run, tmp_path / "out")


def test_a_polydisperse_pile_runs_on_ranks_at_the_serial_time_step(tmp_path: Path) -> None:
    """The example pile (examples/cases/pile_2d.yaml: 30 discs and hexagons packed from size
    distributions, each grain its own mesh size) on 2 ranks, 2,000 steps: each rank's
    time-step probe builds its own grains and each material's coarsest, and finds the contact
    estimate against every grain as a partner (their summaries gathered), so the time step,
    and with it every frame and history column but the searches, is the serial run's."""
    case = Path(__file__).parents[1] / "examples" / "cases" / "pile_2d.yaml"
    for ranks, name in ((1, "serial"), (2, "ranks")):
        done = granulate(tmp_path, "--out", name, "--steps", "2000", ranks=ranks, case=case)
        assert done.returncode == 0, done.stderr
    assert differing(tmp_path / "serial", tmp_path / "ranks") == []
    rows = [history(tmp_path / name) for name in ("serial", "ranks")]
    for row in (*rows[0], *rows[1]):
        del row[SEARCHES]
    assert rows[0] == rows[1] and len(rows[0]) == 2


def test_a_peridem_deck_with_peridems_damping_runs_on_ranks(tmp_path: Path) -> None:
    """PeriDEM's small compression deck with its contact damping on (Damping_On: true) under
    --peridem-compat (PeriDEM's damping between particle centres, and from its wall particles'
    nodes) on 2 ranks, 3,000 steps (the damping changes the run from step 2,000: 4 to 16 of
    history.csv's columns differ from the undamped run's at each row from there): the serial
    run's frames and tables, and history.csv's every column but the searches, which a part of
    fewer nodes makes less often (162 serially against 147 on 2 ranks and 123 on 3 over the
    deck's 20,000 steps)."""

    def damped(text: str) -> str:
        return text.replace("Damping_On: false", "Damping_On: true")

    deck = broken_deck(tmp_path, "compression_small_set", damped)
    assert deck.read_text().count("Damping_On: true") == 8
    for ranks, name in ((1, "serial"), (2, "ranks")):
        arguments = ("--out", name, "--steps", "3000", "--peridem-compat")
        done = granulate(tmp_path, *arguments, ranks=ranks, case=deck)
        assert done.returncode == 0, done.stderr
    assert_same_run(tmp_path / "serial", tmp_path / "ranks", 16, searches_within=None)


PLATE = Path(__file__).parent / "cases" / "notched_plate_mpi.yaml"


@pytest.fixture(scope="module")
def serial_plate(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The notched plate's serial run (tests/cases/notched_plate_mpi.yaml): its output folder."""
    folder = tmp_path_factory.mktemp("plate")
    done = granulate(folder, "--out", "out", case=PLATE)
    assert done.returncode == 0, done.stderr
    return folder / "out"


def test_one_body_is_cut_at_node_level_and_writes_the_serial_runs_outputs(
    serial_plate: Path, tmp_path: Path
) -> None:
    """The notched plate, one body with nothing to touch (contact: null), on 2 and 3 ranks: its
    nodes dealt to the ranks (granulate.parallel.node_split; whole grains could not give two
    ranks one body each), it breaks in two as serially, and every frame (Fragment_ID
    included), table, checkpoint and history row is the serial run's. Cut short on 3 ranks at
    step 350 and resumed on 2, and serially at step 650 and resumed on 3, so that 2 and 3
    ranks each write part of both runs, before the plate breaks (by step 400) and after."""
    assert history(serial_plate)[-1]["fragments"] == "2"
    for first, second, steps, name in ((3, 2, "350", "a"), (1, 3, "650", "b")):
        cut = granulate(tmp_path, "--out", name, "--steps", steps, ranks=first, case=PLATE)
        assert cut.returncode == 0, cut.stderr
        resumed = granulate(tmp_path, "--out", name, "--resume", ranks=second, case=PLATE)
        assert resumed.returncode == 0, resumed.stderr
        assert f"resuming from step {steps}" in resumed.stdout
        assert resumed.stdout.count("finished at step 1000") == 1
        assert_same_run(serial_plate, tmp_path / name, row_count=11)


def test_a_body_cut_at_node_level_writes_frames_in_pieces(
    serial_plate: Path, tmp_path: Path
) -> None:
    """`output: {pieces: true}` on 3 ranks, the first 500 steps (the plate breaks in two by
    step 400): each piece holds the nodes one rank owns, with their fragment labels from rank
    0 (a rank's own bonds cannot tell them), and the pieces joined are the serial run's frames
    bit for bit."""
    case = tmp_path / "plate_pieces.yaml"
    case.write_text(
        PLATE.read_text().replace("output: {every: 100,", "output: {every: 100, pieces: true,")
    )
    done = granulate(tmp_path, "--out", "out", "--steps", "500", ranks=3, case=case)
    assert done.returncode == 0, done.stderr
    for k in range(6):
        expected = read_vtu_point_data(serial_plate / "frames" / f"frame_{k:06d}.vtu")
        joined = read_vtu_point_data(tmp_path / "out" / "frames" / f"frame_{k:06d}.pvtu")
        np.testing.assert_array_equal(joined[0], expected[0])
        assert joined[1].keys() == expected[1].keys()
        for field, values in expected[1].items():
            np.testing.assert_array_equal(joined[1][field], values)
    pieces = sorted((tmp_path / "out" / "frames" / "frame_000005").iterdir())
    numbers = [read_vtu_point_data(p)[1]["Node_ID"] for p in pieces]
    assert [len(n) > 0 for n in numbers] == [True] * 3
    assert sorted(np.concatenate(numbers)) == list(range(len(expected[0])))
    assert len(set(expected[1]["Fragment_ID"])) == 2


def test_one_body_in_contact_on_two_ranks_is_refused_with_the_way_out(tmp_path: Path) -> None:
    """The notched plate with contact on (so its body cannot be cut at node level) on 2 ranks:
    one message naming the ranks and grains and what to do, exit code 2, no traceback."""
    case = tmp_path / "plate_contact.yaml"
    case.write_text(PLATE.read_text().replace("contact: null", "contact: {restitution: 0.5}"))
    done = granulate(tmp_path, "--out", "out", ranks=2, case=case)
    assert done.returncode == 2, done.stdout + done.stderr
    assert done.stderr.count("2 ranks for 1 grain(s): a run with contact gives each rank") == 1
    assert "contact: null" in done.stderr and "Traceback" not in done.stderr


def test_a_body_cut_at_node_level_that_blows_up_ends_every_rank(tmp_path: Path) -> None:
    """The plate's end yanked at 10 km/s on 3 ranks: the rank owning the node that outruns its
    mesh size reports the instability once, naming the node as the serial run does, and every
    rank ends (no hang, no traceback)."""
    case = tmp_path / "plate_yanked.yaml"
    text = PLATE.read_text().replace("velocity: [1.0, 0]", "velocity: [1.0e+4, 0]")
    case.write_text(text.replace("ramp_time: 2.0e-5", "ramp_time: 1.0e-7"))
    done = granulate(tmp_path, "--out", "out", ranks=3, case=case)
    assert done.returncode == 1, done.stdout + done.stderr
    assert done.stderr.count("became unstable at step 2") == 1, done.stderr
    assert "node 2409 of particle 0" in done.stderr
    assert "Traceback" not in done.stderr


def bench_ranks(*arguments: str, ranks: int = 2) -> subprocess.CompletedProcess[str]:
    """`granulate bench --ranks ...` on `ranks` MPI ranks; a hang fails after 5 minutes."""
    command = [mpiexec(), "-n", str(ranks), sys.executable, "-m", "granulate", "bench"]
    return subprocess.run(
        [*command, "--ranks", *arguments], capture_output=True, text=True, timeout=300
    )


def test_bench_ranks_prints_each_ranks_speed_and_communication() -> None:
    """`mpiexec -n 2 granulate bench --ranks --quick --json` (the 3D pile, 200 grains): one JSON
    object, from rank 0: a row per rank, whose grains and nodes add up to the case's, each
    rank holding the other's nearby grains as ghosts, with its work, speed and time shares,
    and the ghost and cap margins; one thread per rank by default."""
    done = bench_ranks("--quick", "--json")
    assert done.returncode == 0, done.stderr
    (line,) = done.stdout.splitlines()
    result = json.loads(line)
    assert (result["case"], result["ranks"], result["threads"], result["steps"]) == (
        "pile3d",
        2,
        1,
        20,
    )
    rows = result["rows"]
    assert len(rows) == 2
    assert sum(row["grains"] for row in rows) == result["grains"] == 200
    # at rest: no migration, and the default margin kept: the largest grain's bounding radius
    # (a cube's, its nodes' corner 1.08 mm from its centre)
    assert (result["migrations"], result["margin_widenings"]) == (0, 0)
    assert 1e-3 < result["margin"] < 1.2e-3
    # and the default cap margin kept: half the mesh size (R/h = 4)
    assert (result["cap_margin"], result["cap_margin_widenings"]) == (0.125e-3, 0)
    assert sum(row["nodes"] for row in rows) == 51_712
    # the ranks' work (nodes, bond copies, list entries) within the balance threshold of the
    # mean (measured 206,967 and 208,445), no rebalance in the timed steps
    work = [row["work"] for row in rows]
    assert all(w > 51_712 / 2 for w in work) and max(work) <= 1.1 * sum(work) / 2
    assert result["rebalance_steps"] == []
    for row in rows:
        assert 0 < row["ghost_nodes"] < row["nodes"]
        assert 0 < row["exchanged_nodes"] <= row["ghost_nodes"]  # the caps: near nodes
        assert row["node_steps_per_s"] > 0
        shares = ("exchange", "check", "caps", "migrate")
        assert all(0 <= row[f"{name}_share"] < 1 for name in shares)
        assert 0 <= row["wait_share"] <= row["exchange_share"]
        assert row["collect_share"] == 0


def test_bench_ranks_measures_one_body_cut_at_node_level() -> None:
    """`mpiexec -n 2 granulate bench --ranks --case block --quick --json` (the notched block
    made small): a row per rank with about half the nodes, each receiving the
    other's nodes bonded to its own (the halo, a part of its own), with its speed and exchange
    share; --grains refused (one body)."""
    done = bench_ranks("--case", "block", "--quick", "--json")
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout)
    assert (result["case"], result["ranks"], result["steps"]) == ("block", 2, 20)
    rows = result["rows"]
    total = sum(row["nodes"] for row in rows)
    assert len(rows) == 2 and total > 500
    for row in rows:
        assert row["nodes"] > 0.4 * total  # bisected by bonds: about half each
        assert 0 < row["halo_nodes"] < row["nodes"]
        assert row["node_steps_per_s"] > 0 and 0 <= row["exchange_share"] < 1
        assert 0 <= row["wait_share"] <= row["exchange_share"]
    refused = bench_ranks("--case", "block", "--quick", "--grains", "5")
    assert refused.returncode == 2 and "--grains does not apply" in refused.stderr


def test_bench_ranks_fine_grains_send_caps() -> None:
    """`--case fine2d --quick` (40 discs and hexagons at 16 nodes per radius): each step sends
    each rank less than half the ghost nodes it holds."""
    done = bench_ranks("--case", "fine2d", "--quick", "--json")
    assert done.returncode == 0, done.stderr
    rows = json.loads(done.stdout)["rows"]
    assert all(0 < row["exchanged_nodes"] < 0.5 * row["ghost_nodes"] for row in rows)


def test_bench_ranks_shatter_breaks_grains() -> None:
    """`--case shatter --quick` (40 brittle grains thrown into each other): bonds break in the
    timed steps, and the result counts them."""
    done = bench_ranks("--case", "shatter", "--quick", "--json")
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout)
    assert result["bonds_broken"] > 0
    assert sum(row["grains"] for row in result["rows"]) == 40


def test_bench_ranks_follows_the_load_balance_it_is_given() -> None:
    """`--load-balance every=5` on the quick drum: in the 20 timed steps (21-40) the ranks
    compare their work at steps 25, 30, 35 and 40 (at the default every 100, never); the
    result names the settings."""
    for given, checks in (("every=5", 4), ("threshold=inf", 0)):
        done = bench_ranks("--case", "drum", "--quick", "--json", "--load-balance", given)
        assert done.returncode == 0, done.stderr
        result = json.loads(done.stdout)
        assert result["load_balance"] == LoadBalance.from_text(given).as_text()
        assert result["balance_checks"] == checks and result["rebalance_steps"] == []


def test_bench_ranks_refuses_what_it_cannot_run_once() -> None:
    """A case it does not have, a load balance it cannot read, or one for a body cut at node
    level: one message, exit 2 from every rank. --collect-every or --load-balance without
    --ranks: one message, exit 2."""
    refusals = [
        (("--case", "lps3d_lattice"), "unknown distributed benchmark case 'lps3d_lattice'"),
        (("--quick", "--load-balance", "evry=5"), "did you mean 'every'"),
        (("--case", "block", "--load-balance", "every=5"), "--load-balance does not apply"),
    ]
    for arguments, message in refusals:
        done = bench_ranks(*arguments)
        assert done.returncode == 2, done.stderr
        assert done.stderr.count(message) == 1, done.stderr
    for option in (("--collect-every", "5"), ("--load-balance", "every=5")):
        done = subprocess.run(
            [sys.executable, "-m", "granulate", "bench", *option],
            capture_output=True,
            text=True,
            timeout=60,
        )
        assert done.returncode == 2
        assert "go with --ranks" in done.stderr
