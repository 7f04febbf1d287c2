"""A distributed run's checkpoint in pieces (issue 17, docs/parallel.md): no rank holds more than
its own grains' states, so a run too large for one process's memory can still checkpoint.

At the checkpoint's path, rank 0 writes a header (granulate.io.checkpoint's format: the set-up's
fingerprint, step, time, output bookkeeping, the contact scalars every rank shares at that step,
and which piece holds each grain). Beside it, in ``<path>.pieces/<step>-<token>/``, each rank
writes ``piece_<rank>.npz``: the states of the grains it owns (transplant.GrainState, in global
node numbers), with their own checksum. The pieces are written first, in a folder of their own,
and the header replaces the last one atomically after them; only then are the last checkpoint's
pieces removed, so a run killed at any moment leaves a whole checkpoint.

It restarts on any number of ranks: rank 0 reads the header, each rank reads some of the pieces
(piece j on rank j mod K), the grains are cut anew where they are (their bounding spheres, one
allgather) and each goes to the ranks that hold it (one all-to-all); or serially, one process
reading every piece (restore_whole). Either way the run goes on bit for bit.
"""

from __future__ import annotations

import secrets
import shutil
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from granulate import checkpoints
from granulate.errors import InputError
from granulate.io import checkpoint as checkpoint_file
from granulate.parallel.agreement import on_root, together
from granulate.parallel.transplant import GrainState, restore_grains

if TYPE_CHECKING:
    from granulate.parallel.engine import DistributedRun
    from granulate.writers.outputs import Outputs

# Each GrainState field's kind and the shape of one of its rows.
_FIELDS: dict[str, tuple[type[np.generic], tuple[int, ...]]] = {
    "positions": (np.float64, (3,)),
    "velocities": (np.float64, (3,)),
    "forces": (np.float64, (3,)),
    "dilatation": (np.float64, ()),
    "opened_rest": (np.float64, ()),
    "bonds": (np.uint8, ()),
    "roots": (np.int64, ()),
    "pair_springs": (np.int64, (2,)),
    "pair_spring_values": (np.float64, (3,)),
    "wall_springs": (np.int64, (3,)),
    "wall_spring_values": (np.float64, (3,)),
    "collisions": (np.int64, (3,)),
    "collision_values": (np.float64, (13,)),
}


def pack(states: dict[int, GrainState]) -> dict[str, NDArray[Any]]:
    """Grain states as flat arrays: the grains (increasing), and per GrainState field the
    grains' rows one after another and each grain's row count (``<field>_rows``)."""
    grains = sorted(states)
    arrays: dict[str, NDArray[Any]] = {"grains": np.array(grains, dtype=np.int64)}
    for name, (kind, row) in _FIELDS.items():
        values = [np.asarray(getattr(states[g], name), kind).reshape(-1, *row) for g in grains]
        arrays[name] = np.concatenate([np.zeros((0, *row), kind), *values])
        arrays[f"{name}_rows"] = np.array([len(v) for v in values], dtype=np.int64)
    return arrays


def unpack(arrays: dict[str, Any], source: Path) -> dict[int, GrainState]:
    """The grain states `pack` made of them, from the piece at `source` (InputError when its
    row counts do not add up)."""
    grains = np.asarray(arrays["grains"], dtype=np.int64)
    fields: dict[str, list[NDArray[Any]]] = {}
    for name, (kind, row) in _FIELDS.items():
        rows = np.asarray(arrays[f"{name}_rows"], dtype=np.int64)
        values = np.asarray(arrays[name], kind).reshape(-1, *row)
        if len(rows) != len(grains) or int(rows.sum()) != len(values):
            raise InputError(f"checkpoint piece {source} is not whole; remove it and start over")
        fields[name] = np.split(values, np.cumsum(rows)[:-1])
    return {
        int(g): GrainState(**{name: fields[name][k] for name in _FIELDS})
        for k, g in enumerate(grains)
    }


