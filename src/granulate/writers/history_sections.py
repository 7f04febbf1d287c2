"""The sections of a history.csv row, in column order (registered in registry.py): the step's
energies and counts, breakage, granular measures, wall loads and tracked bodies."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from granulate import fragments, network, reductions

if TYPE_CHECKING:
    from granulate.writers.outputs import Outputs
    from granulate.writers.step_data import StepData

#: The components of the assembly stress and the fabric tensor (``stress_<name>``,
#: ``fabric_<name>``), per dimension.
STRESS_COMPONENTS = {
    2: (("xx", (0, 0)), ("yy", (1, 1)), ("xy", (0, 1))),
    3: (
        ("xx", (0, 0)), ("yy", (1, 1)), ("zz", (2, 2)),
        ("xy", (0, 1)), ("xz", (0, 2)), ("yz", (1, 2)),
    ),
}  # fmt: skip
_WALL_COMPONENTS = {2: ("fx", "fy", "tz"), 3: ("fx", "fy", "fz", "tx", "ty", "tz")}
_WALL_INDEX = {"fx": 0, "fy": 1, "fz": 2, "tx": 3, "ty": 4, "tz": 5}


class Energies:
    """step, time, the energies [J; J/m in 2D], broken bonds, contact counts, list rebuilds."""

    def columns(self, data: StepData, outputs: Outputs) -> dict[str, float | int]:
        sim = data.simulation
        core = sim.core
        evaluation = data.evaluation
        kinetic, strain = sim.kinetic_energy(), sim.strain_energy()
        gravity, contact = sim.gravity_energy(), evaluation.contact_energy
        return {
            "step": core.step,
            "time": core.time,
            "kinetic_energy": kinetic,
            "strain_energy": strain,
            "gravity_energy": gravity,
            "contact_energy": contact,
            "total_energy": kinetic + strain + gravity + contact,
            "broken_bonds": core.broken_bonds(),
            "node_contacts": evaluation.node_contacts,
            "wall_contacts": evaluation.wall_contacts,
            "list_rebuilds": evaluation.list_rebuilds,
        }


class Breakage:
    """Fragments, debris, particles split, mean damage (granulate.fragments.summary)."""

    def columns(self, data: StepData, outputs: Outputs) -> dict[str, float | int]:
        return fragments.summary(data.fragments, data.damage, data.simulation.model.volumes)


class GranularMeasures:
    """Particle contacts, mean coordination, assembly stress [Pa] and fabric tensor."""

    def columns(self, data: StepData, outputs: Outputs) -> dict[str, float | int]:
        sim = data.simulation
        row: dict[str, float | int] = {
            "contacts": len(network.coordination_pairs(data.contacts)),
            "coordination": network.mean_coordination(data.contacts, len(sim.bodies)),
        }
        solid = network.assembly_stress(*data.stresses)
        fabric = network.fabric_tensor(data.contacts, sim.dimension)
        for name, (i, j) in STRESS_COMPONENTS[sim.dimension]:
            row[f"stress_{name}"] = float(solid[i, j])
        for name, (i, j) in STRESS_COMPONENTS[sim.dimension]:
            row[f"fabric_{name}"] = float(fabric[i, j])
        return row


class WallLoads:
    """Per wall: the particles' force and torque on it, its displacement, and with an area
    its stress."""

    def columns(self, data: StepData, outputs: Outputs) -> dict[str, float | int]:
        sim = data.simulation
        core = sim.core
        row: dict[str, float | int] = {}
        for (name, spec), reaction, wall in zip(
            sim.walls, data.evaluation.wall_reactions, core.walls, strict=True
        ):
            for c in _WALL_COMPONENTS[sim.dimension]:
                row[f"{name}_{c}"] = float(reaction[_WALL_INDEX[c]])
            row[f"{name}_displacement"] = wall.displacement(core.time)
            if spec.area is not None:
                row[f"{name}_stress"] = float(np.linalg.norm(reaction[: sim.dimension])) / spec.area
        return row


class TrackedBodies:
    """Per tracked body: the resultant of its forces other than gravity [N; N/m in 2D], its
    mean displacement [m] and, given an area, its stress [Pa]."""

    def columns(self, data: StepData, outputs: Outputs) -> dict[str, float | int]:
        row: dict[str, float | int] = {}
        if not outputs.tracked:
            return row
        sim = data.simulation
        model = sim.model
        forces, positions, reference = (
            sim.core.forces,
            sim.core.positions,
            model.reference_positions,
        )
        volumes, density, gravity = model.volumes, model.node_density, sim.gravity
        axes = "xyz"[: sim.dimension]
        for body in outputs.tracked:
            nodes = body.node_slice
            v = volumes[nodes]
            weight = reductions.dot(v, density[nodes]) * gravity
            resultant = reductions.weighted_sum(v, forces[nodes]) - weight
            mean = (positions[nodes] - reference[nodes]).mean(axis=0)
            for k, axis in enumerate(axes):
                row[f"{body.name}_f{axis}"] = float(resultant[k])
            for k, axis in enumerate(axes):
                row[f"{body.name}_u{axis}"] = float(mean[k])
            if body.name in outputs.track_areas:
                area = outputs.track_areas[body.name]
                row[f"{body.name}_stress"] = float(np.linalg.norm(resultant)) / area
        return row
