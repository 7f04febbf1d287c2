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

import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from granulate import (
    _core,
    assembly,
    checkpoints,
    core_model,
    fragments,
    network,
    particle_table,
    run_loop,
    threads,
)
from granulate._version import __version__
from granulate.analysis import Analysis
from granulate.assembly import Assembly, Body
from granulate.checkpoints import CheckpointPlan
from granulate.contact import Contact
from granulate.errors import GranulateWarning, InputError
from granulate.functions import TimeFunction
from granulate.input_errors import check_number, unknown_name
from granulate.interactions import Interactions
from granulate.io import checkpoint as checkpoint_file
from granulate.loading import Components, Loading
from granulate.materials import Material
from granulate.packing import Grain, Packing, Placements
from granulate.reference_shapes import ReferenceShape
from granulate.run_loop import Progress, RunPlan, RunRecord
from granulate.shapes import Shape
from granulate.stopping import StopCriterion
from granulate.walls import Surface, Wall
from granulate.writers.outputs import Outputs
from granulate.writers.vtu_frame import FIELDS

__all__ = ["FIELDS", "Body", "Components", "Progress", "Simulation"]


def _read_only(array: NDArray) -> NDArray:
    """A view of `array` that cannot be written (the core keeps writing the original)."""
    view = array.view()
    view.flags.writeable = False
    return view


