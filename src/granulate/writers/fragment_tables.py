"""frames/fragments_NNNNNN.csv: one row per fragment, debris flagged (granulate.fragments)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from granulate import fragments

if TYPE_CHECKING:
    from granulate.writers.outputs import Outputs
    from granulate.writers.step_data import StepData


class FragmentTables:
    needs_whole_state = False  # reads StepData's values (base.py)

    def write(self, data: StepData, outputs: Outputs) -> None:
        path = outputs.directory / "frames" / f"fragments_{outputs.frames:06d}.csv"
        fragments.write_table(path, data.fragments)
