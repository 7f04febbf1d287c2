"""frames/particles_NNNNNN.csv: one row per particle (granulate.particle_table)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from granulate import particle_table

if TYPE_CHECKING:
    from granulate.writers.outputs import Outputs
    from granulate.writers.step_data import StepData


class ParticleTables:
    needs_whole_state = False  # reads StepData's values (base.py)

    def write(self, data: StepData, outputs: Outputs) -> None:
        path = outputs.directory / "frames" / f"particles_{outputs.frames:06d}.csv"
        particle_table.write_table(path, data.particles)