def _warn_above_stable(dt: float, stable: float, stacklevel: int) -> None:
    """A GranulateWarning when the time step dt exceeds the stable estimate [s]."""
    if dt > stable:
        warnings.warn(
            f"time step {dt:.4g} s exceeds the stable estimate {stable:.4g} s; the run may "
            "become unstable",
            GranulateWarning,
            stacklevel=stacklevel,
        )


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
        self._assembly = Assembly(dimension)
        self._loading = Loading(self._assembly)
        self._interactions = Interactions(self._assembly)
        self._output: Outputs | None = None
        self._core: _core.Simulation | None = None
        self._model: _core.Model | None = None
        self._analysis: Analysis | None = None
        self._reference: NDArray[np.float64] | None = None
        self._record = RunRecord()
        self._precracks: list[tuple[NDArray[np.float64], NDArray[np.float64], Shape | None]] = []
        self._tuner: threads.ThreadTuner | None = None
        self._core_materials: list[Material] = []
        self._setup_digest: str | None = None
        self._checkpoint: CheckpointPlan | None = None
        #: Extra text identifying the set-up (a case file's hash), checked by load_checkpoint.
        self.case_fingerprint = ""
        self.viscous_damping = viscous_damping
        if gravity is not None:
            self.gravity = gravity  # type: ignore[assignment]

    @property
    def bodies(self) -> list[Body]:
        """The bodies added, in order (each one's nodes follow the last one's)."""
        return self._assembly.bodies

    @property
    def packings(self) -> list[Packing]:
        """The packings added with add_packing (for summaries)."""
        return self._assembly.packings

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
            return _read_only(self._model.reference_positions)
        return self._assembly.reference_positions()

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
        self._gravity = self._assembly.vector(value, "gravity")
        if self._core is not None:
            self._core.set_body_acceleration(tuple(self._gravity))

    #: The attributes a user may set besides the properties with setters.
    _SETTABLE = ("dimension", "plane", "case_fingerprint")

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
        core = self._build()
        names = self._interactions.wall_names
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
        self._output = Outputs.plan(
            Path(directory),
            every,
            history_every,
            fields,
            tuple(self._assembly.body(b) for b in track),
            track_areas or {},
            self._interactions.wall_names,
            overwrite=overwrite,
            resume=resume,
        )

    # ------------------------------------------------------------------ the core
    def _build(self) -> _core.Simulation:
        """The core simulation, made on first use: the model (materials, shapes, particles,
        bonds), contact laws, walls and damping, the time step, loads, initial velocities,
        precracks."""
        if self._core is not None:
            return self._core
        if not self.bodies:
            raise InputError("the simulation has no body; add one with add_body")
        outer_layers = self._interactions.uses_surface_law()
        model, core_materials = core_model.build_model(self._assembly, self.plane, outer_layers)
        core = _core.Simulation(model)
        self._interactions.apply(core, core_materials)
        self._core_materials = core_materials
        self._interactions.check_start(model, core, self.dimension)
        self._set_time_step(core)
        core.set_body_acceleration(tuple(self._gravity))
        core.viscous_damping = self._viscous_damping
        self._loading.apply(core)
        self._assembly.set_initial_velocities(model, core)
        self._model = model
        self._core = core
        self._analysis = Analysis(core, model, len(self.bodies))
        self._reference = model.reference_positions
        for crack in self._precracks:
            core_model.break_crossing_bonds(core, model, *crack)
        return core

    def _set_time_step(self, core: _core.Simulation) -> None:
        """dt as given (warned above the stable estimate), or dt_safety times that estimate."""
        if self._dt is None:
            core.time_step = self._dt_safety * core.stable_time_step
            return
        _warn_above_stable(self._dt, core.stable_time_step, stacklevel=5)
        core.time_step = self._dt

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
            _warn_above_stable(self._dt, self._core.stable_time_step, stacklevel=3)
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
        self.validate_time_step()
        steps = run_loop.steps_to_run(self.core, steps, until, check_every)
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

    def _thread_tuner(self, most: int) -> threads.ThreadTuner | None:
        """The run's thread-count picker (kept across runs of this simulation), or None when
        the thread count is the user's or there is one CPU (granulate.threads)."""
        if not threads.is_adaptive() or most == 1:
            return None
        if self._tuner is None or max(self._tuner.counts) != most:
            self._tuner = threads.ThreadTuner(most)
        return self._tuner

    def _warn_deep_contact(self, core: _core.Simulation) -> None:
        """Warn once when contacts grow too deep for their law (Interactions)."""
        self._interactions.warn_deep_contact(core)

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
        if self._interactions.walls:
            parts.append(f"walls: {', '.join(self._interactions.wall_names)}")
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
        directory = None if self._output is None else self._output.directory
        self._checkpoint = CheckpointPlan.create(steps, minutes, path, directory)

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
            self._setup_digest = checkpoint_file.fingerprint(
                np.ascontiguousarray(model.reference_positions).tobytes(),
                np.ascontiguousarray(model.volumes).tobytes(),
                np.ascontiguousarray(model.bond_offsets).tobytes(),
                *self._loading.fingerprint_parts(),
                *self._interactions.fingerprint_parts(self._core_materials),
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
        names = self._interactions.wall_names
        for label, wall in zip(names, core.walls, strict=True):
            if label == name:
                return float(wall.displacement(core.time))
        raise InputError(f"no wall named {name!r}; walls: {', '.join(names) or 'none'}")

    def fully_broken_particles(self) -> int:
        """Number of particles none of whose bonds is intact (with at least one bond)."""
        return self.analysis.fully_broken_particles(self.bodies)

    def precrack(
        self, point: ArrayLike, normal: ArrayLike, *, region: Shape | None = None
    ) -> int | None:
        """Break the bonds that cross the plane through ``point`` with ``normal`` (in the reference
        configuration), only those whose midpoint lies in ``region`` if given: a pre-crack or a
        notch without removing material. Before the simulation is built (the first run, or the
        first look at its state) the pre-crack is kept and applied when it is, and None is
        returned, so contact, walls and loading can still be set; after, the bonds break at
        once and their number is returned."""
        vector = self._assembly.vector
        crack = (vector(point, "point"), vector(normal, "normal"), region)
        if region is not None and not isinstance(region, Shape):
            raise InputError(f"precrack: region must be a shape, got {type(region).__name__}")
        if self._core is None:
            self._precracks.append(crack)
            return None
        return core_model.break_crossing_bonds(self._core, self.model, *crack)

    def fragments(self, min_nodes: int = 1) -> list[NDArray[np.uint32]]:
        """Pieces held together by intact bonds, largest first, each as its node indices.

        Fragments smaller than ``min_nodes`` (dust, single detached nodes) are left out.
        """
        return self.analysis.fragments(min_nodes)

    def gravity_energy(self) -> float:
        """Potential energy in the gravity field, -sum m_i g . x_i [J; J/m in 2D] (zero at the
        origin)."""
        return self.analysis.gravity_energy(self._gravity)

    def fragment_table(self) -> fragments.Table:
        """One row per fragment (debris included, flagged) of the current state: its id,
        parent particle, nodes, mass, volume, centre of mass, velocity and equivalent diameter
        (granulate.fragments; ``pandas.DataFrame(table)`` makes it a data frame)."""
        return self.analysis.fragment_table()

    @property
    def analysis(self) -> Analysis:
        """The measures of the current state (granulate.analysis.Analysis), built on first
        access: fragments, the particle and contact tables, particle stresses."""
        self._build()
        assert self._analysis is not None
        return self._analysis

    @property
    def node_count(self) -> int:
        return self._assembly.node_count

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
        return self.analysis.particles(contacts, damage)[0]

    def contact_table(self) -> network.Table:
        """One row per contact of the last force evaluation (pairs of particles or of their
        fragments, and particles on walls): the bodies, contact point [m], normal, force on
        the first body [N; N/m in 2D], normal and tangential force (granulate.network; wall
        k is ``list(sim.wall_reactions())[k]``)."""
        return self.analysis.contact_table()

    def particle_stresses(
        self,
        method: Literal["contacts", "bonds"] = "contacts",
        contacts: network.Table | None = None,
    ) -> NDArray:
        """Each particle's mean stress, (particles, D, D) [Pa; tension positive]: Love-Weber
        from its contacts (`contacts`: the current contact table, made when not given), or from
        its bond forces (granulate.network; the two agree for a particle at rest)."""
        return self.analysis.particle_stresses(method, contacts)

    @property
    def output_seconds(self) -> float:
        """Wall-clock seconds spent writing outputs so far (by the current output(...))."""
        return 0.0 if self._output is None else self._output.seconds
