"""Run under `mpiexec -n K python tests/mpi_checkpoint_check.py CASE` (tests/test_mpi.py does):
a distributed run's checkpoint in pieces (granulate/parallel/checkpoint_pieces.py) on the
checkpoint tests' tumbling drum (tests/assemblies.py). Rank 0 prints one line; the exit
status is non-zero when the check fails.

`pieces`: a checkpoint of 600 steps written on K - 1 ranks is a header and one piece per rank;
it continues on all K ranks bit for bit as the serial run, without rank 0 ever building the
whole simulation, and a second checkpoint at the same path leaves only its own pieces.

`damaged`: a checkpoint missing a piece, or holding a piece of another checkpoint, is refused on
every rank with one InputError naming the piece, and the run's history.csv is left as it was.

`write-fail`: the last rank failing to write its piece (a full disk) ends every rank; the
checkpoint written before is left whole (its header's bytes, its pieces) and a run continues
from it.

`unshared`: the last rank writing its piece to a disk rank 0 does not see (a node's own disk)
ends every rank with one InputError that says so, before any header names the piece; the
checkpoint before is left whole.

`cli`: `granulate run` (in this process, on the ranks) of the drum case with frames in pieces,
cut short and resumed from its checkpoint in pieces, never builds rank 0's whole simulation;
`cli-one-file`: the same with each frame in one file, which rank 0 joins of the ranks' rows.
"""

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
from assemblies import tumbling_drum
from granulate import checkpoints, cli
from granulate.io import checkpoint as checkpoint_file
from granulate.parallel import DistributedRun, checkpoint_pieces
from rank_zero import wait_asleep


def pieces_of(path: Path) -> list[str]:
    """The files in the pieces folder of the checkpoint at `path`, as folder/file."""
    folder = checkpoints.pieces_folder(path)
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file())


def messages_of(action: Callable[[], object], comm: MPI.Comm) -> list[str] | None:
    """action() on every rank; on rank 0 each rank's "ErrorType: message" (empty if it
    finished), None on the others."""
    try:
        action()
        message = ""
    except (gr.InputError, RuntimeError, OSError) as error:
        message = f"{type(error).__name__}: {error}"
    return comm.gather(message, root=0)


def check_pieces(folder: Path, comm: MPI.Comm) -> int:
    """0 when a checkpoint written on K - 1 ranks at step 600 (a header and a piece per rank)
    continues on all K ranks (more ranks than pieces) to step 700 bit for bit as
    the serial run, rank 0's simulation never built, and a second checkpoint at the same path
    leaves only its own pieces."""
    path, rank = folder / "checkpoint.npz", comm.Get_rank()
    fewer = comm.Split(0 if rank < comm.Get_size() - 1 else MPI.UNDEFINED, rank)
    built = False
    if fewer != MPI.COMM_NULL:
        first = DistributedRun(tumbling_drum(folder, outputs=False), fewer)
        first.run(600)
        first.save_checkpoint(path)
        built = first._sim._core is not None
    wait_asleep(comm)
    after_first = pieces_of(path) if rank == 0 else []
    second = DistributedRun(tumbling_drum(folder, outputs=False), comm)
    second.load_checkpoint(path)
    second.run(100)
    second.save_checkpoint(path)
    fields = {name: second.gather(name) for name in ("positions", "velocities", "forces")}
    built = comm.gather(built or second._sim._core is not None, root=0)
    if rank != 0:
        return 0
    serial = tumbling_drum(folder, outputs=False)
    serial.core.run(700)
    same = {name: bool(np.array_equal(fields[name], getattr(serial, name))) for name in fields}
    after_second = pieces_of(path)
    print(
        f"first {after_first}; second {after_second}; rank 0 built the whole: {any(built)}; "
        f"continued on {comm.Get_size()} ranks as serially: {same}"
    )
    pieces = [{f.split("/")[1] for f in files} for files in (after_first, after_second)]
    folders = [len({f.split("/")[0] for f in files}) for files in (after_first, after_second)]
    names = [{f"piece_{r}.npz" for r in range(k)} for k in (comm.Get_size() - 1, comm.Get_size())]
    steps = [files[0].split("-")[0] for files in (after_first, after_second)]
    whole = folders == [1, 1] and pieces == names and steps == ["600", "700"]
    return 0 if whole and all(same.values()) and not any(built) else 1


def check_damaged(folder: Path, comm: MPI.Comm) -> int:
    """0 when a checkpoint with a piece missing, or a piece of another checkpoint, is refused
    with the same InputError on every rank, and history.csv is left as it was."""
    sim = tumbling_drum(folder, comm=comm)
    sim.run(600)  # checkpoints every 1,000 steps: the one below is the folder's
    path = sim.save_checkpoint(folder / "checkpoint.npz")
    other = sim.save_checkpoint(folder / "other.npz")  # the same step: another token
    rank, history = comm.Get_rank(), folder / "history.csv"
    before = history.read_bytes() if rank == 0 else b""
    found = []
    for damage in ("missing", "foreign"):
        if rank == 0:
            piece = next(checkpoints.pieces_folder(path).glob("*/piece_1.npz"))
            kept = piece.read_bytes()
            piece.unlink()
            if damage == "foreign":
                shutil.copy(next(checkpoints.pieces_folder(other).glob("*/piece_0.npz")), piece)
        comm.Barrier()
        resumed = tumbling_drum(folder, comm=comm, resume=True)
        found.append(messages_of(lambda: resumed.load_checkpoint(path), comm))  # noqa: B023
        if rank == 0:
            piece.write_bytes(kept)
    if rank != 0:
        return 0
    same_history = history.read_bytes() == before
    print(f"missing: {found[0]}; foreign: {found[1]}; history.csv kept {same_history}")
    refused = all(
        len(set(messages)) == 1 and messages[0].startswith("InputError") and expected in messages[0]
        for messages, expected in zip(found, ("missing its piece", "does not belong"), strict=True)
    )
    return 0 if refused and same_history else 1


