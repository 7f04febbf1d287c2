"""The Python front of a granulate simulation.

Build the model (bodies, materials, loading, outputs), then ``run``. The model is handed to the
C++ core on the first run (or the first access to the state); after that, bodies can no longer
be added. State arrays (``positions``, ``velocities``, ...) are zero-copy NumPy views into the
core: they stay valid as long as the simulation exists, and writing to ``velocities`` before a
run sets initial conditions.

Units are SI. In 2D a body is a slab of unit thickness: volumes are areas [m^2], force
densities stay N/m^3, forces (force density x volume) are N per metre of thickness and
energies J per metre.
"""

from __future__ import annotations

import difflib
import time as wallclock
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from granulate import (
    _core,
    checkpoints,
    fragments,
    network,
    particle_table,
    reductions,
    resources,
    run_loop,
    threads,
)
from granulate._version import __version__
from granulate.checkpoints import CheckpointPlan
from granulate.contact import Contact
from granulate.errors import GranulateWarning, InputError
from granulate.functions import Constant, Linear, TimeFunction, VelocityRamp
from granulate.input_errors import check_number, unknown_name
from granulate.io import PvdSeries
from granulate.io import checkpoint as checkpoint_file
from granulate.io.run_folder import RunFolder
from granulate.materials import Material
from granulate.packing import Grain, Packing, Placements, grains_by_kind
from granulate.run_loop import Progress, RunPlan, RunRecord
from granulate.shape_sharing import TranslatedShapes
from granulate.shapes import ReferenceShape, Shape, rotation_matrix
from granulate.stopping import StopCriterion
from granulate.walls import Surface, Wall
from granulate.writers.outputs import Outputs

Components = str  # any of "x", "y", "z", e.g. "xy"

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
HISTORY_COLUMNS = (
    "step",
    "time",
    "kinetic_energy",
    "strain_energy",
    "gravity_energy",
    "contact_energy",
    "total_energy",
    "broken_bonds",
    "node_contacts",
    "wall_contacts",
    "list_rebuilds",
    "fragments",
    "debris_nodes",
    "debris_mass",
    "particles_split",
    "mean_damage",
    "contacts",
    "coordination",
)


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


def _read_only(array: NDArray) -> NDArray:
    """A view of `array` that cannot be written (the core keeps writing the original)."""
    view = array.view()
    view.flags.writeable = False
    return view


def _component_mask(components: Components, dimension: int) -> int:
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