def save(run: DistributedRun, path: str | Path, outputs: Outputs | None) -> Path:
    """Every rank of `run`: its owned grains' states as its piece of the checkpoint at `path`,
    then rank 0's header (with `outputs`' bookkeeping). An error on any rank ends every rank
    (agreement.together) and leaves the last checkpoint as it was. The path, on every rank."""
    comm, target = run.comm, Path(path)
    fingerprint = run.fingerprint()
    moment, states = run.checkpoint_part()
    step, rank = int(moment["step"]), comm.Get_rank()
    folder = Path(comm.bcast(on_root(comm, lambda: _new_folder(target, step)), root=0))
    try:
        piece = folder / f"piece_{rank}.npz"
        together(
            comm,
            lambda: checkpoint_file.save(piece, pack(states), {"checkpoint": folder.name}),
            "writing its piece of the checkpoint",
        )
        grains = comm.gather(sorted(states), root=0)
        header = checkpoints.header_of(step, float(moment["time"]), fingerprint, outputs)
        on_root(comm, lambda: _write_header(target, folder, grains, moment, header))
    except Exception:
        if rank == 0:  # the last checkpoint stays whole; the pieces of this one go
            shutil.rmtree(folder, ignore_errors=True)
        raise
    return target


def _new_folder(path: Path, step: int) -> str:
    """A new folder for the pieces of the checkpoint at `path` at `step`, made, as text: its
    name is the step and a random token, so it is never the last checkpoint's."""
    folder = checkpoints.pieces_folder(path) / f"{step}-{secrets.token_hex(4)}"
    folder.mkdir(parents=True)
    return str(folder)


def _write_header(
    path: Path,
    folder: Path,
    grains: list[list[int]] | None,
    moment: dict[str, Any],
    header: dict[str, Any],
) -> None:
    """Rank 0: the checkpoint's header at `path` (atomically), for its pieces in `folder`,
    piece r holding the `grains`[r], at `moment`; then the pieces of the checkpoints before
    are removed. InputError, and no header, when rank 0 cannot see every piece (the ranks
    wrote to disks they do not share: the checkpoint could not be read back)."""
    assert grains is not None
    missing = [
        f"piece_{r}.npz" for r in range(len(grains)) if not (folder / f"piece_{r}.npz").is_file()
    ]
    if missing:
        raise InputError(
            f"checkpoint {path}: {', '.join(missing)} written by the other ranks cannot be seen "
            f"in {folder} from rank 0: the checkpoint must be on a file system every rank "
            "shares (on a cluster, not a node's local disk); choose its path or --out there"
        )
    piece_of_grain = np.full(sum(len(g) for g in grains), -1, dtype=np.int64)
    for piece, held in enumerate(grains):
        piece_of_grain[held] = piece
    header = {**header, "pieces": {"folder": folder.name, "count": len(grains)}}
    checkpoint_file.save(path, {**moment, "piece_of_grain": piece_of_grain}, header)
    for old in folder.parent.iterdir():
        if old != folder:
            shutil.rmtree(old, ignore_errors=True)


def read_pieces(
    path: str | Path, header: dict[str, Any], piece_of_grain: NDArray[np.int64], pieces: list[int]
) -> dict[int, GrainState]:
    """The grain states in the `pieces` (their numbers) of the checkpoint at `path` with
    `header`: InputError when a piece is missing, damaged, or not of this checkpoint."""
    folder = checkpoints.pieces_folder(Path(path)) / header["pieces"]["folder"]
    states: dict[int, GrainState] = {}
    for number in pieces:
        source = folder / f"piece_{number}.npz"
        if not source.is_file():
            raise InputError(
                f"checkpoint {path} is missing its piece {source}; restore the folder "
                f"{folder} whole, or run without --resume to start over"
            )
        arrays, piece = checkpoint_file.load(source)
        mine = unpack(arrays, source)
        if piece.get("checkpoint") != header["pieces"]["folder"] or not np.array_equal(
            sorted(mine), np.flatnonzero(piece_of_grain == number)
        ):
            raise InputError(
                f"checkpoint piece {source} does not belong to checkpoint {path}; restore the "
                f"folder {folder} whole, or run without --resume to start over"
            )
        states |= mine
    return states


def restore_whole(
    core: Any, path: str | Path, state: dict[str, Any], header: dict[str, Any], nodes: int
) -> None:
    """Put the checkpoint in pieces at `path` (its header's `state` and `header`) into `core`,
    a whole simulation of `nodes` nodes: every piece read, every grain restored."""
    piece_of_grain = np.asarray(state["piece_of_grain"], dtype=np.int64)
    states = read_pieces(path, header, piece_of_grain, list(range(header["pieces"]["count"])))
    every = [states[g] for g in range(len(piece_of_grain))]
    restore_grains(core, every, np.arange(nodes), state)
