"""Simulation's set-up calls: bodies, particles, packings and selections, loading, gravity and
damping, contact and walls, outputs.

Each call is checked here and handed to its room (granulate.assembly, granulate.loading,
granulate.interactions, granulate.writers.outputs); nothing is added once the core is built.
``SimulationSetup`` is a part of ``granulate.Simulation``, not a class to use alone: it reads the
rooms Simulation.__init__ makes and calls Simulation._build.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from granulate import _core, assembly
from granulate.analysis import read_only
from granulate.assembly import Assembly, Body
from granulate.contact import Contact
from granulate.errors import InputError
from granulate.evaluation import Evaluation
from granulate.functions import TimeFunction
from granulate.input_errors import check_number
from granulate.interactions import Interactions
from granulate.load_balance import LoadBalance
from granulate.loading import Components, Loading
from granulate.materials import Material
from granulate.packing import Grain, Packing, Placements
from granulate.reference_shapes import ReferenceShape
from granulate.shapes import Shape
from granulate.walls import Surface, Wall
from granulate.writers.outputs import Outputs
from granulate.writers.vtu_frame import FIELDS


class SimulationSetup:
    """The set-up half of Simulation's API (see granulate.simulation.Simulation)."""

    # What Simulation provides (made in its __init__ and _build).
    dimension: int
    _assembly: Assembly
    _loading: Loading
    _interactions: Interactions
    _core: _core.Simulation | None
    _model: _core.Model | None
    _gravity: NDArray[np.float64]
    _viscous_damping: float
    _load_balance: LoadBalance
    _output: Outputs | None
    _output_path: Path | None
    _comm: Any
    _distributed: Any  # granulate.parallel.DistributedRun, once a distributed run is made
    _start: tuple[NDArray[np.float64], NDArray[np.float64]] | None
    _start_step: int
    _build: Callable[[], _core.Simulation]
    _gathered: Evaluation | None

    @property
    def bodies(self) -> list[Body]:
        """The bodies added, in order (each one's nodes follow the last one's)."""
        return self._assembly.bodies

    @property
    def packings(self) -> list[Packing]:
        """The packings added with add_packing (for summaries)."""
        return self._assembly.packings

    def _require_building(self, what: str) -> None:
        if self._core is not None or self._distributed is not None:
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
        self._require_building("add a body")
        return self._assembly.add_body(
            shape,
            material,
            mesh_size,
            discretization=discretization,
            jitter=jitter,
            seed=seed,
            velocity=velocity,
            angular_velocity=angular_velocity,
            name=name,
        )

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
        self._require_building("add a body")
        return self._assembly.add_particle(
            reference,
            material,
            position=position,
            rotation=rotation,
            scale=scale,
            velocity=velocity,
            angular_velocity=angular_velocity,
            name=name,
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
        self._require_building("add a body")
        return self._assembly.add_placements(placements, grains, velocity)

    def add_packing(self, packing: Packing, *, velocity: ArrayLike | None = None) -> list[Body]:
        """Add the particles of a generated packing (``granulate.pack``)."""
        self._require_building("add a body")
        return self._assembly.add_packing(packing, velocity)

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
        core = self._build()
        return assembly.placements_now(bodies, placements, self.model, core.positions)

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
        return self._assembly.add_body_from_nodes(
            positions,
            volumes,
            material,
            mesh_size,
            velocity=velocity,
            angular_velocity=angular_velocity,
            name=name,
        )

    @property
    def reference_positions(self) -> NDArray[np.float64]:
        """(n, 3) reference positions X of all nodes [m], read-only."""
        if self._model is not None:
            return read_only(self._model.reference_positions)
        return self._assembly.reference_positions()

    def start_from(self, positions: ArrayLike, velocities: ArrayLike, step: int = 0) -> None:
        """Start from these node positions x [m] and velocities v [m/s] ((n, 3) each, in node
        order) instead of the reference positions at rest, as a restart from another run's
        frame does, at `step` (time step x dt). The start checks (a node on the wrong side of a
        wall, particles overlapping) judge these positions; the bonds start intact (but for
        precracks) and loaded nodes keep their prescribed motion. Call it before the first
        run."""
        self._require_building("set the start positions")
        check_number("start_from: step", step, integer=True)
        if step < 0:
            raise InputError(f"start_from: step must be non-negative, got {step}")
        shape = (self._assembly.node_count, 3)
        x = np.array(positions, dtype=np.float64)
        v = np.array(velocities, dtype=np.float64)
        for name, value in (("positions", x), ("velocities", v)):
            if value.shape != shape:
                raise InputError(
                    f"start_from: {name} must be {shape[0]} x 3 (one row per node), got "
                    f"{' x '.join(map(str, value.shape))}"
                )
            if not np.all(np.isfinite(value)):
                raise InputError(f"start_from: {name} must be finite")
        self._start = (x, v)
        self._start_step = int(step)

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
        positions = self.reference_positions if region is not None else np.zeros((0, 3))
        return self._assembly.select(positions, region, body, ids)

    def fix(self, nodes: ArrayLike, components: Components = "xyz") -> None:
        """Hold the given components of the nodes at their reference position."""
        self._require_building("add loading")
        self._loading.fix(nodes, components)

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
        self._require_building("add loading")
        self._loading.prescribe_displacement(nodes, direction, function, components)

    def prescribe_velocity(
        self,
        nodes: ArrayLike,
        velocity: ArrayLike,
        *,
        ramp_time: float = 0.0,
        components: Components | None = None,
    ) -> None:
        """Move nodes at a constant velocity [m/s], reached smoothly over ``ramp_time`` [s]."""
        self._require_building("add loading")
        self._loading.prescribe_velocity(nodes, velocity, ramp_time, components)

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
        self._loading.prescribe_rotation(nodes, center, angle, axis)

    def add_force_density(
        self, nodes: ArrayLike, vector: ArrayLike, function: TimeFunction | None = None
    ) -> None:
        """Add f(t) * vector [N/m^3, also in 2D] to the force density of the nodes."""
        self._require_building("add loading")
        self._loading.add_force_density(nodes, vector, function)

    @property
    def gravity(self) -> NDArray[np.float64]:
        """Body acceleration g [m/s^2] (adds rho g to every node)."""
        return self._gravity.copy()

    @gravity.setter
    def gravity(self, value: ArrayLike) -> None:
        if self._distributed is not None:
            self._require_building("change gravity in a distributed run")
        self._gravity = self._assembly.vector(value, "gravity")
        if self._core is not None:
            self._core.set_body_acceleration(tuple(self._gravity))

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
    def load_balance(self) -> LoadBalance:
        """When the ranks of a distributed run (``comm``) compare their work and cut the grains
        anew (granulate.LoadBalance; default every 100 steps, past 1.1 times the mean). It
        changes a run's speed, never its results; a serial run ignores it. It may be changed
        between runs."""
        return self._load_balance

    @load_balance.setter
    def load_balance(self, value: LoadBalance) -> None:
        if not isinstance(value, LoadBalance):
            raise InputError(
                f"load_balance must be a granulate.LoadBalance(every=..., threshold=...), "
                f"got {value!r}"
            )
        self._load_balance = value

    @property
    def contact(self) -> Contact | None:
        """Contact between all particles (and fragments) unless set per pair; None: no contact."""
        return self._interactions.contact

    @contact.setter
    def contact(self, value: Contact | None) -> None:
        self._require_building("change contact")
        self._interactions.set_default(value)

    def set_contact(self, a: Material, b: Material, contact: Contact | None) -> None:
        """Contact between bodies of materials a and b (None: they pass through each other)."""
        self._require_building("change contact")
        self._interactions.set_pair(a, b, contact)

    def set_peridem_damping(
        self, a: Material, b: Material, *, epsilon: float, beta_factor: float = 1.0
    ) -> None:
        """PeriDEM's contact damping between particles of materials a and b, for comparisons
        with PeriDEM only (``--peridem-compat``): it acts between particle centres and does not
        give the restitution ``epsilon`` names (formulas: contact/peridem_damping.hpp). The
        contact law of the pair should then have restitution 1, or both dampings act.
        ``beta_factor`` is PeriDEM's Beta_n_Factor."""
        self._require_building("change contact")
        self._interactions.set_peridem_damping(a, b, epsilon, beta_factor)

    def set_peridem_walls(self, bodies: Sequence[Body | str]) -> None:
        """The bodies PeriDEM's damping treats as walls (PeriDEM's Is_Wall zones): they damp
        particles through their nodes and are not damped themselves."""
        self._require_building("change contact")
        self._interactions.peridem_walls = list(bodies)

    def set_neighbor_skin(self, skin: float) -> None:
        """Verlet skin of the contact neighbour lists [m] (default: half the contact radius)."""
        if self._distributed is not None:
            self._require_building("change the skin in a distributed run")
        self._interactions.set_skin(skin)
        if self._core is not None:
            self._core.set_contact_skin(skin)

    def add_wall(self, wall: Wall | Surface, *, name: str | None = None) -> str:
        """Add a rigid wall (or one fixed surface); returns its name, used in history.csv."""
        self._require_building("add a wall")
        return self._interactions.add_wall(wall, name, self.dimension)

    @property
    def walls(self) -> tuple[tuple[str, Wall], ...]:
        """The walls added, in order, with their names (history.csv's <name>_fx, ...)."""
        return tuple(self._interactions.walls)

    def wall_reactions(self) -> dict[str, NDArray[np.float64]]:
        """Per wall: (fx, fy, fz, tx, ty, tz), the force and torque the particles exert on it
        at the last step [N, N m; per unit thickness in 2D]."""
        names = self._interactions.wall_names
        if self._gathered is not None:  # a distributed run's, on rank 0
            return dict(zip(names, self._gathered.wall_reactions.copy(), strict=True))
        reactions = self._build().wall_reactions()
        return {name: np.asarray(r) for name, r in zip(names, reactions, strict=True)}

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
        pieces: bool = False,
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

        ``pieces``: each frame is ``frames/frame_NNNNNN.pvtu`` over pieces
        ``frames/frame_NNNNNN/piece_R.vtu``, one written by each rank of a distributed run (of
        the nodes of the grains it owns, with their numbers in the whole run, ``Node_ID``), one
        in a serial run, rather than one ``.vtu`` written by rank 0 from the whole state.
        ParaView opens the series as before; granulate.Results and ``restart:`` join the
        pieces in the nodes' order.

        A directory that already holds a run (simulation.pvd or frames) is refused unless
        ``overwrite`` is true (the old run is deleted when the new one starts writing, so an
        error found before leaves it intact) or ``resume`` is true (it is kept for
        ``load_checkpoint``, which must follow; temporaries of interrupted writes are removed).
        A file, or a directory you cannot write, is refused at once; while a run writes, the
        directory is locked (.granulate.lock) against a second run.
        """
        tracked = tuple(self._assembly.body(b) for b in track)

        def plan() -> Outputs:
            return Outputs.plan(
                Path(directory),
                every,
                history_every,
                fields,
                tracked,
                track_areas or {},
                self._interactions.wall_names,
                overwrite=overwrite,
                resume=resume,
                pieces=pieces,
            )

        if self._comm is None:
            self._output = plan()
        else:  # rank 0 writes; its folder's problems stop every rank
            from granulate.parallel.agreement import on_root

            self._output = on_root(self._comm, plan)
        self._output_path = Path(directory)
