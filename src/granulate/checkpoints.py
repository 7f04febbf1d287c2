"""Checkpoints of a run: when they are written (every so many steps and/or minutes of wall
time, and on Ctrl-C or SIGTERM), the budget that keeps a run from becoming mostly writing, and
what one holds: the core's state (positions, velocities, forces, bond states, contact history,
time, step) and the output bookkeeping (frames, PVD series), so that a resumed run's outputs
are those of an uninterrupted one. The file format is granulate.io.checkpoint's."""

from __future__ import annotations

import shutil
import time as wallclock
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from granulate import resources
from granulate._version import __version__
from granulate.errors import InputError
from granulate.io import checkpoint as checkpoint_file

if TYPE_CHECKING:
    from granulate.simulation import Simulation
    from granulate.writers.outputs import Outputs

#: The most bytes a run's checkpoints may write in all: at 1 GB/s, 20 minutes of writing.
MOST_CHECKPOINT_BYTES = 1.2e12
#: A checkpoint's bytes per node: positions, velocities, forces and the contact lists'
#: positions at their build (24 each), dilatation and the probes' opened rests (8 each), the
#: lists' offsets (4); and per bond copy, its state (1). Measured: 97.6-98.0 % of the file
#: (its arrays' headers and the contact lists' entries are the rest; session 52).
CHECKPOINT_BYTES_PER_NODE = 116
CHECKPOINT_BYTES_PER_BOND = 1


def checkpoint_bytes(nodes: int, bonds: int) -> float:
    """About the bytes of a checkpoint of `nodes` nodes and `bonds` bond copies."""
    return CHECKPOINT_BYTES_PER_NODE * nodes + CHECKPOINT_BYTES_PER_BOND * bonds


@dataclass
class CheckpointPlan:
    """Where and how often a run writes its checkpoint (each replaces the last atomically)."""

    path: Path
    every_steps: int | None
    every_seconds: float | None
    last_wall_time: float = 0.0

    @classmethod
    def create(
        cls,
        steps: int | None,
        minutes: float | None,
        path: str | Path | None,
        output_directory: Path | None,
    ) -> CheckpointPlan:
        """The plan Simulation.checkpoint_every asks for, checked (InputError): `path`, or
        checkpoint.npz in the output directory."""
        if steps is not None and not (isinstance(steps, int) and steps > 0):
            raise InputError(f"checkpoint interval must be a positive number of steps, got {steps}")
        if minutes is not None and not (np.isfinite(minutes) and minutes > 0):
            raise InputError(
                f"checkpoint interval must be a positive number of minutes, got {minutes}"
            )
        if path is None:
            if output_directory is None:
                raise InputError("give a checkpoint path, or set output(...) first")
            path = output_directory / "checkpoint.npz"
        seconds = None if minutes is None else 60.0 * minutes
        return cls(Path(path), steps, seconds, wallclock.perf_counter())

    def steps_to_next(self, step: int) -> int | None:
        """Steps from `step` to the next checkpoint by step count (None: by time only)."""
        if not self.every_steps:
            return None
        return self.every_steps - step % self.every_steps

    def require_budget(self, steps: int, nodes: int, bonds: int) -> None:
        """InputError when checkpoints every few steps would make the run mostly writing: each
        holds the state (checkpoint_bytes) and replaces the last."""
        if not self.every_steps:
            return
        count = steps // self.every_steps
        size = checkpoint_bytes(nodes, bonds)
        if count * size > MOST_CHECKPOINT_BYTES:
            raise InputError(
                f"checkpoints every {self.every_steps} steps would write {count:,} checkpoints of "
                f"about {resources.size_text(size)} over this run ("
                f"{resources.size_text(count * size)}); checkpoint less often (every_steps), or "
                "every few minutes (every_minutes)"
            )

    def is_due(self, step: int) -> bool:
        """Whether a checkpoint is due at `step`: a checkpoint step, or its minutes passed."""
        if self.every_steps and step % self.every_steps == 0:
            return True
        elapsed = wallclock.perf_counter() - self.last_wall_time
        return self.every_seconds is not None and elapsed >= self.every_seconds

    def saved(self) -> None:
        """A checkpoint was written now: the minutes count from here."""
        self.last_wall_time = wallclock.perf_counter()


