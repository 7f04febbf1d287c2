"""What a writer of a run's outputs is: a frame writer writes files at each frame; a history
section adds columns to each history.csv row. Both read the step's StepData.

A writer whose class sets ``needs_whole_state = False`` reads only StepData's values, which a
distributed run makes of its ranks' measures; one without it (False is not assumed) may read
``data.simulation``, for which rank 0 of a distributed run first takes the whole state."""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    from granulate.writers.outputs import Outputs
    from granulate.writers.step_data import StepData


class FrameWriter(Protocol):
    """Writes its files for one frame, numbered ``outputs.frames`` (frames/<kind>_NNNNNN.*)."""

    def write(self, data: StepData, outputs: Outputs) -> None: ...


class HistorySection(Protocol):
    """The columns it adds to a history.csv row, in order; every row must give the same
    columns (the file's header is the first row's)."""

    def columns(self, data: StepData, outputs: Outputs) -> dict[str, float | int]: ...