class LocalDisk:
    """granulate.io.checkpoint as seen by a rank that writes to a disk of its own: its pieces
    go to `where`, a folder no other rank reads."""

    def __init__(self, where: Path) -> None:
        self.where = where

    def save(self, path: Path, state: dict[str, Any], header: dict[str, Any]) -> None:
        checkpoint_file.save(self.where / Path(path).name, state, header)

    def __getattr__(self, name: str) -> Any:
        return getattr(checkpoint_file, name)


def check_failed_save(folder: Path, comm: MPI.Comm, failure: str) -> int:
    """0 when a checkpoint the last rank cannot give (`failure`: "full", its disk full; or
    "local", its piece on a disk rank 0 does not see) ends every rank, the checkpoint written
    before is left whole, and a run continues from it."""
    path = folder / "checkpoint.npz"
    run = DistributedRun(tumbling_drum(folder, outputs=False), comm)
    run.run(300)
    run.save_checkpoint(path)
    rank, last = comm.Get_rank(), comm.Get_size() - 1
    header = path.read_bytes() if rank == 0 else b""
    pieces = pieces_of(path) if rank == 0 else []
    run.run(300)
    if rank == last and failure == "full":

        def full_disk(*_: object) -> object:
            raise OSError(28, "No space left on device")

        checkpoint_pieces.pack = full_disk  # type: ignore[assignment]
    if rank == last and failure == "local":
        (folder / "local_disk").mkdir()  # beside the checkpoint, not where its pieces go
        checkpoint_pieces.checkpoint_file = LocalDisk(folder / "local_disk")  # type: ignore[assignment]
    messages = messages_of(lambda: run.save_checkpoint(path), comm)
    resumed = DistributedRun(tumbling_drum(folder, outputs=False), comm)
    resumed.load_checkpoint(path)
    resumed.run(10)
    step = int(resumed.local.core.step)
    if rank != 0:
        return 0
    kept = path.read_bytes() == header and pieces_of(path) == pieces
    print(f"{failure}: messages {messages}; checkpoint kept {kept}; continued to step {step}")
    if failure == "full":
        failed = messages[last].startswith("OSError") and all(
            f"rank {last} failed" in m for m in messages[:last]
        )
    else:
        failed = len(set(messages)) == 1 and "cannot be seen" in messages[0]
    return 0 if failed and kept and step == 310 else 1


def check_command_line(folder: Path, comm: MPI.Comm, pieces: bool) -> int:
    """0 when `granulate run` of the drum case, its frames in pieces (`pieces`) or each in one
    file, cut short at step 850 (its checkpoints in pieces, at 500 and at the end) and
    resumed to step 1,500, never builds rank 0's whole simulation (the only one given the
    communicator), and both commands succeed."""
    case = folder / "drum.yaml"
    if comm.Get_rank() == 0:
        text = (Path(__file__).parent / "cases" / "drum_mpi.yaml").read_text()
        if pieces:
            text = text.replace("output: {every: 125}", "output: {every: 125, pieces: true}")
        case.write_text(text)
    comm.Barrier()
    builds = []
    build = gr.Simulation._build

    def watched(sim: gr.Simulation) -> object:
        before = sim._core is None
        core = build(sim)
        if sim._comm is not None and before:
            builds.append(sim.step)
        return core

    gr.Simulation._build = watched  # type: ignore[method-assign]
    out = ["--out", str(folder / "out"), "--quiet"]
    codes = [
        cli.main(["run", str(case), *out, "--steps", "850"]),
        cli.main(["run", str(case), *out, "--resume"]),
    ]
    gr.Simulation._build = build  # type: ignore[method-assign]
    every_build = comm.gather(builds, root=0)
    if comm.Get_rank() != 0:
        return 0
    files = pieces_of(folder / "out" / "checkpoint.npz")
    print(f"exit codes {codes}; rank 0's whole builds {every_build[0]}; checkpoint {files}")
    at_end = len(files) == comm.Get_size() and all(f.startswith("1500-") for f in files)
    return 0 if codes == [0, 0] and not every_build[0] and at_end else 1


CASES = {
    "pieces": check_pieces,
    "damaged": check_damaged,
    "write-fail": functools.partial(check_failed_save, failure="full"),
    "unshared": functools.partial(check_failed_save, failure="local"),
    "cli": functools.partial(check_command_line, pieces=True),
    "cli-one-file": functools.partial(check_command_line, pieces=False),
}


def main() -> int:
    comm = MPI.COMM_WORLD
    warnings.filterwarnings("ignore", message="contact.*bodies pressed")
    folder = Path(comm.bcast(tempfile.mkdtemp() if comm.Get_rank() == 0 else None, root=0))
    try:
        return CASES[sys.argv[1]](folder, comm)
    finally:
        wait_asleep(comm)  # while rank 0 compares
        if comm.Get_rank() == 0:
            shutil.rmtree(folder)


if __name__ == "__main__":
    sys.exit(main())