def header_of(step: int, time: float, fingerprint: str, outputs: Outputs | None) -> dict[str, Any]:
    """A checkpoint's header at `step` and `time` [s]: granulate's version, the set-up's
    `fingerprint` and the bookkeeping of `outputs` (frames written, intervals, PVD series)."""
    return {
        "granulate": __version__,
        "fingerprint": fingerprint,
        "step": int(step),
        "time": float(time),
        "output": None
        if outputs is None
        else {
            "frames": outputs.frames,
            "every": outputs.every,
            "history_every": outputs.history_every,
            "pvd": outputs.pvd.entries,
        },
    }


def save(
    sim: Simulation, path: str | Path, outputs: Outputs | None, fingerprint: str | None = None
) -> Path:
    """Write sim's whole state and the bookkeeping of its `outputs` to `path` atomically, then
    remove the pieces of a distributed run's checkpoint there before (pieces_folder).
    `fingerprint`: sim's, when already known."""
    core = sim.core
    header = header_of(core.step, core.time, fingerprint or sim.fingerprint(), outputs)
    return save_state(path, core.checkpoint(), header)


def save_state(path: str | Path, state: dict[str, Any], header: dict[str, Any]) -> Path:
    """Write a core's `state` (core.checkpoint) with `header` (header_of) to `path` atomically,
    then remove the pieces of a distributed run's checkpoint there before (pieces_folder)."""
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    checkpoint_file.save(target, state, header)
    shutil.rmtree(pieces_folder(target), ignore_errors=True)
    return target


def pieces_folder(path: str | Path) -> Path:
    """Where a distributed run's checkpoint at `path` keeps its ranks' pieces: path.pieces."""
    target = Path(path)
    return target.with_name(target.name + checkpoint_file.PIECES_SUFFIX)


def read(path: str | Path, fingerprint: str) -> tuple[dict[str, Any], dict[str, Any]]:
    """The checkpoint at `path` (granulate.io.checkpoint.load: its arrays and header), refused
    (InputError) unless it belongs to the set-up with this `fingerprint`."""
    state, header = checkpoint_file.load(path)
    if header.get("fingerprint") != fingerprint:
        raise InputError(
            f"checkpoint {path} belongs to a different set-up (other nodes, loading, walls, "
            "time step or case file); run without --resume, or restore the original case"
        )
    return state, header


def load(
    sim: Simulation, path: str | Path, outputs: Outputs | None, fingerprint: str | None = None
) -> None:
    """Continue sim from a checkpoint of its same set-up (else InputError), whole or in a
    distributed run's pieces (parallel/checkpoint_pieces.py): the state and, when `outputs` are
    set, their frame count, PVD series and history.csv up to the checkpoint's step.
    `fingerprint`: sim's, when already known."""
    state, header = read(path, fingerprint or sim.fingerprint())
    core = sim.core
    if "pieces" in header:
        from granulate.parallel import checkpoint_pieces

        checkpoint_pieces.restore_whole(core, path, state, header, sim.node_count)
    else:
        core.restore(state)
    sim.analysis.forget_fragments()  # the labels of the bonds before the restore
    resume_outputs(path, header, outputs)


def resume_outputs(path: str | Path, header: dict[str, Any], outputs: Outputs | None) -> None:
    """The bookkeeping of `outputs` (when set) as the checkpoint at `path` with `header` left
    it: frames written, PVD series, history.csv up to its step; InputError when it was written
    with other output settings."""
    saved = header.get("output")
    if outputs is None:
        return
    if (
        saved is None
        or saved["every"] != outputs.every
        or saved.get("history_every", saved["every"]) != outputs.history_every
    ):
        raise InputError(
            f"checkpoint {path} was written with other output settings; keep the "
            "output interval of the original run"
        )
    outputs.resume(int(saved["frames"]), saved["pvd"], int(header["step"]))


def interrupt_path(plan: CheckpointPlan | None, outputs: Outputs | None) -> Path | None:
    """Where a run interrupted by Ctrl-C or SIGTERM leaves its checkpoint: at the plan's path,
    else in the output folder; None (nothing written) when neither is set."""
    if plan is not None:
        return plan.path
    if outputs is not None:
        return outputs.directory / "checkpoint.npz"
    return None
