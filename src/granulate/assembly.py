"""The bodies of a simulation as the user adds them, before the core is built: each body's
nodes, volumes, material, mesh size and initial motion, the reference shapes particles are
placed from, the packings they came from, and node selections. `granulate.core_model` turns an
Assembly into the core's Model; `Simulation` is the front door users call.

Units are SI: positions [m], volumes [m^3; m^2 in 2D], velocities [m/s], angular velocities
[rad/s].
"""

from __future__ import annotations

import difflib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from granulate import _core, reductions
from granulate.body_nodes import BodyNodes, NodeField, PlacedNodes, StoredNodes
from granulate.errors import InputError
from granulate.input_errors import check_number
from granulate.materials import Material
from granulate.node_map import NodeMap
from granulate.packing import Grain, Packing, Placements, grains_by_kind
from granulate.reference_shapes import ReferenceShape
from granulate.shapes import Shape, rotation_matrix

#: A body's initial motion: its linear velocity and its spin (about z in 2D, a vector in 3D).
InitialVelocity = tuple["Body", NDArray[np.float64], float | NDArray[np.float64]]


@dataclass(frozen=True)
class Body:
    """A particle: a contiguous range of nodes with one material and mesh size."""

    index: int
    name: str
    first_node: int
    node_count: int
    material: Material
    mesh_size: float
    reference: ReferenceShape | None = None
    scale: float = 1.0

    def __repr__(self) -> str:
        return (
            f"Body({self.name!r}, nodes {self.first_node}..{self.first_node + self.node_count - 1}"
            f", mesh size {self.mesh_size:.4g} m, {self.material!r})"
        )

    @property
    def nodes(self) -> NDArray[np.uint32]:
        """Global indices of the body's nodes."""
        return np.arange(self.first_node, self.first_node + self.node_count, dtype=np.uint32)

    @property
    def node_slice(self) -> slice:
        """The body's nodes as a slice of the global node arrays."""
        return slice(self.first_node, self.first_node + self.node_count)


def as_vector(value: ArrayLike, name: str, dimension: int) -> NDArray[np.float64]:
    """`value` as a 3-vector: `dimension` (or 3) finite numbers, no z component in 2D."""
    array = np.asarray(value, dtype=np.float64).reshape(-1)
    if array.shape not in ((dimension,), (3,)) or not np.all(np.isfinite(array)):
        raise InputError(f"{name} must be {dimension} finite numbers, got {value!r}")
    out = np.zeros(3)
    out[: len(array)] = array
    if dimension == 2 and out[2] != 0:
        raise InputError(f"{name} has a z component in a 2D simulation")
    return out


def node_ids(nodes: ArrayLike, count: int) -> NDArray[np.uint32]:
    """`nodes` checked as a non-empty set of node indices in [0, count)."""
    array = np.asarray(nodes).reshape(-1)
    if len(array) == 0:
        raise InputError("the node set is empty")
    if array.dtype.kind not in "iu" or np.any(array < 0) or np.any(array >= count):
        raise InputError(f"node ids must be integers in [0, {count})")
    return np.ascontiguousarray(array, dtype=np.uint32)