class Simulation:
    """A peridynamic simulation of one or more bodies.

    Args:
        dimension: 2 or 3.
        plane: 2D assumption, ``"strain"`` (default) or ``"stress"``; ignored in 3D.
            ``"peridem"`` reproduces PeriDEM's 2D LPS (3D coefficients and critical stretch in
            2D), for comparisons with PeriDEM only: it does not give the material's 2D moduli.
        dt: time step [s]; default ``dt_safety`` times the stable estimate.
        dt_safety: fraction of the stable estimate used when ``dt`` is not given.
        gravity: body acceleration [m/s^2], e.g. (0, -9.81, 0).
        viscous_damping: background damping rate gamma [1/s] (force density -gamma rho v) for
            quasi-static settling; 0 (off) for dynamics, since it also damps rigid motion.
    """

    def __init__(
        self,
        dimension: int = 2,
        plane: Literal["strain", "stress", "peridem"] = "strain",
        *,
        dt: float | None = None,
        dt_safety: float = 0.8,
        gravity: ArrayLike | None = None,
        viscous_damping: float = 0.0,
    ) -> None:
        if dimension not in (2, 3):
            raise InputError(f"dimension must be 2 or 3, got {dimension!r}")
        if plane not in ("strain", "stress", "peridem"):
            raise InputError(f"plane must be 'strain', 'stress' or 'peridem', got {plane!r}")
        if not 0 < dt_safety <= 1:
            raise InputError(f"dt_safety must be in (0, 1], got {dt_safety}")
        self.dimension = dimension
        self.plane = plane
        self._dt = None if dt is None else self._check_dt(dt)
        self._dt_safety = dt_safety
        self._gravity = np.zeros(3)
        self.bodies: list[Body] = []
        self._body_names: dict[str, Body] = {}  # every body by name (adding one is O(1))
        self._labels: tuple[tuple[int, int], NDArray[np.uint32]] | None = None  # fragments
        self._positions: list[NDArray[np.float64]] = []
        self._volumes: list[NDArray[np.float64]] = []
        # Per body without a reference shape: the discretised shape its nodes came from (for
        # its surface offsets and depths), or None.
        self._surfaces: list[ReferenceShape | None] = []
        self._initial_velocities: list[
            tuple[Body, NDArray[np.float64], float | NDArray[np.float64]]
        ] = []
        self._loads: list[tuple[str, tuple]] = []
        self._output: Outputs | None = None
        self._contact: Contact | None = Contact()
        self._pair_contacts: dict[tuple[int, int], Contact | None] = {}
        self._peridem_damping: dict[tuple[int, int], tuple[float, float]] = {}
        self._peridem_walls: list[Body | str] = []
        self._walls: list[tuple[str, Wall]] = []
        self._skin: float | None = None
        self._core: _core.Simulation | None = None
        self._model: _core.Model | None = None
        self._reference: NDArray[np.float64] | None = None
        self._record = RunRecord()
        self._precracks: list[tuple[NDArray[np.float64], NDArray[np.float64], Shape | None]] = []
        self._tuner: threads.ThreadTuner | None = None
        self._deep_contact_warned = False
        self._output_seconds = 0.0
        self._core_materials: list[Material] = []
        self._setup_digest: str | None = None
        self._checkpoint: CheckpointPlan | None = None
        #: Packings added with add_packing (for summaries).
        self.packings: list[Packing] = []
        #: Extra text identifying the set-up (a case file's hash), checked by load_checkpoint.
        self.case_fingerprint = ""
        self.viscous_damping = viscous_damping
        if gravity is not None:
            self.gravity = gravity  # type: ignore[assignment]

    # ------------------------------------------------------------------ building
    @staticmethod
    def _check_dt(dt: float) -> float:
        check_number("time step dt", dt)
        if not (np.isfinite(dt) and dt > 0):
            raise InputError(f"time step dt must be a positive number of seconds, got {dt!r}")
        return float(dt)

    def _require_building(self, what: str) -> None:
        if self._core is not None:
            raise InputError(
                f"cannot {what} after the simulation has started; build everything first"
            )

    def add_body(
        self,
        shape: Shape,
        material: Material,
        mesh_size: float,
        *,
        discretization: str = "lattice",
        jitter: float = 0.0,
        seed: int = 0,
        velocity: ArrayLike | None = None,
        angular_velocity: float | ArrayLike | None = None,
        name: str | None = None,
    ) -> Body:
        """Discretize a shape with nodes of spacing ``mesh_size`` [m] and add it.

        ``discretization``: "lattice" (uniform lattice clipped to the shape; optional
        ``jitter``) or "conforming" (rings or shells following the surface of a Disc, Ellipse,
        Sphere or Ellipsoid; see granulate.shapes.conforming). ``velocity`` [m/s] and
        ``angular_velocity`` [rad/s; a scalar about z in 2D, a vector in 3D, about the body's
        centroid] set the initial motion.
        """
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
        self._surfaces[body.index] = reference
        return body

    def add_particle(
        self,
        reference: ReferenceShape,
        material: Material,
        *,
        position: ArrayLike = (0.0, 0.0, 0.0),
        rotation: float | ArrayLike | None = None,
        scale: float = 1.0,
        velocity: ArrayLike | None = None,
        angular_velocity: float | ArrayLike | None = None,
        name: str | None = None,
    ) -> Body:
        """Place a reference shape: x = position + R (scale p) for its local nodes p.

        ``rotation``: an angle [rad] about z (2D), or in 3D a rotation vector or a 3x3 matrix.
        Particles placed from one reference shape share its bonds in memory (per distinct
        scale when the material's horizon is absolute). The mesh size is scale times the
        shape's; volumes scale with scale^d.
        """
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
        placed = (
            self._vector(position, "position")
            + (scale * reference.positions) @ rotation_matrix(rotation, self.dimension).T
        )
        if self.dimension == 2:
            placed[:, 2] = 0.0
        return self._add(
            placed,
            reference.volumes * scale**self.dimension,
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
        *,
        velocity: ArrayLike | None = None,
    ) -> list[Body]:
        """Add one particle per placement (see granulate.packing): the grain of its kind
        (zone), scaled by r / r_ref, rotated and moved into place; all share the grain's
        discretization. ``grains``: a list indexed by kind, or a {zone: Grain} mapping (PeriDEM
        CSV zones). ``velocity`` [m/s]: initial velocity of every particle."""
        chosen = grains_by_kind(grains, placements.kinds)
        return [
            self.add_particle(
                grain.reference,
                grain.material,
                position=placements.positions[k],
                rotation=placements.rotations[k],
                scale=float(placements.radii[k] / grain.radius),
                velocity=velocity,
            )
            for k, grain in enumerate(chosen)
        ]

    def add_packing(self, packing: Packing, *, velocity: ArrayLike | None = None) -> list[Body]:
        """Add the particles of a generated packing (``granulate.pack``)."""
        bodies = self.add_placements(packing, packing.grains, velocity=velocity)
        self.packings.append(packing)
        return bodies

    def placements_now(self, bodies: Sequence[Body], placements: Placements) -> Placements:
        """`placements` (a packing, say) moved to where `bodies`, the particles added from it,
        are now: each one's rigid-body fit, its nodes' centroid and the rotation that best
        maps its reference nodes onto its current ones (2D: the angle; 3D: Kabsch's, as a
        rotation vector). The elastic strain is left out. To continue from a settled pile in a
        new simulation, with walls placed on it: ``sim2.add_packing(sim.placements_now(bodies,
        packing))``."""
        if len(bodies) != len(placements):
            raise InputError(
                f"placements_now: {len(bodies)} bodies for {len(placements)} placements; give "
                "the bodies add_packing (or add_placements) returned for them"
            )
        core, model = self._build(), self.model
        volumes = np.asarray(model.volumes)
        positions, rotations = placements.positions.copy(), placements.rotations.copy()
        for k, body in enumerate(bodies):
            nodes = slice(body.first_node, body.first_node + body.node_count)
            w = volumes[nodes] / volumes[nodes].sum()
            before, now = model.reference_positions[nodes], core.positions[nodes]
            c0, c = reductions.weighted_sum(w, before), reductions.weighted_sum(w, now)
            a, b = before - c0, now - c
            if self.dimension == 2:
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
            positions[k] = c + rotation @ (placements.positions[k] - c0)
        return replace(placements, positions=positions, rotations=rotations)

    def add_body_from_nodes(
        self,
        positions: ArrayLike,
        volumes: ArrayLike,
        material: Material,
        mesh_size: float,
        *,
        velocity: ArrayLike | None = None,
        angular_velocity: float | ArrayLike | None = None,
        name: str | None = None,
    ) -> Body:
        """Add a body from its nodes: positions (n, 2 or 3) [m] and volumes (n,) [m^d]."""
        self._require_building("add a body")
        if not isinstance(material, Material):
            raise InputError(
                f"material must be a granulate.Material, got {type(material).__name__}"
            )
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
        return self._add(p, v, material, mesh_size, velocity, angular_velocity, name, None, 1.0)

    def _add(
        self,
        p: NDArray[np.float64],
        v: NDArray[np.float64],
        material: Material,
        mesh_size: float,
        velocity: ArrayLike | None,
        angular_velocity: float | ArrayLike | None,
        name: str | None,
        reference: ReferenceShape | None,
        scale: float,
    ) -> Body:
        self._require_building("add a body")
        if not isinstance(material, Material):
            raise InputError(
                f"material must be a granulate.Material, got {type(material).__name__}"
            )
        index = len(self.bodies)
        first = self.node_count
        if name is not None and name in self._body_names:
            raise InputError(f"a body named {name!r} exists already; give each body its own name")
        body = Body(
            index,
            name or f"body{index}",
            first,
            len(p),
            material,
            float(mesh_size),
            reference,
            scale,
        )
        self.bodies.append(body)
        self._body_names.setdefault(body.name, body)
        self._positions.append(np.ascontiguousarray(p))
        self._volumes.append(np.ascontiguousarray(v))
        self._surfaces.append(None)
        if velocity is not None or angular_velocity is not None:
            linear = np.zeros(3) if velocity is None else self._vector(velocity, "velocity")
            spin: float | NDArray[np.float64] = 0.0
            if angular_velocity is not None:
                if self.dimension == 2:
                    spin = float(np.asarray(angular_velocity).reshape(-1)[-1])
                else:
                    spin = self._vector(angular_velocity, "angular_velocity")
            self._initial_velocities.append((body, linear, spin))
        return body

    def _vector(self, value: ArrayLike, name: str) -> NDArray[np.float64]:
        array = np.asarray(value, dtype=np.float64).reshape(-1)
        if array.shape not in ((self.dimension,), (3,)) or not np.all(np.isfinite(array)):
            raise InputError(f"{name} must be {self.dimension} finite numbers, got {value!r}")
        out = np.zeros(3)
        out[: len(array)] = array
        if self.dimension == 2 and out[2] != 0:
            raise InputError(f"{name} has a z component in a 2D simulation")
        return out

    @property
    def reference_positions(self) -> NDArray[np.float64]:
        """(n, 3) reference positions X of all nodes [m], read-only."""
        if self._model is not None:
            return _read_only(self._model.reference_positions)
        if not self._positions:
            return np.zeros((0, 3))
        return np.concatenate(self._positions)

    def select(
        self,
        region: Shape | None = None,
        *,
        body: Body | None = None,
        ids: ArrayLike | None = None,
    ) -> NDArray[np.uint32]:
        """Node indices selected by a region (tested on reference positions), a body, or ids.

        Criteria combine by intersection. Raises InputError when nothing is selected.
        """
        count = self.node_count
        mask = np.ones(count, dtype=bool)
        if region is not None:
            mask &= region.contains(self.reference_positions)
        if body is not None:
            in_body = np.zeros(count, dtype=bool)
            in_body[body.first_node : body.first_node + body.node_count] = True
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

    def _nodes(self, nodes: ArrayLike) -> NDArray[np.uint32]:
        array = np.asarray(nodes).reshape(-1)
        count = self.node_count
        if len(array) == 0:
            raise InputError("the node set is empty")
        if array.dtype.kind not in "iu" or np.any(array < 0) or np.any(array >= count):
            raise InputError(f"node ids must be integers in [0, {count})")
        return np.ascontiguousarray(array, dtype=np.uint32)

    def fix(self, nodes: ArrayLike, components: Components = "xyz") -> None:
        """Hold the given components of the nodes at their reference position."""
        components = components[: self.dimension] if components == "xyz" else components
        self._prescribe(nodes, np.zeros(3), Constant(0.0), components)

    def prescribe_displacement(
        self,
        nodes: ArrayLike,
        direction: ArrayLike,
        function: TimeFunction,
        *,
        components: Components | None = None,
    ) -> None:
        """Impose x = X + f(t) * direction on the given components (default: all).

        Example: ``prescribe_displacement(ids, (1, 0), Linear(0.01))`` pulls at 0.01 m/s in x.
        A zero direction would hold the nodes still: use ``fix`` for that.
        """
        vector = self._vector(direction, "direction")
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
        self._require_building("add loading")
        mask = _component_mask(components or "xyz"[: self.dimension], self.dimension)
        self._loads.append(("displacement", (self._nodes(nodes), mask, vector, function)))

    def prescribe_velocity(
        self,
        nodes: ArrayLike,
        velocity: ArrayLike,
        *,
        ramp_time: float = 0.0,
        components: Components | None = None,
    ) -> None:
        """Move nodes at a constant velocity [m/s], reached smoothly over ``ramp_time`` [s]."""
        v = self._vector(velocity, "velocity")
        speed = float(np.linalg.norm(v))
        if speed == 0:
            self.fix(nodes, components or "xyz"[: self.dimension])
            return
        function: TimeFunction = VelocityRamp(speed, ramp_time) if ramp_time > 0 else Linear(speed)
        self.prescribe_displacement(nodes, v / speed, function, components=components)

    def prescribe_rotation(
        self,
        nodes: ArrayLike,
        center: ArrayLike,
        angle: TimeFunction,
        *,
        axis: ArrayLike = (0, 0, 1),
    ) -> None:
        """Rigid rotation x = c + R(angle(t)) (X - c) about an axis through c (z in 2D)."""
        self._require_building("add loading")
        axis_vector = np.asarray(axis, dtype=float).reshape(-1)
        if self.dimension == 2 and not np.allclose(axis_vector, (0, 0, 1)):
            raise InputError("in 2D, rotations are about the z axis")
        self._loads.append(
            ("rotation", (self._nodes(nodes), self._vector(center, "center"), axis_vector, angle))
        )

    def add_force_density(
        self, nodes: ArrayLike, vector: ArrayLike, function: TimeFunction | None = None
    ) -> None:
        """Add f(t) * vector [N/m^3, also in 2D] to the force density of the nodes."""
        self._require_building("add loading")
        self._loads.append(
            (
                "force",
                (
                    self._nodes(nodes),
                    self._vector(vector, "force density"),
                    function or Constant(1.0),
                ),
            )
        )

    @property
    def gravity(self) -> NDArray[np.float64]:
        """Body acceleration g [m/s^2] (adds rho g to every node)."""
        return self._gravity.copy()

    @gravity.setter
    def gravity(self, value: ArrayLike) -> None:
        self._gravity = self._vector(value, "gravity")
        if self._core is not None:
            self._core.set_body_acceleration(tuple(self._gravity))

    #: The attributes a user may set besides the properties with setters.
    _SETTABLE = ("dimension", "plane", "bodies", "packings", "case_fingerprint")

    def __setattr__(self, name: str, value: object) -> None:
        """Refuses attributes the class does not have: a misspelt or invented one
        (``sim.damping = 5``) would otherwise be stored and do nothing."""
        if name.startswith("_") or name in self._SETTABLE:
            object.__setattr__(self, name, value)
            return
        known = getattr(type(self), name, None)
        if isinstance(known, property) and known.fset is not None:
            object.__setattr__(self, name, value)
            return
        settable = sorted(
            n for n, v in vars(Simulation).items() if isinstance(v, property) and v.fset is not None
        )
        what = "cannot be set" if known is not None else "is not an attribute of Simulation"
        raise InputError(f"{name!r} {what}{unknown_name(name, settable)}")

    @property
    def viscous_damping(self) -> float:
        """Background damping rate gamma [1/s]: force density -gamma rho v on every node (set it
        before the first run; settles piles quasi-statically)."""
        return self._viscous_damping

    @viscous_damping.setter
    def viscous_damping(self, value: float) -> None:
        self._require_building("change the viscous damping")
        check_number("viscous_damping", value)
        if not (np.isfinite(value) and value >= 0):
            raise InputError(f"viscous_damping must be a non-negative rate in 1/s, got {value}")
        self._viscous_damping = float(value)

    @property
    def contact(self) -> Contact | None:
        """Contact between all particles (and fragments) unless set per pair; None: no contact."""
        return self._contact

    @contact.setter
    def contact(self, value: Contact | None) -> None:
        self._require_building("change contact")
        if value is not None and not isinstance(value, Contact):
            raise InputError(
                f"contact must be a granulate.Contact or None, got {type(value).__name__}"
            )
        self._contact = value

    def set_contact(self, a: Material, b: Material, contact: Contact | None) -> None:
        """Contact between bodies of materials a and b (None: they pass through each other)."""
        self._require_building("change contact")
        if contact is not None and not isinstance(contact, Contact):
            raise InputError(
                f"contact must be a granulate.Contact or None, got {type(contact).__name__}"
            )
        self._pair_contacts[(id(a), id(b))] = contact
        self._pair_contacts[(id(b), id(a))] = contact

    def set_peridem_damping(
        self, a: Material, b: Material, *, epsilon: float, beta_factor: float = 1.0
    ) -> None:
        """PeriDEM's contact damping between particles of materials a and b, for comparisons
        with PeriDEM only (``--peridem-compat``): it acts between particle centres and does not
        give the restitution ``epsilon`` names (formulas: contact/peridem_damping.hpp). The
        contact law of the pair should then have restitution 1, or both dampings act.
        ``beta_factor`` is PeriDEM's Beta_n_Factor."""
        self._require_building("change contact")
        if not (0 < epsilon <= 1):
            raise InputError(f"epsilon must be in (0, 1], got {epsilon}")
        if not (beta_factor >= 0 and np.isfinite(beta_factor)):
            raise InputError(f"beta_factor must be a non-negative number, got {beta_factor}")
        self._peridem_damping[(id(a), id(b))] = (float(epsilon), float(beta_factor))
        self._peridem_damping[(id(b), id(a))] = (float(epsilon), float(beta_factor))

    def set_peridem_walls(self, bodies: Sequence[Body | str]) -> None:
        """The bodies PeriDEM's damping treats as walls (PeriDEM's Is_Wall zones): they damp
        particles through their nodes and are not damped themselves."""
        self._require_building("change contact")
        self._peridem_walls = list(bodies)

    def _set_peridem_damping(self, core: _core.Simulation, materials: list[Material]) -> None:
        if not self._peridem_damping:
            return
        walls = {self._body(b).index for b in self._peridem_walls}
        centers, radii = [], []
        for body in self.bodies:
            if body.reference is not None:
                local = body.reference.positions
                distance = np.linalg.norm(local, axis=1)
                centers.append(body.first_node + int(np.argmin(distance)))
                radii.append(float(distance.max()) * body.scale)
            else:
                nodes = self._positions[body.index]
                distance = np.linalg.norm(nodes - nodes.mean(axis=0), axis=1)
                centers.append(body.first_node + int(np.argmin(distance)))
                radii.append(float(distance.max()))
        count = len(materials)
        betan, kappa, radius = np.zeros((3, count, count))
        for a, material_a in enumerate(materials):
            for b, material_b in enumerate(materials):
                setting = self._peridem_damping.get((id(material_a), id(material_b)))
                if setting is None:
                    continue
                epsilon, factor = setting
                contact = self._pair_contacts.get((id(material_a), id(material_b)), self._contact)
                if contact is None:
                    raise InputError(
                        "PeriDEM damping is set for a pair of materials without contact"
                    )
                if contact.contact_radius is not None:
                    radius[a, b] = contact.contact_radius
                else:  # factor x the smallest mesh size among particles of the two materials
                    sizes = [
                        bd.mesh_size
                        for bd in self.bodies
                        if bd.material is material_a or bd.material is material_b
                    ]
                    radius[a, b] = contact.contact_radius_factor * min(sizes, default=0.0)
                log_e = np.log(epsilon)
                betan[a, b] = factor * (-2 * log_e / np.sqrt(np.pi**2 + log_e**2))
                k_a, k_b = material_a.elastic_moduli()[0], material_b.elastic_moduli()[0]
                kappa[a, b] = 2 * k_a * k_b / (k_a + k_b)  # PeriDEM's harmonic mean
        core.set_peridem_damping(
            np.asarray(centers, dtype=np.uint32),
            np.asarray(radii),
            np.asarray([1 if k in walls else 0 for k in range(len(self.bodies))], dtype=np.uint32),
            betan.ravel(),
            kappa.ravel(),
            radius.ravel(),
        )

    def set_neighbor_skin(self, skin: float) -> None:
        """Verlet skin of the contact neighbour lists [m] (default: half the contact radius)."""
        if not (np.isfinite(skin) and skin > 0):
            raise InputError(f"skin must be a positive length, got {skin}")
        self._skin = float(skin)
        if self._core is not None:
            self._core.set_contact_skin(self._skin)

    def add_wall(self, wall: Wall | Surface, *, name: str | None = None) -> str:
        """Add a rigid wall (or one fixed surface); returns its name, used in history.csv."""
        self._require_building("add a wall")
        if isinstance(wall, Surface):
            wall = Wall((wall,))
        if not isinstance(wall, Wall):
            raise InputError(
                f"add_wall takes a granulate Wall or surface, got {type(wall).__name__}"
            )
        label = name or wall.name or f"wall{len(self._walls)}"
        if any(label == existing for existing, _ in self._walls):
            raise InputError(f"a wall named {label!r} exists already; give each wall its own name")
        if not label.replace("_", "").isalnum():
            raise InputError(f"wall name {label!r} must be letters, digits and underscores")
        wall.core(label, self.dimension)  # checks the description now, not at the first run
        self._walls.append((label, wall))
        return label

    @property
    def walls(self) -> tuple[tuple[str, Wall], ...]:
        """The walls added, in order, with their names (history.csv's <name>_fx, ...)."""
        return tuple(self._walls)

    def wall_reactions(self) -> dict[str, NDArray[np.float64]]:
        """Per wall: (fx, fy, fz, tx, ty, tz), the force and torque the particles exert on it
        at the last step [N, N m; per unit thickness in 2D]."""
        core = self._build()
        names = [name for name, _ in self._walls]
        return {name: np.asarray(r) for name, r in zip(names, core.wall_reactions(), strict=True)}

    def output(
        self,
        directory: str | Path,
        every: int,
        *,
        fields: tuple[str, ...] = FIELDS,
        overwrite: bool = False,
        resume: bool = False,
        history_every: int | None = None,
        track: Sequence[Body | str] = (),
        track_areas: Mapping[str, float] | None = None,
    ) -> None:
        """Write VTU frames (``frames/``), ``simulation.pvd`` and particle snapshots
        (``frames/particles_*.csv``) every ``every`` steps, and a row of ``history.csv`` every
        ``history_every`` steps (default: with each frame).

        ``track``: bodies (or their names) whose load and motion history.csv records:
        ``<name>_fx, _fy[, _fz]``, the resultant of the forces on the body other than gravity
        (contacts, walls, applied force densities, viscous damping; the internal bond forces
        cancel) [N; N/m in 2D], and ``<name>_ux, _uy[, _uz]``, its mean nodal displacement
        [m]. For a body whose nodes are all prescribed (a meshed wall, a loading platen) the
        force is the reaction a load cell would measure. ``track_areas`` maps tracked bodies'
        names to a nominal area [m^2; m in 2D, per unit thickness], for which history.csv also
        records ``<name>_stress``, the magnitude of that resultant over the area [Pa] (a loading
        platen's stress, as ``Wall(area=)`` gives a wall's).

        A directory that already holds a run (simulation.pvd or frames) is refused unless
        ``overwrite`` is true (the old run is deleted when the new one starts writing, so an
        error found before leaves it intact) or ``resume`` is true (it is kept for
        ``load_checkpoint``, which must follow; temporaries of interrupted writes are removed).
        A file, or a directory you cannot write, is refused at once; while a run writes, the
        directory is locked (.granulate.lock) against a second run.
        """
        if not (isinstance(every, int) and every > 0):
            raise InputError(f"output interval must be a positive number of steps, got {every!r}")
        history_every = every if history_every is None else history_every
        if not (isinstance(history_every, int) and history_every > 0):
            raise InputError(
                f"history interval must be a positive number of steps, got {history_every!r}"
            )
        tracked = tuple(self._body(b) for b in track)
        walls = {name for name, _ in self._walls}
        clashing = sorted({b.name for b in tracked} & walls)
        if clashing:
            raise InputError(
                f"tracked bodies {clashing} are named like walls: their history.csv columns "
                "(<name>_fx, ...) would overwrite each other; rename them"
            )
        areas = _track_areas(track_areas or {}, tracked)
        unknown = [f for f in fields if f not in FIELDS]
        if unknown:
            raise InputError(f"unknown output fields {unknown}; choose from {', '.join(FIELDS)}")
        path = Path(directory)
        folder = RunFolder(path, overwrite=overwrite, resume=resume)
        self._output = Outputs(
            path,
            every,
            tuple(fields),
            PvdSeries(path / "simulation.pvd"),
            history_every,
            folder,
            tracked,
            areas,
        )

    def _body(self, body: Body | str) -> Body:
        """A body of this simulation, or the one of that name (InputError otherwise)."""
        if isinstance(body, Body):
            if body.index >= len(self.bodies) or self.bodies[body.index] is not body:
                raise InputError(f"body {body.name!r} belongs to another simulation")
            return body
        if isinstance(body, str) and body in self._body_names:
            return self._body_names[body]
        match = difflib.get_close_matches(str(body), list(self._body_names), n=1)
        hint = f"; did you mean {match[0]!r}?" if match else ""
        raise InputError(f"no body named {body!r}{hint}")

    # ------------------------------------------------------------------ the core
    def _build(self) -> _core.Simulation:
        """The core simulation, made on first use: the model (materials, shapes, particles,
        bonds), contact laws and damping, the time step, loads, initial velocities, precracks."""
        if self._core is not None:
            return self._core
        if not self.bodies:
            raise InputError("the simulation has no body; add one with add_body")
        model, core_materials = self._build_model()
        core = _core.Simulation(model)
        self._set_contact_laws(core, core_materials)
        self._set_peridem_damping(core, core_materials)
        self._core_materials = core_materials
        self._check_start(model, core)
        self._set_time_step(core)
        core.set_body_acceleration(tuple(self._gravity))
        core.viscous_damping = self._viscous_damping
        self._apply_loads(core)
        self._set_initial_velocities(model, core)
        self._model = model
        self._core = core
        self._reference = model.reference_positions
        for crack in self._precracks:
            self._break_crossing_bonds(*crack)
        return core

    def _build_model(self) -> tuple[_core.Model, list[Material]]:
        """The finalized core model and its materials, in core order. One core material per
        Material; each particle carries its own horizon (absolute, or horizon_factor times its
        mesh size), so particles of any size share one material."""
        model = _core.Model(self.dimension, getattr(_core.PlaneMode, self.plane))
        # Lattices' and conforming discretisations' outer layers carry surface points only for
        # the surface law (the node-sphere law sees those nodes at themselves: no anchors).
        outer_layers = self._uses_surface_law()
        copy_of = self._translated_copies(outer_layers)
        self._require_memory_for_model(copy_of)
        material_ids: dict[int, int] = {}
        core_materials: list[Material] = []
        shape_ids: dict[int, int] = {}
        shape_of_body: dict[int, int] = {}  # bodies without a reference shape
        for body, positions, volumes, surface in zip(
            self.bodies, self._positions, self._volumes, self._surfaces, strict=True
        ):
            horizon = body.material.resolved_horizon(body.mesh_size)
            key = id(body.material)
            if key not in material_ids:
                material_ids[key] = model.add_material(body.material.core_params(body.mesh_size))
                core_materials.append(body.material)
            if body.reference is None:
                original = copy_of.get(body.index)
                if original is None:
                    surface_arrays = _surface_arrays(surface, outer_layers)
                    shape = model.add_shape(positions, volumes, body.mesh_size, *surface_arrays)
                else:
                    shape = shape_of_body[original]
                shape_of_body[body.index] = shape
                model.place_shape(shape, material_ids[key], positions, 1.0, horizon)
                continue
            reference = body.reference
            if id(reference) not in shape_ids:
                shape_ids[id(reference)] = model.add_shape(
                    reference.positions,
                    reference.volumes,
                    reference.mesh_size,
                    *_surface_arrays(reference, outer_layers),
                )
            model.place_shape(
                shape_ids[id(reference)], material_ids[key], positions, body.scale, horizon
            )
        model.finalize()
        return model, core_materials

    def _set_time_step(self, core: _core.Simulation) -> None:
        """dt as given (warned above the stable estimate), or dt_safety times that estimate."""
        if self._dt is None:
            core.time_step = self._dt_safety * core.stable_time_step
            return
        if self._dt > core.stable_time_step:
            warnings.warn(
                f"time step {self._dt:.4g} s exceeds the stable estimate "
                f"{core.stable_time_step:.4g} s; the run may become unstable",
                GranulateWarning,
                stacklevel=4,
            )
        core.time_step = self._dt

    def _apply_loads(self, core: _core.Simulation) -> None:
        """The prescribed displacements and rotations and the force densities, in order."""
        for kind, args in self._loads:
            if kind == "displacement":
                nodes, mask, direction, function = args
                core.add_displacement(nodes, mask, tuple(direction), *function.core())
            elif kind == "rotation":
                nodes, center, axis, function = args
                core.add_rotation(nodes, tuple(center), tuple(axis), *function.core())
            else:
                nodes, vector, function = args
                core.add_nodal_force(nodes, tuple(vector), *function.core())

    def _set_initial_velocities(self, model: _core.Model, core: _core.Simulation) -> None:
        """Each body's initial velocity: v + omega x (X - its centroid)."""
        velocities = core.velocities
        X = model.reference_positions
        volumes = model.volumes
        for body, linear, spin in self._initial_velocities:
            sl = slice(body.first_node, body.first_node + body.node_count)
            centroid = np.average(X[sl], axis=0, weights=volumes[sl])
            arm = X[sl] - centroid
            omega = np.array([0.0, 0.0, spin]) if np.isscalar(spin) else np.asarray(spin)
            velocities[sl] = linear + np.cross(omega, arm)

    def _check_start(self, model: _core.Model, core: _core.Simulation) -> None:
        """Refuse particles that start outside their container (inside an obstacle) or
        overlapping each other by more than half a mesh size."""
        owner = model.node_particle
        node, wall = core.first_wall_penetration()
        if node < model.node_count:
            body = self.bodies[owner[node]]
            where = ", ".join(f"{c:.4g}" for c in model.reference_positions[node][: self.dimension])
            raise InputError(
                f"{body.name} starts on the wrong side of wall {self._walls[wall][0]!r} (its "
                f"node {node} at ({where})); place it inside the container, or outside the "
                "obstacle"
            )
        i, j = core.first_overlap(0.5)
        if i < model.node_count:
            a, b = self.bodies[owner[i]], self.bodies[owner[j]]
            raise InputError(
                f"{a.name} and {b.name} overlap at the start (nodes {i} and {j} are closer than "
                "half a mesh size); move them apart, or generate the assembly with "
                "granulate.pack, which never overlaps"
            )

    @staticmethod
    def _law(contact: Contact) -> _core.ContactLaw:
        """The core law: Rc and kn absolute when given, else relative to the two particles
        (factor x the finer mesh size; factor x the default kn of the finer horizon)."""
        law = _core.ContactLaw()
        law.contact_radius = contact.contact_radius or 0.0
        law.contact_radius_factor = contact.contact_radius_factor
        law.normal_stiffness = contact.normal_stiffness or 0.0
        law.stiffness_factor = contact.stiffness_factor
        law.damping_ratio = _core.damping_ratio_from_restitution(contact.restitution)
        law.friction = contact.friction
        law.tangential_stiffness_ratio = contact.tangential_stiffness_ratio
        law.rolling_friction = contact.rolling_friction
        law.rolling_damping = contact.rolling_damping
        law.peridem_friction = contact.friction_law == "peridem"
        law.node_pair = contact.pair_law == "peridem"
        law.surface = contact.pair_law == "surface"
        return law

    def _uses_surface_law(self) -> bool:
        """Whether any contact law (the default, or one set per pair of materials) is the
        surface law."""
        laws = [self._contact, *self._pair_contacts.values()]
        return any(law is not None and law.pair_law == "surface" for law in laws)

    def _set_contact_laws(self, core: _core.Simulation, materials: list[Material]) -> None:
        """Laws for every pair of materials and every (wall, material)."""
        for a, material_a in enumerate(materials):
            for b, material_b in enumerate(materials[: a + 1]):
                contact = self._pair_contacts.get((id(material_a), id(material_b)), self._contact)
                if contact is not None:
                    core.set_contact_law(a, b, self._law(contact))
        for name, wall in self._walls:
            index = core.add_wall(wall.core(name, self.dimension))
            contact = wall.contact or self._contact or Contact()
            for a in range(len(materials)):
                core.set_wall_law(index, a, self._law(contact))
        if self._skin is not None:
            core.set_contact_skin(self._skin)

    @property
    def core(self) -> _core.Simulation:
        """The C++ simulation (built on first access)."""
        return self._build()

    @property
    def model(self) -> _core.Model:
        """The frozen C++ model: nodes, particles, materials, bonds (built on first access)."""
        self._build()
        assert self._model is not None
        return self._model

    @property
    def dt(self) -> float:
        """Time step [s]."""
        return self._build().time_step

    @dt.setter
    def dt(self, value: float) -> None:
        self._dt = self._check_dt(value)
        if self._core is not None:
            if self._dt > self._core.stable_time_step:
                warnings.warn(
                    f"time step {self._dt:.4g} s exceeds the stable estimate "
                    f"{self._core.stable_time_step:.4g} s; the run may become unstable",
                    GranulateWarning,
                    stacklevel=2,
                )
            self._core.time_step = self._dt

    @property
    def stable_dt(self) -> float:
        """Stable time-step estimate [s] (Silling & Askari's bound, see Model::stable_time_step)."""
        return self._build().stable_time_step

    def run(
        self,
        steps: int | None = None,
        *,
        until: float | None = None,
        stop: Sequence[StopCriterion] = (),
        check_every: int = 100,
        progress: Callable[[Progress], None] | bool | None = None,
        write_final: bool = True,
    ) -> str | None:
        """Advance ``steps`` time steps, or until simulated time ``until`` [s].

        Writes outputs at step 0 and every ``output(every=...)`` steps, and checkpoints as set
        by ``checkpoint_every``. ``stop`` criteria (granulate.stopping) are checked every
        ``check_every`` steps; the run ends at the first one met and its reason is returned
        (None when the run reached its last step). ``progress=True`` shows a progress bar (a
        terminal or a Jupyter notebook; lines in a log); a callable is called with a Progress
        after each chunk of steps (about every half second). Raises InstabilityError if the
        integration blows up.

        Ctrl-C or SIGTERM during a run finishes the current chunk, writes a checkpoint (when
        checkpoints or outputs are set) and raises KeyboardInterrupt; outputs stay intact.

        When the run ends (its last step or a stop criterion) between output steps, the frame
        and history row of its last step are written too (``write_final=False`` skips them at
        the last step, for a run advanced in pieces; a stop criterion met always writes them),
        and run.json is brought up to date.
        """
        core = self._build()
        steps = self._run_steps(core, steps, until, check_every)
        self._require_checkpoint_budget(steps)
        if not (progress is None or isinstance(progress, bool) or callable(progress)):
            raise InputError(
                f"progress must be True, False or a function of a Progress, got {progress!r}"
            )
        callback = None if isinstance(progress, bool) else progress
        plan = RunPlan(steps, tuple(stop), check_every, callback, write_final)
        if progress is not True:
            return run_loop.run_in_folder(self, plan)
        from granulate.progress import ProgressReporter

        reporter = ProgressReporter(steps)
        try:
            return run_loop.run_in_folder(self, replace(plan, progress=reporter))
        finally:
            reporter.close()

    def _run_steps(
        self, core: _core.Simulation, steps: int | None, until: float | None, check_every: int
    ) -> int:
        """The number of steps a run(steps, until=...) takes; InputError for bad arguments or a
        time step far above the stable estimate."""
        self.validate_time_step()
        if (steps is None) == (until is None):
            raise InputError("give either steps or until")
        if steps is not None:
            check_number("run: steps", steps, integer=True)
        if until is not None:
            check_number("run: until", until)
            if not np.isfinite(until):
                raise InputError(f"until must be a finite time, got {until}")
            steps = max(0, int(np.ceil((until - core.time) / core.time_step - 1e-9)))
        assert steps is not None
        if steps < 0:
            raise InputError(f"steps must be non-negative, got {steps}")
        if not (isinstance(check_every, int) and check_every > 0):
            raise InputError(f"check_every must be a positive number of steps, got {check_every}")
        return int(steps)

    def _translated_copies(self, outer_layers: bool) -> dict[int, int]:
        """Bodies without a reference shape that are translated copies of an earlier one
        (shape_sharing.py): body index -> the earlier body's index. They share its core shape
        and bond family."""
        copies, copy_of = TranslatedShapes(), {}
        for body, positions, volumes, surface in zip(
            self.bodies, self._positions, self._volumes, self._surfaces, strict=True
        ):
            if body.reference is not None:
                continue
            surface_arrays = _surface_arrays(surface, outer_layers)
            original = copies.find(positions, volumes, body.mesh_size, surface_arrays)
            if original is None:
                copies.remember(body.index, positions, volumes, body.mesh_size, surface_arrays)
            else:
                copy_of[body.index] = original
        return copy_of

    def _require_memory_for_model(self, copy_of: Mapping[int, int]) -> None:
        """InputError before the bonds are built when the model would not fit in memory:
        every node's state, and one bond family per reference shape and horizon ratio
        (particles placed from one shape share it) or per body not a translated copy of an
        earlier one (`copy_of`)."""
        families: dict[tuple[int, float], float] = {}
        for body in self.bodies:
            ratio = body.material.resolved_horizon(body.mesh_size) / body.mesh_size
            self._check_material_for(body, ratio * body.mesh_size)
            own = -1 - copy_of.get(body.index, body.index)
            key = (id(body.reference) if body.reference is not None else own, ratio)
            family = body.node_count * resources.bonds_per_node(self.dimension, ratio)
            families[key] = family
        nodes, bonds = float(self.node_count), float(sum(families.values()))
        resources.require_memory(
            resources.simulation_bytes(nodes, bonds),
            f"the model ({nodes:,.0f} nodes, about {bonds:,.0f} bonds)",
            "use fewer or coarser particles, or a smaller horizon_factor",
        )

    #: The most horizon / mesh size accepted: peridynamic horizons are 3-4 mesh sizes; at 20
    #: a node has about 1,300 bonds in 2D and 34,000 in 3D.
    MOST_HORIZON_FACTOR = 20.0

    def _check_material_for(self, body: Body, horizon: float) -> None:
        """InputError for a material a body cannot use as given: a horizon far beyond its mesh
        size (an absolute horizon in the wrong unit bonds every node to every other), or PMB
        with a Poisson ratio it cannot have (1/4; 1/3 in plane stress)."""
        ratio = horizon / body.mesh_size
        if ratio > self.MOST_HORIZON_FACTOR:
            raise InputError(
                f"body {body.name!r}: the horizon {horizon:.4g} m is {ratio:.0f} times its mesh "
                f"size {body.mesh_size:.4g} m (at most {self.MOST_HORIZON_FACTOR:.0f}; usually "
                "3-4): give horizon_factor, or the horizon in metres"
            )
        material = body.material
        if material.model != "pmb":
            return
        K, G = material.elastic_moduli()
        nu = (3 * K - 2 * G) / (2 * (3 * K + G))
        allowed = 1 / 3 if (self.dimension == 2 and self.plane == "stress") else 0.25
        if abs(nu - allowed) > 1e-3:
            raise InputError(
                f"body {body.name!r}: model 'pmb' has Poisson ratio {allowed:.4g} here, but the "
                f"material's constants give {nu:.4g}; use model 'lps', or constants with "
                f"poisson_ratio {allowed:.4g}"
            )

    def _thread_tuner(self, most: int) -> threads.ThreadTuner | None:
        """The run's thread-count picker (kept across runs of this simulation), or None when
        the thread count is the user's or there is one CPU (granulate.threads)."""
        if not threads.is_adaptive() or most == 1:
            return None
        if self._tuner is None or max(self._tuner.counts) != most:
            self._tuner = threads.ThreadTuner(most)
        return self._tuner

    def _warn_deep_contact(self, core: _core.Simulation) -> None:
        """Warn once when node pairs of two bodies came within half their contact distance
        into each other: the contact layer is too soft for the impact or the load, and nodes
        may pass through each other (an impact's overlap falls as 1 / sqrt(stiffness_factor),
        a steady load's as 1 / stiffness_factor)."""
        deepest = core.contact_statistics.deepest_overlap
        if self._deep_contact_warned or deepest < 0.5:
            return
        self._deep_contact_warned = True
        warnings.warn(
            f"contact: node pairs overlapped by {deepest:.0%} of their contact radius (by step "
            f"{core.step}); the contact layer is too soft for these impacts or loads and nodes "
            "may pass through each other. Raise Contact(stiffness_factor=...): an impact's "
            "overlap falls as 1/sqrt of it (10 keeps a 10 m/s impact of soft grains to a fifth), "
            "a steady load's as 1/its value; a stiffer contact shortens the time step",
            GranulateWarning,
            stacklevel=3,
        )

    def __repr__(self) -> str:
        """What the simulation holds and where it stands, without building it."""
        parts = [f"{self.dimension}D", f"{len(self.bodies)} bodies", f"{self.node_count:,} nodes"]
        if self._core is None:
            parts.append("not built yet (built by the first run)")
        else:
            core = self._core
            parts += [
                f"{self.bond_count:,} bonds",
                f"step {core.step:,}",
                f"t = {core.time:.6g} s",
                f"dt = {core.time_step:.4g} s",
            ]
        if self._walls:
            parts.append(f"walls: {', '.join(name for name, _ in self._walls)}")
        if self._output is not None:
            parts.append(f"output: {self._output.directory} every {self._output.every} steps")
        return f"Simulation({'; '.join(parts)})"

    @property
    def output_directory(self) -> Path | None:
        """Where output(...) writes, or None."""
        return None if self._output is None else self._output.directory

    @property
    def checkpoint_path(self) -> Path | None:
        """Where checkpoint_every(...) writes, or None."""
        return None if self._checkpoint is None else self._checkpoint.path

    def validate_time_step(self, tolerance: float = 5.0) -> None:
        """InputError if the time step exceeds ``tolerance`` times the stable estimate (a run
        would blow up); the case runner calls it before running."""
        core = self._build()
        if core.time_step > tolerance * core.stable_time_step:
            raise InputError(
                f"time step {core.time_step:.4g} s is {core.time_step / core.stable_time_step:.1f} "
                f"times the stable estimate {core.stable_time_step:.4g} s; use at most the "
                "estimate (or leave dt out: the default is 0.8 times it)"
            )

    # ------------------------------------------------------------------ checkpoints
    def checkpoint_every(
        self,
        steps: int | None = None,
        *,
        minutes: float | None = None,
        path: str | Path | None = None,
    ) -> None:
        """Write a checkpoint every ``steps`` steps and/or every ``minutes`` of wall time, and on
        Ctrl-C/SIGTERM, to ``path`` (default: ``checkpoint.npz`` in the output directory). Each
        checkpoint replaces the last one atomically."""
        if steps is not None and not (isinstance(steps, int) and steps > 0):
            raise InputError(f"checkpoint interval must be a positive number of steps, got {steps}")
        if minutes is not None and not (np.isfinite(minutes) and minutes > 0):
            raise InputError(
                f"checkpoint interval must be a positive number of minutes, got {minutes}"
            )
        if path is None:
            if self._output is None:
                raise InputError("give a checkpoint path, or set output(...) first")
            path = self._output.directory / "checkpoint.npz"
        self._checkpoint = CheckpointPlan(
            Path(path), steps, None if minutes is None else 60.0 * minutes, wallclock.perf_counter()
        )

    def _require_checkpoint_budget(self, steps: int) -> None:
        if self._checkpoint is not None:
            self._checkpoint.require_budget(steps, self.node_count, self.bond_count)

    def _checkpoint_if_due(self) -> None:
        if self._checkpoint is not None:
            self._checkpoint.save_if_due(self)

    def _save_on_interrupt(self) -> Path | None:
        if self._checkpoint is not None:
            path = self._checkpoint.path
        elif self._output is not None:
            path = self._output.directory / "checkpoint.npz"
        else:
            return None
        self.save_checkpoint(path)
        return path

    def fingerprint(self) -> str:
        """Identifies the set-up a checkpoint belongs to: nodes, volumes, bonds, loading,
        walls, contact (frozen once built: hashed once), time step, body force, damping and
        ``case_fingerprint``. Materials are named by their order, not by object identity, so
        the fingerprint is the same in every process."""
        core = self._build()
        if self._setup_digest is None:
            model = self.model
            loads = []
            for kind, args in self._loads:
                loads.append(kind)
                for a in args:
                    loads.append(np.asarray(a).tobytes() if isinstance(a, np.ndarray) else repr(a))
            order = {id(m): k for k, m in enumerate(self._core_materials)}
            pairs = sorted(
                (order[a], order[b], repr(contact))
                for (a, b), contact in self._pair_contacts.items()
                if a in order and b in order
            )
            self._setup_digest = checkpoint_file.fingerprint(
                np.ascontiguousarray(model.reference_positions).tobytes(),
                np.ascontiguousarray(model.volumes).tobytes(),
                np.ascontiguousarray(model.bond_offsets).tobytes(),
                *loads,
                repr(self._walls),
                repr(self._contact),
                repr(pairs),
                repr(
                    sorted(
                        (order[a], order[b], setting)
                        for (a, b), setting in self._peridem_damping.items()
                        if a in order and b in order
                    )
                ),
                repr(sorted(self._body(b).index for b in self._peridem_walls)),
            )
        return checkpoint_file.fingerprint(
            self._setup_digest,
            float(core.time_step),
            repr(self.gravity.tolist()),
            self._viscous_damping,
            self.case_fingerprint,
        )

    def save_checkpoint(self, path: str | Path) -> Path:
        """Write the state (positions, velocities, forces, bond states, contact history, time,
        step) and the output bookkeeping to ``path`` atomically (granulate.checkpoints)."""
        return checkpoints.save(self, path)

    def load_checkpoint(self, path: str | Path) -> None:
        """Continue from a checkpoint of this same set-up (else InputError): restores the state
        and, when outputs are set, the frame count, the PVD series and history.csv up to the
        checkpoint's step, so that the outputs that follow are those of an uninterrupted run."""
        checkpoints.load(self, path)

    # ------------------------------------------------------------------ results
    @property
    def positions(self) -> NDArray[np.float64]:
        """(n, 3) current positions x [m]: a live, writable view. Writing moves nodes before
        or between runs (bonds stretch accordingly; contact lists follow); the forces are
        recomputed at the next step."""
        return self._build().positions

    @property
    def velocities(self) -> NDArray[np.float64]:
        """(n, 3) velocities v [m/s]: a live, writable view (set initial or changed velocities
        before or between runs; prescribed nodes keep their prescribed motion)."""
        return self._build().velocities

    @property
    def forces(self) -> NDArray[np.float64]:
        """(n, 3) net force densities f [N/m^3] of the last step: a live, read-only view (the
        next step starts from them)."""
        return _read_only(self._build().forces)

    @property
    def displacements(self) -> NDArray[np.float64]:
        """(n, 3) displacements x - X [m] (a copy)."""
        core = self._build()
        return core.positions - self._reference

    @property
    def volumes(self) -> NDArray[np.float64]:
        """(n,) nodal volumes [m^3; m^2 in 2D], read-only."""
        self._build()
        assert self._model is not None
        return _read_only(self._model.volumes)

    @property
    def damage(self) -> NDArray[np.float64]:
        """(n,) damage phi = 1 - intact / initial influence-weighted volume of the bonds."""
        return self._build().damage()[0]

    @property
    def damage_z(self) -> NDArray[np.float64]:
        """(n,) PeriDEM's Damage_Z: max over a node's bonds of |stretch| / s0."""
        return self._build().damage()[1]

    @property
    def time(self) -> float:
        return self._build().time

    @property
    def step(self) -> int:
        return self._build().step

    def kinetic_energy(self) -> float:
        """sum 1/2 rho V |v|^2 [J; J/m in 2D]."""
        return self._build().kinetic_energy()

    def strain_energy(self) -> float:
        """sum W_i V_i over intact bonds [J; J/m in 2D]."""
        return self._build().strain_energy()

    def broken_bonds(self) -> int:
        """Number of broken bonds, each counted once."""
        return self._build().broken_bonds()

    def wall_displacement(self, name: str) -> float:
        """Distance the named wall has moved (translation) or angle it has turned [m or rad]."""
        core = self._build()
        for (label, _), wall in zip(self._walls, core.walls, strict=True):
            if label == name:
                return float(wall.displacement(core.time))
        names = ", ".join(label for label, _ in self._walls) or "none"
        raise InputError(f"no wall named {name!r}; walls: {names}")

    def fully_broken_particles(self) -> int:
        """Number of particles none of whose bonds is intact (with at least one bond)."""
        model = self.model
        intact = np.asarray(self._build().bond_intact)
        offsets = np.asarray(model.bond_offsets)
        count = 0
        for body in self.bodies:
            begin, end = offsets[body.first_node], offsets[body.first_node + body.node_count]
            if end > begin and not intact[begin:end].any():
                count += 1
        return count

    def precrack(
        self, point: ArrayLike, normal: ArrayLike, *, region: Shape | None = None
    ) -> int | None:
        """Break the bonds that cross the plane through ``point`` with ``normal`` (in the reference
        configuration), only those whose midpoint lies in ``region`` if given: a pre-crack or a
        notch without removing material. Before the simulation is built (the first run, or the
        first look at its state) the pre-crack is kept and applied when it is, and None is
        returned, so contact, walls and loading can still be set; after, the bonds break at
        once and their number is returned."""
        crack = (self._vector(point, "point"), self._vector(normal, "normal"), region)
        if region is not None and not isinstance(region, Shape):
            raise InputError(f"precrack: region must be a shape, got {type(region).__name__}")
        if self._core is None:
            self._precracks.append(crack)
            return None
        return self._break_crossing_bonds(*crack)

    def _break_crossing_bonds(
        self, point: NDArray[np.float64], normal: NDArray[np.float64], region: Shape | None
    ) -> int:
        core = self._build()
        assert self._model is not None
        X = self._model.reference_positions
        side = (X - point) @ normal
        offsets = self._model.bond_offsets
        owner = np.repeat(
            np.arange(len(offsets) - 1, dtype=np.uint32), np.diff(offsets).astype(np.int64)
        )
        neighbor = self._model.bond_neighbors()
        crossing = (side[owner] < 0) & (side[neighbor] >= 0)
        if region is not None:
            crossing &= region.contains(0.5 * (X[owner] + X[neighbor]))
        pairs = np.ascontiguousarray(
            np.column_stack([owner[crossing], neighbor[crossing]]), dtype=np.uint32
        )
        before = core.broken_bonds()
        core.break_bonds(pairs)
        return core.broken_bonds() - before

    def fragments(self, min_nodes: int = 1) -> list[NDArray[np.uint32]]:
        """Pieces held together by intact bonds, largest first, each as its node indices.

        Fragments smaller than ``min_nodes`` (dust, single detached nodes) are left out.
        """
        labels = self._fragment_labels()
        order = np.argsort(labels, kind="stable")
        _roots, starts, counts = np.unique(labels[order], return_index=True, return_counts=True)
        pieces = [
            order[s : s + c].astype(np.uint32)
            for s, c in zip(starts, counts, strict=True)
            if c >= min_nodes
        ]
        return sorted(pieces, key=lambda piece: (-len(piece), int(piece[0])))

    def gravity_energy(self) -> float:
        """Potential energy in the gravity field, -sum m_i g . x_i [J; J/m in 2D] (zero at the
        origin)."""
        model = self.model
        mass = np.asarray(model.node_density) * np.asarray(model.volumes)
        moment = reductions.weighted_sum(mass, self._build().positions)  # sum_i m_i x_i
        return -reductions.dot(moment, self._gravity)

    def _fragment_labels(self) -> NDArray[np.uint32]:
        """Each node's piece: its smallest node (computed once per step and bond count)."""
        core = self._build()
        key = (int(core.step), int(core.broken_bonds()))
        if self._labels is None or self._labels[0] != key:
            self._labels = (key, core.fragments())
        return self._labels[1]

    def fragment_table(self) -> fragments.Table:
        """One row per fragment (debris included, flagged) of the current state: its id,
        parent particle, nodes, mass, volume, centre of mass, velocity and equivalent diameter
        (granulate.fragments; ``pandas.DataFrame(table)`` makes it a data frame)."""
        core, model = self._build(), self.model
        return fragments.fragment_table(
            self._fragment_labels(),
            model.node_particle,
            core.positions,
            core.velocities,
            model.volumes,
            model.node_density,
            self.dimension,
        )

    @property
    def node_count(self) -> int:
        last = self.bodies[-1] if self.bodies else None
        return last.first_node + last.node_count if last is not None else 0

    @property
    def bond_count(self) -> int:
        """Bonds, each counted once per end (as LAMMPS counts them)."""
        self._build()
        assert self._model is not None
        return self._model.bond_count

    def summary(self) -> dict[str, float | int]:
        """Counts, time step and timings of the run so far: ``steps`` is the current step,
        ``steps_run`` and ``wall_seconds`` the steps advanced and the wall time taken by this
        process's runs (after a resume, only the resumed part)."""
        core = self._build()
        phases = core.phase_times
        return {
            "granulate": __version__,
            "case_fingerprint": self.case_fingerprint,
            "dimension": self.dimension,
            "bodies": len(self.bodies),
            "nodes": self.node_count,
            "bonds": self.bond_count,
            "dt": core.time_step,
            "stable_dt": core.stable_time_step,
            "steps": core.step,
            "time": core.time,
            "threads": threads.get_num_threads(),
            "threads_in_use": self._tuner.current if self._tuner is not None else None,
            "status": self._record.status,
            "steps_run": self._record.steps_run,
            "wall_seconds": self._record.wall_seconds,
            "peridynamics_seconds": phases.peridynamics,
            "integration_seconds": phases.integration,
            "loading_seconds": phases.loading,
            "contact_seconds": phases.contact,
            "neighbor_list_rebuilds": core.contact_statistics.rebuilds,
        }

    def particle_table(
        self, contacts: network.Table | None = None, damage: ArrayLike | None = None
    ) -> particle_table.Table:
        """One row per particle of the current state (granulate.particle_table): time, centre
        of mass [m], velocity [m/s], angular velocity [rad/s], mass [kg; kg/m in 2D], radius
        of gyration [m], volume-weighted mean damage, coordination and Love-Weber stress [Pa]
        (granulate.network), from `contacts` (default: ``contact_table()``)."""
        contacts = self.contact_table() if contacts is None else contacts
        return self._particles(contacts, damage)[0]

    def _particles(
        self, contacts: network.Table, damage: ArrayLike | None
    ) -> tuple[particle_table.Table, NDArray, NDArray]:
        """The particle table, the particles' Love-Weber stresses (N, D, D) [Pa] and their
        volumes [m^3; m^2 in 2D]: what a frame's table and a history row both need."""
        core, count = self._build(), len(self.bodies)
        owner, volumes, table = self._particle_motion()
        phi = core.damage()[0] if damage is None else np.asarray(damage)
        particle_volume = np.bincount(owner, volumes, count)
        table["particle"] = np.arange(count)
        table["time"] = np.full(count, float(core.time))
        table["damage"] = np.bincount(owner, volumes * phi, count) / particle_volume
        table["coordination"] = network.coordination(contacts, count)
        centres = np.column_stack([table[axis] for axis in "xyz"])
        stresses = network.love_weber_stresses(contacts, centres, particle_volume, self.dimension)
        particle_table.add_stresses(table, stresses, self.dimension)
        return table, stresses, particle_volume

    def _particle_motion(self) -> tuple[NDArray, NDArray, particle_table.Table]:
        """Each node's particle, each node's volume, and the particles' motion columns
        (granulate.particle_table.motion)."""
        model, core = self.model, self._build()
        owner, volumes = np.asarray(model.node_particle), np.asarray(model.volumes)
        mass = np.asarray(model.node_density) * volumes
        motion = particle_table.motion(
            owner, mass, core.positions, core.velocities, len(self.bodies)
        )
        return owner, volumes, motion

    def contact_table(self) -> network.Table:
        """One row per contact of the last force evaluation (pairs of particles or of their
        fragments, and particles on walls): the bodies, contact point [m], normal, force on
        the first body [N; N/m in 2D], normal and tangential force (granulate.network; wall
        k is ``list(sim.wall_reactions())[k]``)."""
        return network.contact_table(self._build().contact_network())

    def particle_stresses(
        self,
        method: Literal["contacts", "bonds"] = "contacts",
        contacts: network.Table | None = None,
    ) -> NDArray:
        """Each particle's mean stress, (particles, D, D) [Pa; tension positive]: Love-Weber
        from its contacts (`contacts`: the current contact table, made when not given), or from
        its bond forces (granulate.network; the two agree for a particle at rest)."""
        core, count = self._build(), len(self.bodies)
        owner, volumes, table = self._particle_motion()
        centres = np.column_stack([table[axis] for axis in "xyz"])
        if method == "contacts":
            network_table = self.contact_table() if contacts is None else contacts
            return network.love_weber_stresses(
                network_table, centres, np.bincount(owner, volumes, count), self.dimension
            )
        if method == "bonds":
            bonds = np.asarray(core.bond_force_densities()).reshape(-1, 3)
            return network.internal_stresses(
                bonds, core.positions, volumes, owner, centres, self.dimension
            )
        raise InputError(f"particle_stresses: method must be 'contacts' or 'bonds', got {method!r}")

    @property
    def output_seconds(self) -> float:
        """Wall-clock seconds spent writing outputs so far."""
        return self._output_seconds

    def _write_output(self) -> None:
        """The frame and history row the current step writes (Outputs.write_step), timed."""
        assert self._output is not None
        start = wallclock.perf_counter()
        try:
            self._output.write_step(self)
        finally:
            self._output_seconds += wallclock.perf_counter() - start

    def _write_final_state(self, frame: bool) -> None:
        """The end of a run: with ``frame``, the frame and history row of the last step when
        it was not an output step (run() then writes run.json with the run's status)."""
        assert self._output is not None
        start = wallclock.perf_counter()
        try:
            self._output.write_final(self, frame)
        finally:
            self._output_seconds += wallclock.perf_counter() - start


def _track_areas(areas: Mapping[str, float], tracked: tuple[Body, ...]) -> dict[str, float]:
    """``Simulation.output``'s track_areas, checked: tracked bodies' names, positive areas."""
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


def _surface_arrays(
    reference: ReferenceShape | None, outer_layers: bool
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A shape's surface offsets (flat, 3 per node) and depths for the core; empty arrays where
    it has none (all depths 0: empty too). With ``outer_layers`` (the surface law) a lattice's
    or conforming discretisation's outer layer, which only that law uses."""
    if reference is None:
        return np.zeros(0), np.zeros(0)
    layer = reference.outer_layer_of if outer_layers else None
    if layer is not None:
        return np.ascontiguousarray(layer[0]).reshape(-1), np.ascontiguousarray(layer[1])
    if reference.surface is None:
        return np.zeros(0), np.zeros(0)
    return np.ascontiguousarray(reference.surface, dtype=np.float64).reshape(-1), np.zeros(0)
