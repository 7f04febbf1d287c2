"""Checkpoint files: everything a run needs to continue bit for bit.

A checkpoint is a NumPy .npz archive (zip, CRC-checked members) written atomically, holding
the core's state and contact history (``_core.Simulation.checkpoint()``) and a JSON header:
format version, granulate version, the model fingerprint, step, time, the state of the outputs
(frames written, PVD entries) and a SHA-256 checksum of the arrays (a file changed after it was
written is refused; the core also checks every array's size and range). A checkpoint is only
loaded into a simulation with the same fingerprint (same nodes, volumes, bonds, time step,
loading and walls).
"""

from __future__ import annotations

import hashlib
import io
import json
import zipfile
from pathlib import Path
from typing import Any

import numpy as np

from granulate.errors import InputError
from granulate.io.atomic import atomic_write

# 2: per-contact friction springs and per-node contact radii; 3: each collision's force-law
# exponent (the damping that gives the requested restitution); 4: contact against the
# particles' smooth surfaces; 5: the turned collision forces fading out in lasting contacts;
# 6: the rest overlaps of nodes opened by cracks; 7: the set-up fingerprinted grain by grain (a
# distributed run's checkpoint in pieces has no rank holding the whole model)
FORMAT = 7
HEADER = "__header__"
#: A distributed run's checkpoint at a path keeps its ranks' pieces in path + this, a folder.
PIECES_SUFFIX = ".pieces"


def content_checksum(arrays: dict[str, np.ndarray]) -> str:
    """SHA-256 of the arrays' names, kinds, shapes and bytes, in name order."""
    digest = hashlib.sha256()
    for name in sorted(arrays):
        value = np.ascontiguousarray(arrays[name])
        digest.update(f"{name}:{value.dtype.str}:{value.shape}".encode())
        digest.update(value.tobytes())
    return digest.hexdigest()


def save(path: str | Path, state: dict[str, Any], header: dict[str, Any]) -> None:
    """Write the core's checkpoint dict and a JSON header (with the checksum of the arrays) to
    ``path`` atomically."""
    arrays = {k: np.asarray(v) for k, v in state.items()}
    header = {"format": FORMAT, **header, "checksum": content_checksum(arrays)}
    arrays[HEADER] = np.frombuffer(json.dumps(header).encode(), np.uint8)
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    atomic_write(Path(path), buffer.getvalue())


def load(path: str | Path) -> tuple[dict[str, Any], dict[str, Any]]:
    """Read a checkpoint: (state dict for the core, header). Refuses missing, corrupted or
    foreign files with one clear InputError."""
    file = Path(path)
    if not file.is_file():
        raise InputError(f"checkpoint {file} does not exist; run without --resume to start over")
    try:
        with np.load(file, allow_pickle=False) as archive:
            data = {name: archive[name] for name in archive.files}
        header = json.loads(bytes(data.pop(HEADER)).decode())
    except (
        zipfile.BadZipFile,
        ValueError,
        KeyError,
        OSError,
        EOFError,
        UnicodeDecodeError,
    ) as error:
        raise InputError(
            f"checkpoint {file} is corrupted or not a granulate checkpoint ({error}); remove it "
            "and run without --resume"
        ) from None
    if header.get("format") != FORMAT:
        raise InputError(
            f"checkpoint {file} has format {header.get('format')!r}; this granulate reads "
            f"format {FORMAT} (format 1 predates the contact model with friction springs and "
            "per-node contact radii, format 2 the damping fitted to each collision's force law, "
            "format 3 contact against the particles' smooth surfaces, format 4 the turned "
            "collision forces fading out in lasting contacts, format 5 the rest overlaps of "
            "nodes that cracks open: their trajectories differ; format 6 fingerprints the "
            "set-up as a whole, not grain by grain); run without --resume to start over"
        )
    checksum = header.get("checksum")
    if checksum is not None and checksum != content_checksum(data):
        raise InputError(
            f"checkpoint {file} was changed after it was written (its arrays do not match the "
            "checksum in its header); remove it and run without --resume"
        )
    state: dict[str, Any] = {}
    for name, value in data.items():
        state[name] = value.item() if value.ndim == 0 else np.ascontiguousarray(value).reshape(-1)
    return state, header


def fingerprint(*parts: bytes | str | float | int) -> str:
    """SHA-256 of the parts, in order."""
    digest = hashlib.sha256()
    for part in parts:
        if isinstance(part, bytes):
            digest.update(part)
        else:
            digest.update(repr(part).encode())
        digest.update(b"\0")
    return digest.hexdigest()