class Assembly:
    """The bodies added so far, in order, with their node arrays.

    ``positions[k]``, ``volumes[k]``: body k's node arrays (a particle placed from a reference
    shape computes them when asked: body_nodes.py). ``surfaces[k]``: for a body without a
    reference shape, the discretised shape its nodes came from (for its surface offsets and
    depths), or None.
    """

    def __init__(self, dimension: int) -> None:
        self.dimension = dimension
        self.bodies: list[Body] = []
        self.packings: list[Packing] = []
        self._nodes: list[BodyNodes] = []
        self.positions = NodeField(self._nodes, "positions")
        self.volumes = NodeField(self._nodes, "volumes")
        self.surfaces: list[ReferenceShape | None] = []
        self.initial_velocities: list[InitialVelocity] = []
        self._names: dict[str, Body] = {}  # every body by name (adding one is O(1))
        #: For a subset (subset()): the assembly it was taken from and each body's index
        #: there; its bodies take their core shapes from that one's (core_model.py).
        self.parent: tuple[Assembly, NDArray[np.int64]] | None = None

    @property
    def node_count(self) -> int:
        last = self.bodies[-1] if self.bodies else None
        return last.first_node + last.node_count if last is not None else 0

    def stored_arrays(self) -> list[NDArray[np.float64]]:
        """The node arrays the assembly holds (positions and volumes of the bodies not placed
        from a reference shape, whose nodes are computed when asked)."""
        stored = [nodes for nodes in self._nodes if isinstance(nodes, StoredNodes)]
        return [array for nodes in stored for array in (nodes.position_array, nodes.volume_array)]

    def reference_positions(self) -> NDArray[np.float64]:
        """(n, 3) reference positions of all nodes added so far [m] (a copy)."""
        if not self._nodes:
            return np.zeros((0, 3))
        return np.concatenate(list(self.positions))

    def vector(self, value: ArrayLike, name: str) -> NDArray[np.float64]:
        return as_vector(value, name, self.dimension)

    def add_body(
        self,
        shape: Shape,
        material: Material,
        mesh_size: float,
        *,
        discretization: str,
        jitter: float,
        seed: int,
        velocity: ArrayLike | None,
        angular_velocity: float | ArrayLike | None,
        name: str | None,
    ) -> Body:
        """Discretize `shape` at spacing `mesh_size` and add its nodes (Simulation.add_body)."""
        if not isinstance(shape, Shape):
            order = (
                " (the order is shape, material, mesh_size)" if isinstance(shape, Material) else ""
            )
            raise InputError(
                f"add_body: shape must be a shape (Disc, Rectangle, Sphere, ...), got "
                f"{type(shape).__name__}{order}"
            )
        if not isinstance(material, Material):
            raise InputError(
                f"add_body: material must be a granulate.Material, got {type(material).__name__}"
            )
        check_number("add_body: mesh_size", mesh_size)
        if shape.dimension != self.dimension:
            raise InputError(
                f"{type(shape).__name__} is a {shape.dimension}D shape but the simulation is "
                f"{self.dimension}D"
            )
        reference = ReferenceShape.from_shape(
            shape, mesh_size, discretization=discretization, jitter=jitter, seed=seed
        )
        body = self.add_body_from_nodes(
            reference.positions,
            reference.volumes,
            material,
            mesh_size,
            velocity=velocity,
            angular_velocity=angular_velocity,
            name=name,
        )
        self.surfaces[body.index] = reference
        return body

    def add_particle(
        self,
        reference: ReferenceShape,
        material: Material,
        *,
        position: ArrayLike,
        rotation: float | ArrayLike | None,
        scale: float,
        velocity: ArrayLike | None,
        angular_velocity: float | ArrayLike | None,
        name: str | None,
    ) -> Body:
        """Place a reference shape: x = position + R (scale p) (Simulation.add_particle)."""
        if not isinstance(reference, ReferenceShape):
            raise InputError(
                f"add_particle takes a granulate.ReferenceShape, got {type(reference).__name__}"
            )
        if reference.dimension != self.dimension:
            raise InputError(
                f"the reference shape is {reference.dimension}D "
                f"but the simulation is {self.dimension}D"
            )
        if not (np.isfinite(scale) and scale > 0):
            raise InputError(f"scale must be positive, got {scale}")
        placed = PlacedNodes(
            reference,
            self.vector(position, "position"),
            rotation_matrix(rotation, self.dimension),
            scale,
            self.dimension,
        )
        return self._add(
            placed,
            material,
            scale * reference.mesh_size,
            velocity,
            angular_velocity,
            name,
            reference,
            float(scale),
        )

    def add_placements(
        self,
        placements: Placements,
        grains: Sequence[Grain] | Mapping[int, Grain],
        velocity: ArrayLike | None,
    ) -> list[Body]:
        """One particle per placement, from the grain of its kind (Simulation.add_placements)."""
        chosen = grains_by_kind(grains, placements.kinds)
        return [
            self.add_particle(
                grain.reference,
                grain.material,
                position=placements.positions[k],
                rotation=placements.rotations[k],
                scale=float(placements.radii[k] / grain.radius),
                velocity=velocity,
                angular_velocity=None,
                name=None,
            )
            for k, grain in enumerate(chosen)
        ]

    def add_packing(self, packing: Packing, velocity: ArrayLike | None) -> list[Body]:
        bodies = self.add_placements(packing, packing.grains, velocity)
        self.packings.append(packing)
        return bodies

    def add_body_from_nodes(
        self,
        positions: ArrayLike,
        volumes: ArrayLike,
        material: Material,
        mesh_size: float,
        *,
        velocity: ArrayLike | None,
        angular_velocity: float | ArrayLike | None,
        name: str | None,
    ) -> Body:
        """A body from its nodes (Simulation.add_body_from_nodes)."""
        p = np.asarray(positions, dtype=np.float64)
        if p.ndim != 2 or p.shape[1] not in (self.dimension, 3):
            raise InputError(
                f"positions must be an (n, {self.dimension}) array, got shape {p.shape}"
            )
        if p.shape[1] == 2:
            p = np.column_stack([p, np.zeros(len(p))])
        v = np.asarray(volumes, dtype=np.float64).reshape(-1)
        if len(v) != len(p):
            raise InputError(f"{len(p)} positions but {len(v)} volumes")
        check_number("add_body_from_nodes: mesh_size", mesh_size)
        if not (np.isfinite(mesh_size) and mesh_size > 0):
            raise InputError(f"mesh size must be positive, got {mesh_size}")
        nodes = StoredNodes(p, v)
        return self._add(nodes, material, mesh_size, velocity, angular_velocity, name, None, 1.0)

    def _add(
        self,
        nodes: BodyNodes,
        material: Material,
        mesh_size: float,
        velocity: ArrayLike | None,
        angular_velocity: float | ArrayLike | None,
        name: str | None,
        reference: ReferenceShape | None,
        scale: float,
    ) -> Body:
        if not isinstance(material, Material):
            raise InputError(
                f"material must be a granulate.Material, got {type(material).__name__}"
            )
        index = len(self.bodies)
        if name is not None and name in self._names:
            raise InputError(f"a body named {name!r} exists already; give each body its own name")
        body = Body(
            index,
            name or f"body{index}",
            self.node_count,
            nodes.node_count,
            material,
            float(mesh_size),
            reference,
            scale,
        )
        self.bodies.append(body)
        self._names.setdefault(body.name, body)
        if isinstance(nodes, StoredNodes):
            nodes = StoredNodes(
                np.ascontiguousarray(nodes.position_array),
                np.ascontiguousarray(nodes.volume_array),
            )
        self._nodes.append(nodes)
        self.surfaces.append(None)
        if velocity is not None or angular_velocity is not None:
            self.initial_velocities.append((body, *self._motion(velocity, angular_velocity)))
        return body

    def _motion(
        self, velocity: ArrayLike | None, angular_velocity: float | ArrayLike | None
    ) -> tuple[NDArray[np.float64], float | NDArray[np.float64]]:
        """A body's initial linear velocity and spin, checked."""
        linear = np.zeros(3) if velocity is None else self.vector(velocity, "velocity")
        spin: float | NDArray[np.float64] = 0.0
        if angular_velocity is not None:
            if self.dimension == 2:
                spin = float(np.asarray(angular_velocity).reshape(-1)[-1])
            else:
                spin = self.vector(angular_velocity, "angular_velocity")
        return linear, spin

    def subset(self, grains: ArrayLike) -> tuple[Assembly, NodeMap]:
        """The bodies `grains` (indices, increasing) as an assembly of their own, renumbered in
        that order, with their initial motions; and the map of this assembly's node indices to
        the subset's (-1 for nodes left out). A distributed run's rank holds such a subset: the
        grains it owns and its ghosts (granulate.parallel). The subset's bodies take their core
        shapes from this assembly's (`parent`), so translated copies share the bond lengths of
        the same body here, whichever grains the subset holds."""
        chosen = np.asarray(grains, dtype=np.int64).reshape(-1)
        if len(chosen) == 0 or np.any(np.diff(chosen) <= 0) or chosen[0] < 0:
            raise InputError("subset: give increasing body indices")
        if chosen[-1] >= len(self.bodies):
            raise InputError(f"subset: body {chosen[-1]} does not exist")
        part = Assembly(self.dimension)
        part.parent = (
            (self, chosen) if self.parent is None else (self.parent[0], self.parent[1][chosen])
        )
        local = np.full(len(self.bodies), -1, dtype=np.int64)
        renamed: dict[int, Body] = {}
        for g in chosen:
            body = self.bodies[g]
            copy = replace(body, index=len(part.bodies), first_node=part.node_count)
            local[g] = copy.first_node
            part.bodies.append(copy)
            part._names[copy.name] = copy
            part._nodes.append(self._nodes[g])
            part.surfaces.append(self.surfaces[g])
            renamed[int(g)] = copy
        part.initial_velocities = [
            (renamed[body.index], linear, spin)
            for body, linear, spin in self.initial_velocities
            if body.index in renamed
        ]
        starts = np.array([body.first_node for body in self.bodies], dtype=np.int64)
        counts = np.array([body.node_count for body in self.bodies], dtype=np.int64)
        return part, NodeMap(starts, counts, local)

    def body(self, body: Body | str) -> Body:
        """A body of this assembly, or the one of that name (InputError otherwise)."""
        if isinstance(body, Body):
            if body.index >= len(self.bodies) or self.bodies[body.index] is not body:
                raise InputError(f"body {body.name!r} belongs to another simulation")
            return body
        if isinstance(body, str) and body in self._names:
            return self._names[body]
        match = difflib.get_close_matches(str(body), list(self._names), n=1)
        hint = f"; did you mean {match[0]!r}?" if match else ""
        raise InputError(f"no body named {body!r}{hint}")

    def select(
        self,
        reference_positions: NDArray[np.float64],
        region: Shape | None,
        body: Body | None,
        ids: ArrayLike | None,
    ) -> NDArray[np.uint32]:
        """Node indices selected by a region (tested on `reference_positions`), a body, or ids,
        combined by intersection (Simulation.select)."""
        count = self.node_count
        mask = np.ones(count, dtype=bool)
        if region is not None:
            mask &= region.contains(reference_positions)
        if body is not None:
            in_body = np.zeros(count, dtype=bool)
            in_body[body.node_slice] = True
            mask &= in_body
        if ids is not None:
            chosen = np.asarray(ids, dtype=np.int64).reshape(-1)
            if np.any(chosen < 0) or np.any(chosen >= count):
                raise InputError(f"node ids must be in [0, {count}), got some outside")
            in_ids = np.zeros(count, dtype=bool)
            in_ids[chosen] = True
            mask &= in_ids
        nodes = np.flatnonzero(mask).astype(np.uint32)
        if len(nodes) == 0:
            raise InputError("the selection contains no node; check the region against the bodies")
        return nodes

    def set_initial_velocities(self, model: _core.Model, core: _core.Simulation) -> None:
        """Each body's initial velocity: v + omega x (X - its centroid)."""
        velocities = core.velocities
        X = model.reference_positions
        volumes = model.volumes
        for body, linear, spin in self.initial_velocities:
            sl = body.node_slice
            centroid = np.average(X[sl], axis=0, weights=volumes[sl])
            arm = X[sl] - centroid
            omega = np.array([0.0, 0.0, spin]) if np.isscalar(spin) else np.asarray(spin)
            velocities[sl] = linear + np.cross(omega, arm)

    def centres_and_radii(self) -> tuple[list[int], list[float]]:
        """Per body, the node nearest its centre and its radius about that centre [m] (PeriDEM's
        particle centres and radii, for its damping)."""
        centers, radii = [], []
        for body in self.bodies:
            if body.reference is not None:
                local = body.reference.positions
                distance = np.linalg.norm(local, axis=1)
                centers.append(body.first_node + int(np.argmin(distance)))
                radii.append(float(distance.max()) * body.scale)
            else:
                nodes = self.positions[body.index]
                distance = np.linalg.norm(nodes - nodes.mean(axis=0), axis=1)
                centers.append(body.first_node + int(np.argmin(distance)))
                radii.append(float(distance.max()))
        return centers, radii


