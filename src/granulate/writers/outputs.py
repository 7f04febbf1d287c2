"""The outputs of a run in its folder: when each step writes a frame and a history row, and
what the frames and rows hold (the registered writers, registry.py)."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from granulate.io import HistoryWriter, PvdSeries, atomic_write
from granulate.io.run_folder import RunFolder
from granulate.writers import registry
from granulate.writers.step_data import StepData

if TYPE_CHECKING:
    from granulate.simulation import Body, Simulation


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

    def is_output_step(self, step: int) -> bool:
        """Whether `step` writes a frame or a history row."""
        return step % self.every == 0 or step % self.history_every == 0

    def steps_to_next(self, step: int) -> int:
        """Steps from `step` to the next frame or history row."""
        return min(self.every - step % self.every, self.history_every - step % self.history_every)

    def write_step(self, sim: Simulation) -> None:
        """The frame (at a frame step, or the first) and the history row (at a history step,
        or the first) of the current step."""
        step = sim.core.step
        self.write(
            sim,
            step % self.every == 0 or self.frames == 0,
            step % self.history_every == 0 or self.history is None,
        )

    def write_final(self, sim: Simulation, frame: bool) -> None:
        """The end of a run: with ``frame``, the frame and history row of the last step when
        it was not an output step."""
        step = int(sim.core.step)
        self.write(sim, frame and self.frame_step != step, frame and self.history_step != step)

    def write(self, sim: Simulation, frame: bool, history: bool) -> None:
        """The frame and the history row of the current step, as asked, from one StepData."""
        if not (frame or history):
            return
        data = StepData.of(sim)
        if frame:
            for writer in registry.FRAME_WRITERS:
                writer.write(data, self)
            self.frames += 1
            self.frame_step = int(sim.core.step)
            self.write_run_record(sim)
        if history:
            row: dict[str, float | int] = {}
            for section in registry.HISTORY_SECTIONS:
                row.update(section.columns(data, self))
            if self.history is None:
                self.history = HistoryWriter(self.directory / "history.csv", list(row))
            self.history.write(row)
            self.history_step = int(sim.core.step)

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
