"""frames/frame_NNNNNN.vtu, the nodes with the chosen point fields, listed in simulation.pvd."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from granulate.io import write_vtu

if TYPE_CHECKING:
    from granulate.writers.outputs import Outputs
    from granulate.writers.step_data import StepData

#: The point fields a frame can hold (Simulation.output(fields=...)); all by default.
FIELDS = (
    "Displacement",
    "Velocity",
    "Force_Density",
    "Force",
    "Damage",
    "Damage_Z",
    "Dilatation",
    "Particle_ID",
    "Fragment_ID",
    "Fixity",
    "Nodal_Volume",
)


class VtuFrame:
    """The node frame: positions and the fields of ``Simulation.output(fields=...)``."""

    def write(self, data: StepData, outputs: Outputs) -> None:
        sim = data.simulation
        core, model = sim.core, sim.model
        volumes = model.volumes
        available = {
            "Displacement": lambda: sim.displacements,
            "Velocity": lambda: core.velocities,
            "Force_Density": lambda: core.forces,
            "Force": lambda: core.forces * volumes[:, None],
            "Damage": lambda: data.damage,
            "Damage_Z": lambda: data.damage_z,
            "Dilatation": lambda: core.dilatation,
            "Particle_ID": lambda: model.node_particle,
            "Fragment_ID": sim.analysis.fragment_labels,
            "Fixity": lambda: core.fixity(),
            "Nodal_Volume": lambda: volumes,
        }
        name = f"frame_{outputs.frames:06d}.vtu"
        write_vtu(
            outputs.directory / "frames" / name,
            core.positions,
            {f: available[f]() for f in outputs.fields},
        )
        outputs.pvd.add(core.time, Path("frames") / name)