def placements_now(
    bodies: Sequence[Body],
    placements: Placements,
    model: _core.Model,
    positions: NDArray[np.float64],
) -> Placements:
    """`placements` moved to where `bodies` (the particles added from them) are at
    `positions`: each one's rigid-body fit (Simulation.placements_now). 2D: the angle
    atan2(sum w a x b, sum w a . b); 3D: Kabsch's rotation (an SVD of sum w a b^T), a and b
    being the reference and current nodes about their volume-weighted centroids."""
    dimension = model.dimension
    volumes = np.asarray(model.volumes)
    moved, rotations = placements.positions.copy(), placements.rotations.copy()
    for k, body in enumerate(bodies):
        nodes = body.node_slice
        w = volumes[nodes] / volumes[nodes].sum()
        before, now = model.reference_positions[nodes], positions[nodes]
        c0, c = reductions.weighted_sum(w, before), reductions.weighted_sum(w, now)
        a, b = before - c0, now - c
        if dimension == 2:
            cross = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
            turn = float(
                np.arctan2(reductions.dot(w, cross), reductions.dot(w, np.sum(a * b, axis=1)))
            )
            rotation = rotation_matrix(turn, 2)
            rotations[k] = rotations[k] + turn
        else:
            u, _, vt = np.linalg.svd(reductions.outer_sum(a * w[:, None], b))
            flip = np.diag([1.0, 1.0, np.sign(np.linalg.det(vt.T @ u.T))])
            rotation = vt.T @ flip @ u.T
            rotations[k] = _rotation_vector(rotation @ rotation_matrix(rotations[k], 3))
        moved[k] = c + rotation @ (placements.positions[k] - c0)
    return replace(placements, positions=moved, rotations=rotations)


def _rotation_vector(rotation: NDArray[np.float64]) -> NDArray[np.float64]:
    """The rotation vector (axis times angle [rad]) of a 3 x 3 rotation matrix."""
    angle = float(np.arccos(np.clip((np.trace(rotation) - 1) / 2, -1.0, 1.0)))
    if angle < 1e-12:
        return np.zeros(3)
    if np.pi - angle < 1e-6:  # a half turn: the axis from the symmetric part
        axis = np.sqrt(np.clip((np.diag(rotation) + 1) / 2, 0.0, None))
        k = int(np.argmax(axis))
        axis = (rotation[k] + np.eye(3)[k]) / (2 * axis[k])
        return angle * axis / np.linalg.norm(axis)
    skew = np.array(
        [
            rotation[2, 1] - rotation[1, 2],
            rotation[0, 2] - rotation[2, 0],
            rotation[1, 0] - rotation[0, 1],
        ]
    )
    return angle * skew / (2 * np.sin(angle))
