"""The sections of a history.csv row, in column order (registered in registry.py): the step's
energies and counts, breakage, granular measures, wall loads and tracked bodies."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from granulate import fragments, network

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

    needs_whole_state = False  # reads StepData's values (base.py)

    def columns(self, data: StepData, outputs: Outputs) -> dict[str, float | int]:
        totals, evaluation = data.totals, data.evaluation
        kinetic, strain = totals.kinetic.value, totals.strain.value
        gravity, contact = totals.gravity.value, totals.contact.value
        return {
            "step": data.step,
            "time": data.time,
            "kinetic_energy": kinetic,
            "strain_energy": strain,
            "gravity_energy": gravity,
            "contact_energy": contact,
            "total_energy": kinetic + strain + gravity + contact,
            "broken_bonds": data.broken_bonds,
            "node_contacts": evaluation.node_contacts,
            "wall_contacts": evaluation.wall_contacts,
            "list_rebuilds": evaluation.list_rebuilds,
        }


class Breakage:
    """Fragments, debris, particles split, mean damage (granulate.fragments.summary)."""

    needs_whole_state = False  # reads StepData's values (base.py)

    def columns(self, data: StepData, outputs: Outputs) -> dict[str, float | int]:
        return fragments.summary(data.fragments, data.mean_damage)


class GranularMeasures:
    """Particle contacts, mean coordination, assembly stress [Pa] and fabric tensor."""

    needs_whole_state = False  # reads StepData's values (base.py)

    def columns(self, data: StepData, outputs: Outputs) -> dict[str, float | int]:
        particles = len(data.particles["particle"])
        row: dict[str, float | int] = {
            "contacts": len(network.coordination_pairs(data.contacts)),
            "coordination": network.mean_coordination(data.contacts, particles),
        }
        solid = network.assembly_stress(*data.stresses)
        fabric = network.fabric_tensor(data.contacts, data.dimension)
        for name, (i, j) in STRESS_COMPONENTS[data.dimension]:
            row[f"stress_{name}"] = float(solid[i, j])
        for name, (i, j) in STRESS_COMPONENTS[data.dimension]:
            row[f"fabric_{name}"] = float(fabric[i, j])
        return row


class WallLoads:
    """Per wall: the particles' force and torque on it, its displacement, and with an area
    its stress."""

    needs_whole_state = False  # reads StepData's values (base.py)

    def columns(self, data: StepData, outputs: Outputs) -> dict[str, float | int]:
        row: dict[str, float | int] = {}
        for (name, spec), reaction, moved in zip(
            data.walls, data.evaluation.wall_reactions, data.wall_displacements, strict=True
        ):
            for c in _WALL_COMPONENTS[data.dimension]:
                row[f"{name}_{c}"] = float(reaction[_WALL_INDEX[c]])
            row[f"{name}_displacement"] = moved
            if spec.area is not None:
                row[f"{name}_stress"] = (
                    float(np.linalg.norm(reaction[: data.dimension])) / spec.area
                )
        return row


class TrackedBodies:
    """Per tracked body: the resultant of its forces other than gravity [N; N/m in 2D], its
    mean displacement [m] and, given an area, its stress [Pa] (granulate.step_totals)."""

    needs_whole_state = False  # reads StepData's values (base.py)

    def columns(self, data: StepData, outputs: Outputs) -> dict[str, float | int]:
        row: dict[str, float | int] = {}
        axes = "xyz"[: data.dimension]
        for body, sums in zip(outputs.tracked, data.totals.tracked, strict=True):
            resultant, mean = sums.load(data.gravity)
            for k, axis in enumerate(axes):
                row[f"{body.name}_f{axis}"] = float(resultant[k])
            for k, axis in enumerate(axes):
                row[f"{body.name}_u{axis}"] = float(mean[k])
            if body.name in outputs.track_areas:
                area = outputs.track_areas[body.name]
                row[f"{body.name}_stress"] = float(np.linalg.norm(resultant)) / area
        return row
