"""The set-up fingerprint a checkpoint must match (granulate.checkpoints): what the run is made
of, hashed so that every process makes the same text without holding the whole model. Each
grain's nodes (reference positions, volumes, bonds per node) are hashed on their own
(grain_digest), so a rank of a distributed run hashes the grains it owns and rank 0 puts the
digests together in grain order; then the loading, walls and contact (materials named by the
order in which the bodies first use them), and the time step, gravity, damping and the case
file's hash."""

from __future__ import annotations

import hashlib
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from granulate.core_model import materials_in_core_order
from granulate.io import checkpoint as checkpoint_file

if TYPE_CHECKING:
    from granulate.simulation import Simulation


#: The bytes of one grain_digest (SHA-256).
GRAIN_DIGEST_BYTES = hashlib.sha256().digest_size


def grain_digest(
    reference: NDArray[np.float64], volumes: NDArray[np.float64], bond_offsets: NDArray[Any]
) -> bytes:
    """SHA-256 of one grain's reference positions, node volumes and bonds per node (from its
    nodes' `bond_offsets`, one more than nodes): what a checkpoint's set-up fingerprint holds of
    each grain, the same whether the grain's rank holds the whole model or only its grains."""
    digest = hashlib.sha256()
    for values in (reference, volumes, np.diff(np.asarray(bond_offsets, dtype=np.int64))):
        digest.update(np.ascontiguousarray(values).tobytes())
    return digest.digest()


def model_grain_digests(model: Any, slices: list[slice]) -> bytes:
    """grain_digest of each grain (its node slice in `model`, a core Model), in order."""
    reference, volumes = model.reference_positions, model.volumes
    offsets = np.asarray(model.bond_offsets)
    return b"".join(
        grain_digest(reference[s], volumes[s], offsets[s.start : s.stop + 1]) for s in slices
    )


def set_up_digest(sim: Simulation, grain_digests: bytes) -> str:
    """The part of sim's fingerprint fixed when it is set up: its grains (`grain_digests`, one
    grain_digest per body in order), loading, walls and contact, with materials named by the
    order in which the bodies first use them (the core's order), so that it is the same in
    every process and needs no whole model."""
    return checkpoint_file.fingerprint(
        grain_digests,
        *sim._loading.fingerprint_parts(),
        *sim._interactions.fingerprint_parts(materials_in_core_order(sim.bodies)),
    )


def whole_model_digest(sim: Simulation, model: Any) -> str:
    """set_up_digest of sim from `model`, a core Model of every body (the whole simulation's,
    or a node-split rank's, which holds them all)."""
    slices = [body.node_slice for body in sim.bodies]
    return set_up_digest(sim, model_grain_digests(model, slices))


def fingerprint(sim: Simulation, setup: str, time_step: float) -> str:
    """Identifies the set-up a checkpoint belongs to: the `setup` digest (set_up_digest), the
    time step [s], gravity, damping and sim's case_fingerprint."""
    return checkpoint_file.fingerprint(
        setup,
        float(time_step),
        repr(sim.gravity.tolist()),
        sim._viscous_damping,
        sim.case_fingerprint,
    )
