"""The outputs of a run in its folder: when each step writes a frame and a history row, and
what the frames and rows hold (the registered writers, registry.py)."""

from __future__ import annotations

import json
import time as wallclock
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from granulate.errors import InputError
from granulate.io import HistoryWriter, PvdSeries, atomic_write
from granulate.io.run_folder import RunFolder
from granulate.writers import registry
from granulate.writers.step_data import StepData
from granulate.writers.vtu_frame import FIELDS

if TYPE_CHECKING:
    from granulate.assembly import Body
    from granulate.simulation import Simulation


@dataclass
class Outputs:
    """Frames every `every` steps, a history row every `history_every` steps, and run.json
    after each frame (Simulation.output sets them up)."""

    directory: Path
    every: int
    fields: tuple[str, ...]
    pvd: PvdSeries
    history_every: int
    folder: RunFolder
    tracked: tuple[Body, ...] = ()
    track_areas: dict[str, float] = field(default_factory=dict)  # body name -> area
    history: HistoryWriter | None = None
    frames: int = 0
    frame_step: int = -1  # the step of the last frame written (-1: none in this process)
    history_step: int = -1  # likewise for the last history row
    seconds: float = 0.0  # wall-clock seconds spent writing frames and rows
    #: Frames as a .pvtu over pieces (vtu_frame.py) rather than one .vtu each.
    pieces: bool = False
    #: The ranks that write a frame's pieces (a distributed run's), or 0: the frame writer
    #: writes the one piece of a serial run itself.
    piece_ranks: int = 0

    @classmethod
    def plan(
        cls,
        directory: Path,
        every: int,
        history_every: int | None,
        fields: Sequence[str],
        tracked: tuple[Body, ...],
        track_areas: Mapping[str, float],
        wall_names: Sequence[str],
        *,
        overwrite: bool,
        resume: bool,
        pieces: bool = False,
    ) -> Outputs:
        """The outputs Simulation.output asks for, checked (InputError), in their folder
        (RunFolder: a run already there is refused unless `overwrite` or `resume`)."""
        if not (isinstance(every, int) and every > 0):
            raise InputError(f"output interval must be a positive number of steps, got {every!r}")
        history_every = every if history_every is None else history_every
        if not (isinstance(history_every, int) and history_every > 0):
            raise InputError(
                f"history interval must be a positive number of steps, got {history_every!r}"
            )
        clashing = sorted({b.name for b in tracked} & set(wall_names))
        if clashing:
            raise InputError(
                f"tracked bodies {clashing} are named like walls: their history.csv columns "
                "(<name>_fx, ...) would overwrite each other; rename them"
            )
        areas = _track_areas(track_areas, tracked)
        unknown = [f for f in fields if f not in FIELDS]
        if unknown:
            raise InputError(f"unknown output fields {unknown}; choose from {', '.join(FIELDS)}")
        folder = RunFolder(directory, overwrite=overwrite, resume=resume)
        pvd = PvdSeries(directory / "simulation.pvd")
        if not isinstance(pieces, bool):
            raise InputError(f"pieces must be true or false, got {pieces!r}")
        outputs = cls(directory, every, tuple(fields), pvd, history_every, folder, tracked, areas)
        outputs.pieces = pieces
        return outputs

    def is_output_step(self, step: int) -> bool:
        """Whether `step` writes a frame or a history row."""
        return step % self.every == 0 or step % self.history_every == 0

    def steps_to_next(self, step: int) -> int:
        """Steps from `step` to the next frame or history row."""
        return min(self.every - step % self.every, self.history_every - step % self.history_every)

    def frame_due(self, step: int, final: bool | None = None) -> bool:
        """Whether the outputs of `step` write a frame: write_step's (final None), or
        write_final's with its `frame` flag (`final`)."""
        if final is None:
            return step % self.every == 0 or self.frames == 0
        return final and self.frame_step != step

    def needs_whole_state(self, step: int, final: bool | None = None) -> bool:
        """Whether the outputs of `step` (write_step's, or write_final's) read the whole
        simulation: a writer that may read it (base.py). Otherwise a distributed run makes
        them of its ranks' measures (StepData), and a frame of every node of their rows
        (one_file_frame)."""
        return not registry.reads_values_only()

    def may_need_whole_state(self) -> bool:
        """Whether some output step may read the whole simulation (needs_whole_state)."""
        return not registry.reads_values_only()

    def one_file_frame(self, step: int, final: bool | None = None) -> tuple[str, ...] | None:
        """The fields of the frame of every node in one file that the outputs of `step` write
        (frame_due, not in pieces), or None."""
        return self.fields if self.frame_due(step, final) and not self.pieces else None

    def piece_folder(self, step: int, final: bool | None = None) -> Path | None:
        """The folder of the pieces the ranks write of the frame `step`'s outputs write
        (frame_due), or None when there is none or it is not written by ranks."""
        if not (self.pieces and self.piece_ranks and self.frame_due(step, final)):
            return None
        return self.directory / "frames" / f"frame_{self.frames:06d}"

    def write_step(self, sim: Simulation, data: StepData | None = None) -> None:
        """The frame (at a frame step, or the first) and the history row (at a history step,
        or the first) of the current step, from `data` (a distributed run's, made of its
        ranks' measures) or from `sim`'s whole state."""
        step = sim.step
        self.write(
            sim,
            self.frame_due(step),
            step % self.history_every == 0 or self.history is None,
            data,
        )

    def write_final(self, sim: Simulation, frame: bool, data: StepData | None = None) -> None:
        """The end of a run: with ``frame``, the frame and history row of the last step when
        it was not an output step."""
        step = sim.step
        self.write(sim, self.frame_due(step, frame), frame and self.history_step != step, data)

    def write(
        self, sim: Simulation, frame: bool, history: bool, data: StepData | None = None
    ) -> None:
        """The frame and the history row of the current step, as asked, from one StepData
        (`data`, or made of `sim`'s whole state)."""
        if not (frame or history):
            return
        start = wallclock.perf_counter()
        try:
            self._write(sim, frame, history, data)
        finally:
            self.seconds += wallclock.perf_counter() - start

    def _write(self, sim: Simulation, frame: bool, history: bool, data: StepData | None) -> None:
        data = data or StepData.of(sim, self.tracked)
        if frame:
            for writer in registry.FRAME_WRITERS:
                writer.write(data, self)
            self.frames += 1
            self.frame_step = data.step
            self.write_run_record(sim)
        if history:
            row: dict[str, float | int] = {}
            for section in registry.HISTORY_SECTIONS:
                row.update(section.columns(data, self))
            if self.history is None:
                self.history = HistoryWriter(self.directory / "history.csv", list(row))
            self.history.write(row)
            self.history_step = data.step

    def resume(self, frames: int, pvd: list[tuple[float, str]], step: int) -> None:
        """Continue the outputs of a checkpoint at `step`: its frame count and PVD entries,
        and history.csv cut back to its rows up to `step`."""
        self.frames = frames
        self.pvd.entries = [(float(t), str(f)) for t, f in pvd]
        history = self.directory / "history.csv"
        if history.exists():
            self.history = HistoryWriter.resume(history, step)

    def write_run_record(self, sim: Simulation) -> None:
        """run.json: the counts, time step, status and timings of the run so far."""
        atomic_write(self.directory / "run.json", json.dumps(sim.summary(), indent=2).encode())


def _track_areas(areas: Mapping[str, float], tracked: tuple[Body, ...]) -> dict[str, float]:
    """Simulation.output's track_areas, checked: tracked bodies' names, positive areas."""
    names = {b.name for b in tracked}
    if not isinstance(areas, Mapping):
        raise InputError(f"track_areas must map tracked bodies' names to areas, got {areas!r}")
    checked = {}
    for name, area in areas.items():
        if name not in names:
            raise InputError(
                f"track_areas names {name!r}, which is not tracked; track it too "
                f"(tracked: {sorted(names) or 'none'})"
            )
        if (
            isinstance(area, bool)
            or not isinstance(area, (int, float))
            or not (np.isfinite(area) and area > 0)
        ):
            raise InputError(
                f"track_areas[{name!r}] must be a positive area [m^2; m in 2D], got {area!r}"
            )
        checked[name] = float(area)
    return checked
