"""A distributed run's checkpoint in pieces, the parts one process can check
(granulate/parallel/checkpoint_pieces.py): grain states packed into a piece and read back, the
set-up fingerprint made of grain digests alike from the whole model and from ranks' parts, and
a whole checkpoint replacing pieces. tests/test_mpi.py writes and reads pieces on 2 and 3 ranks
(tests/mpi_checkpoint_check.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import granulate as gr
from assemblies import tumbling_drum
from granulate import checkpoints, fingerprints
from granulate.io import checkpoint as checkpoint_file
from granulate.io.run_folder import CHECKPOINT_PIECES
from granulate.parallel import checkpoint_pieces
from granulate.parallel.transplant import GrainState, grain_states


@pytest.fixture(scope="module")
def drum_states(tmp_path_factory: pytest.TempPathFactory) -> dict[int, GrainState]:
    """The drum's four grains after 1,500 steps: broken bonds, collisions in progress,
    friction springs between grains and with the drum."""
    sim = tumbling_drum(tmp_path_factory.mktemp("drum"), outputs=False)
    sim.run(1500)
    saved = dict(sim.core.checkpoint())
    slices = {body.index: body.node_slice for body in sim.bodies}
    return grain_states(sim, saved, np.arange(sim.node_count), slices)


def test_grain_states_come_back_from_a_piece_unchanged(
    drum_states: dict[int, GrainState], tmp_path: Path
) -> None:
    """Every field of grains 1 and 3 (with friction springs and collisions: not empty), bit
    for bit and with its shape, through a piece's file; a piece of no grain too."""
    states = {g: drum_states[g] for g in (3, 1)}
    assert sum(len(s.pair_springs) + len(s.collisions) for s in states.values()) > 0
    for chosen in (states, {}):
        piece = tmp_path / "piece_0.npz"
        checkpoint_file.save(piece, checkpoint_pieces.pack(chosen), {"checkpoint": "test"})
        arrays, header = checkpoint_file.load(piece)
        back = checkpoint_pieces.unpack(arrays, piece)
        assert sorted(back) == sorted(chosen) and header["checkpoint"] == "test"
        for grain, state in chosen.items():
            for name in checkpoint_pieces._FIELDS:
                value, expected = getattr(back[grain], name), getattr(state, name)
                assert value.dtype == expected.dtype and np.array_equal(value, expected), name
                assert value.shape == expected.shape or len(expected) == 0, name


def test_a_piece_whose_rows_do_not_add_up_is_refused(
    drum_states: dict[int, GrainState], tmp_path: Path
) -> None:
    arrays = checkpoint_pieces.pack({0: drum_states[0]})
    arrays["bonds"] = arrays["bonds"][:-1]
    with pytest.raises(gr.InputError, match=r"piece .*piece_0.npz is not whole"):
        checkpoint_pieces.unpack(arrays, tmp_path / "piece_0.npz")


def test_the_fingerprint_of_a_ranks_parts_is_the_whole_models() -> None:
    """Each grain's digest (reference positions, volumes, bonds per node) from a part of two
    grains (as a rank builds it) is the whole model's, so the set-up's fingerprint is the
    same whoever makes it; one grain's volumes changed by one bit change it."""
    sim = tumbling_drum(Path("unused"), outputs=False)
    whole = sim.fingerprint()
    digests = b""
    for grains in ([0, 1], [2, 3]):
        part, _ = sim._subdomain(np.array(grains))
        slices = [part.bodies[k].node_slice for k in range(len(grains))]
        digests += fingerprints.model_grain_digests(part.model, slices)
    made = fingerprints.fingerprint(sim, fingerprints.set_up_digest(sim, digests), sim.dt)
    assert made == whole
    model = sim.model
    offsets = np.asarray(model.bond_offsets)
    grain = sim.bodies[2].node_slice
    volumes = np.array(model.volumes[grain])
    volumes[0] = np.nextafter(volumes[0], np.inf)
    changed = fingerprints.grain_digest(
        model.reference_positions[grain], volumes, offsets[grain.start : grain.stop + 1]
    )
    assert changed != digests[64:96]


def test_a_whole_checkpoint_replaces_the_pieces_of_one_before(tmp_path: Path) -> None:
    """A serial run continued from a distributed run's checkpoint writes its own, whole, at
    the same path: the pieces of the one before go with it. (A run folder's --overwrite
    removes them by the name they have there.)"""
    sim = tumbling_drum(tmp_path, outputs=False)
    assert checkpoints.pieces_folder(tmp_path / "checkpoint.npz").name == CHECKPOINT_PIECES
    stale = checkpoints.pieces_folder(tmp_path / "checkpoint.npz") / "100-0a1b2c3d"
    stale.mkdir(parents=True)
    (stale / "piece_0.npz").write_bytes(b"a piece")
    sim.save_checkpoint(tmp_path / "checkpoint.npz")
    assert not checkpoints.pieces_folder(tmp_path / "checkpoint.npz").exists()
    assert (tmp_path / "checkpoint.npz").is_file()
