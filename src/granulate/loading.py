"""The loading of a simulation's nodes, kept in the order given and handed to the core when it
is built: prescribed displacements x = X + f(t) d on chosen components, rigid rotations
x = c + R(angle(t)) (X - c), and force densities f(t) b [N/m^3, also in 2D]. Gravity and the
background damping act on every node and are the core's own settings."""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from granulate import _core
from granulate.assembly import Assembly, node_ids
from granulate.errors import InputError
from granulate.functions import Constant, Linear, TimeFunction, VelocityRamp
from granulate.node_map import NodeMap

Components = str  # any of "x", "y", "z", e.g. "xy"


@dataclass(frozen=True)
class PrescribedDisplacement:
    nodes: NDArray[np.uint32]
    mask: int  # bit k: component k is prescribed
    direction: NDArray[np.float64]
    function: TimeFunction

    kind = "displacement"

    def apply(self, core: _core.Simulation) -> None:
        core.add_displacement(self.nodes, self.mask, tuple(self.direction), *self.function.core())


@dataclass(frozen=True)
class PrescribedRotation:
    nodes: NDArray[np.uint32]
    center: NDArray[np.float64]
    axis: NDArray[np.float64]
    angle: TimeFunction

    kind = "rotation"

    def apply(self, core: _core.Simulation) -> None:
        core.add_rotation(self.nodes, tuple(self.center), tuple(self.axis), *self.angle.core())


@dataclass(frozen=True)
class ForceDensity:
    nodes: NDArray[np.uint32]
    vector: NDArray[np.float64]
    function: TimeFunction

    kind = "force"

    def apply(self, core: _core.Simulation) -> None:
        core.add_nodal_force(self.nodes, tuple(self.vector), *self.function.core())


Load = PrescribedDisplacement | PrescribedRotation | ForceDensity


def component_mask(components: Components, dimension: int) -> int:
    """Bit k set for each named component ("x" -> 1, "y" -> 2, "z" -> 4)."""
    mask = 0
    for c in components:
        if c not in "xyz"[:dimension]:
            raise InputError(
                f"component {c!r} is not one of {', '.join('xyz'[:dimension])} in {dimension}D"
            )
        mask |= 1 << "xyz".index(c)
    if mask == 0:
        raise InputError("name at least one component (x, y or z)")
    return mask


class Loading:
    """The loads on an assembly's nodes, in the order added (Simulation.fix and the rest)."""

    def __init__(self, assembly: Assembly) -> None:
        self._assembly = assembly
        self.loads: list[Load] = []

    def _nodes(self, nodes: ArrayLike) -> NDArray[np.uint32]:
        return node_ids(nodes, self._assembly.node_count)

    def fix(self, nodes: ArrayLike, components: Components) -> None:
        dimension = self._assembly.dimension
        components = components[:dimension] if components == "xyz" else components
        self._prescribe(nodes, np.zeros(3), Constant(0.0), components)

    def prescribe_displacement(
        self,
        nodes: ArrayLike,
        direction: ArrayLike,
        function: TimeFunction,
        components: Components | None,
    ) -> None:
        vector = self._assembly.vector(direction, "direction")
        if not np.any(vector):
            raise InputError(
                "prescribe_displacement: the direction is zero, so the nodes would be held still; "
                "give the direction of the motion (or fix the nodes with fix / a fix entry)"
            )
        self._prescribe(nodes, vector, function, components)

    def _prescribe(
        self,
        nodes: ArrayLike,
        vector: NDArray[np.float64],
        function: TimeFunction,
        components: Components | None,
    ) -> None:
        dimension = self._assembly.dimension
        mask = component_mask(components or "xyz"[:dimension], dimension)
        self.loads.append(PrescribedDisplacement(self._nodes(nodes), mask, vector, function))

    def prescribe_velocity(
        self,
        nodes: ArrayLike,
        velocity: ArrayLike,
        ramp_time: float,
        components: Components | None,
    ) -> None:
        """A constant velocity, reached over ramp_time: a fix when it is zero."""
        v = self._assembly.vector(velocity, "velocity")
        speed = float(np.linalg.norm(v))
        if speed == 0:
            self.fix(nodes, components or "xyz"[: self._assembly.dimension])
            return
        function: TimeFunction = VelocityRamp(speed, ramp_time) if ramp_time > 0 else Linear(speed)
        self.prescribe_displacement(nodes, v / speed, function, components)

    def prescribe_rotation(
        self, nodes: ArrayLike, center: ArrayLike, angle: TimeFunction, axis: ArrayLike
    ) -> None:
        axis_vector = np.asarray(axis, dtype=float).reshape(-1)
        if self._assembly.dimension == 2 and not np.allclose(axis_vector, (0, 0, 1)):
            raise InputError("in 2D, rotations are about the z axis")
        ids = self._nodes(nodes)
        center_vector = self._assembly.vector(center, "center")
        self.loads.append(PrescribedRotation(ids, center_vector, axis_vector, angle))

    def add_force_density(
        self, nodes: ArrayLike, vector: ArrayLike, function: TimeFunction | None
    ) -> None:
        ids = self._nodes(nodes)
        density = self._assembly.vector(vector, "force density")
        self.loads.append(ForceDensity(ids, density, function or Constant(1.0)))

    def prescribed(self) -> NDArray[np.bool_]:
        """Per node of the assembly, whether its motion is prescribed in some direction: fixed,
        displaced or rotated (the nodes of a meshed wall or a loading platen)."""
        held = np.zeros(self._assembly.node_count, dtype=bool)
        for load in self.loads:
            if isinstance(load, PrescribedDisplacement | PrescribedRotation):
                held[load.nodes] = True
        return held

    def subset(self, assembly: Assembly, node_map: NodeMap) -> Loading:
        """The loads on `assembly`, a subset of this one's (Assembly.subset and its node map):
        each load on the nodes it keeps, renumbered; loads that keep no node are left out."""
        part = Loading(assembly)
        for load in self.loads:
            kept = node_map[load.nodes]
            kept = kept[kept >= 0].astype(np.uint32)
            if len(kept):
                part.loads.append(replace(load, nodes=kept))
        return part

    def apply(self, core: _core.Simulation) -> None:
        """Hand the loads to the core, in order."""
        for load in self.loads:
            load.apply(core)

    def fingerprint_parts(self) -> list[bytes | str]:
        """The loads as bytes and text for a checkpoint's fingerprint: per load its kind, then
        its arrays' bytes and its other fields' repr, in the order of the fields."""
        parts: list[bytes | str] = []
        for load in self.loads:
            parts.append(load.kind)
            for value in (getattr(load, f.name) for f in fields(load)):
                is_array = isinstance(value, np.ndarray)
                parts.append(value.tobytes() if is_array else repr(value))
        return parts
