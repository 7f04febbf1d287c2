"""A validated case built into a Simulation: names and paths resolved, every section applied."""

from __future__ import annotations

import difflib
import hashlib
import json
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import BaseModel

from granulate import packing, shapes, stopping, walls
from granulate.case.particle_specs import _SIZES, make_function
from granulate.case.run_specs import (
    CaseSpec,
    DisplacementSpec,
    FixSpec,
    ForceDensitySpec,
    OutputSpec,
    RotationLoadSpec,
    RotationSpec,
    SelectSpec,
    SteadyRotationSpec,
    TranslationSpec,
    VelocitySpec,
    WallSpec,
)
from granulate.case.shape_specs import ShapeRef
from granulate.errors import InputError
from granulate.io.files import existing_file
from granulate.materials import Material
from granulate.reference_shapes import ReferenceShape
from granulate.simulation import Body, Simulation


@dataclass
class CaseContext:
    """Resolves names and paths while a case is built."""

    spec: CaseSpec
    folder: Path
    _shapes: dict[str, shapes.Shape] = field(default_factory=dict)
    _grains: dict[str, packing.Grain] = field(default_factory=dict)
    _resolving: list[str] = field(default_factory=list)  # named shapes being made

    def path(self, name: str) -> Path:
        """A file the case names, relative to the case file's folder."""
        try:
            return (self.folder / name).resolve()
        except (RuntimeError, OSError) as error:  # a loop of symbolic links, a bad name
            raise InputError(f"the file {name!r} cannot be resolved: {error}") from None

    def shape(self, ref: ShapeRef) -> shapes.Shape:  # type: ignore[valid-type]
        if isinstance(ref, str):
            if ref not in self.spec.shapes:
                raise InputError(f"unknown shape {ref!r}{_closest(ref, self.spec.shapes)}")
            if ref in self._resolving:  # a named shape made of itself, through others or not
                cycle = " -> ".join([*self._resolving[self._resolving.index(ref) :], ref])
                raise InputError(f"shapes refer to each other in a cycle: {cycle}")
            if ref not in self._shapes:
                self._resolving.append(ref)
                try:
                    self._shapes[ref] = self.spec.shapes[ref].make(self)  # type: ignore[union-attr]
                finally:
                    self._resolving.pop()
            return self._shapes[ref]
        return ref.make(self)  # type: ignore[union-attr]

    def material(self, name: str) -> Material:
        if name not in self.spec.materials:
            raise InputError(f"unknown material {name!r}{_closest(name, self.spec.materials)}")
        return self.spec.materials[name]

    def grain(self, name: str) -> packing.Grain:
        if name not in self.spec.grains:
            raise InputError(f"unknown grain {name!r}{_closest(name, self.spec.grains)}")
        if name not in self._grains:
            g = self.spec.grains[name]
            sizes = None
            if g.sizes is not None:
                values = g.sizes.model_dump()
                sizes = _SIZES[values.pop("distribution")](**values)
            if g.mesh is not None:
                source: shapes.Shape | ReferenceShape = ReferenceShape.from_mesh(
                    str(self.path(g.mesh.file)),
                    dimension=g.mesh.dimension,
                    mesh_size=g.mesh.mesh_size,
                    center=g.mesh.center,
                )
            else:
                source = self.shape(g.shape)
            self._grains[name] = packing.Grain(
                source,
                self.material(g.material),
                g.mesh_size,
                sizes,
                g.fraction,
                g.discretization,
                g.reference_radius,
                name,
            )
        return self._grains[name]


def _closest(name: str, choices: Any) -> str:
    options = sorted(choices)
    match = difflib.get_close_matches(name, options, n=1)
    if match:
        return f"; did you mean {match[0]!r}?"
    return f"; defined: {', '.join(map(repr, options)) or 'none'}"


@dataclass
class Case:
    """A validated case, built into a Simulation with its run plan."""

    spec: CaseSpec
    source: Path
    text: str
    #: What a translated PeriDEM deck runs differently (printed once by the CLI).
    notes: list[str] = field(default_factory=list)

    @property
    def fingerprint(self) -> str:
        """The case's digest, in the set-up's fingerprint (checkpoints, --resume): of every
        section but load_balance, which changes a distributed run's speed, never its results
        (a run may resume with other settings, and checkpoints written before the section
        existed keep their fingerprint)."""
        spec = self.spec.model_dump(mode="json", exclude={"load_balance"})
        return hashlib.sha256(json.dumps(spec, sort_keys=True).encode()).hexdigest()

    def build(
        self,
        *,
        output: str | Path | None = None,
        resume: bool = False,
        overwrite: bool = False,
        outputs: bool = True,
        comm: object | None = None,
    ) -> Simulation:
        """The Simulation the case describes (not yet run). ``output`` overrides the output
        directory; ``resume`` keeps an existing run there for load_checkpoint; ``outputs=False``
        sets up no output or checkpoints (``granulate check``); ``comm``: an mpi4py
        communicator to run it on (Simulation's)."""
        spec = self.spec
        case = CaseContext(spec, self.source.parent)
        sim = Simulation(
            spec.dimension,
            spec.plane,
            dt=spec.time.dt,
            dt_safety=spec.time.dt_safety,
            gravity=None
            if spec.gravity is None
            else _vector(spec.gravity, spec.dimension, "gravity"),
            viscous_damping=spec.viscous_damping,
            comm=comm,
        )
        sim.case_fingerprint = self.fingerprint
        named = _add_bodies(sim, spec, case)
        _add_particles(sim, spec, case, named)
        _add_packings(sim, spec, case)
        for c in spec.precracks:
            region = None if c.region is None else case.shape(c.region)
            sim.precrack(c.point, c.normal, region=region)
        _set_contact(sim, spec, case, named)
        for w in spec.walls:
            sim.add_wall(_wall(w, case), name=w.name)
        for load in spec.loading:
            _load(sim, load, case, named)
        sim.load_balance = spec.load_balance.make()
        if spec.restart is not None:
            # On --resume too: the start checks judge the restart's positions, not the
            # reference ones (the checkpoint then replaces the whole state).
            _restart(sim, case.path(spec.restart.file), spec.restart.step)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            sim.validate_time_step()  # an error here makes the warning about dt moot
        for warning in caught:
            warnings.warn(warning.message, warning.category, stacklevel=2)
        if not outputs:
            if spec.output is not None:  # what check can say about the outputs
                for t in spec.output.track:
                    _named(t, named, "output.track")
            return sim
        _set_outputs(sim, spec, named, output, resume=resume, overwrite=overwrite)
        return sim

    def stop_criteria(self) -> list[stopping.StopCriterion]:
        s = self.spec.stop
        if s is None:
            return []
        criteria: list[stopping.StopCriterion] = []
        if s.kinetic_energy_below is not None:
            criteria.append(
                stopping.KineticEnergyBelow(
                    s.kinetic_energy_below.energy, s.kinetic_energy_below.after
                )
            )
        if s.wall_displacement is not None:
            if s.wall_displacement.wall not in {w.name for w in self.spec.walls}:
                raise InputError(
                    f"stop.wall_displacement names wall {s.wall_displacement.wall!r}"
                    f"{_closest(s.wall_displacement.wall, [w.name for w in self.spec.walls])}"
                )
            criteria.append(
                stopping.WallDisplacement(s.wall_displacement.wall, s.wall_displacement.distance)
            )
        if s.particles_broken is not None:
            criteria.append(stopping.ParticlesBroken(s.particles_broken))
        if s.broken_bonds is not None:
            criteria.append(stopping.BrokenBonds(s.broken_bonds))
        if s.node_distance is not None:
            criteria.append(stopping.NodeDistance(s.node_distance))
        return criteria

    #: The most steps a case may ask for: a year at 10^5 steps per second.
    MOST_STEPS = 3 * 10**12

    def steps(self, sim: Simulation) -> int:
        """Steps from the current state to the end of the case; InputError past MOST_STEPS
        (an end time in the wrong unit: 1e300 s, or a step count beyond any run)."""
        if self.spec.time.steps is not None:
            count = float(self.spec.time.steps - sim.step)
        else:
            count = np.ceil((self.spec.time.end - sim.time) / sim.dt - 1e-9)  # type: ignore[operator]
        if not count <= self.MOST_STEPS:
            raise InputError(
                f"time: the run would take {count:.3g} steps of dt = {sim.dt:.4g} s (at most "
                f"{self.MOST_STEPS:.0e}, a year at 100,000 steps per second); check time.end or "
                "time.steps"
            )
        return max(0, int(count))


def _add_bodies(sim: Simulation, spec: CaseSpec, case: CaseContext) -> dict[str, Body]:
    """The case's bodies (Simulation.add_body), by name (body<k> for an unnamed one)."""
    named: dict[str, Body] = {}
    for k, b in enumerate(spec.bodies):
        shape = case.shape(b.shape)
        try:
            body = sim.add_body(
                shape,
                case.material(b.material),
                b.mesh_size,
                discretization=b.discretization,
                jitter=b.jitter,
                seed=b.seed,
                velocity=b.velocity,
                angular_velocity=b.angular_velocity,
                name=b.name or f"body{k}",
            )
        except InputError as error:
            raise InputError(f"bodies[{k}] ({b.name or f'body{k}'}): {error}") from None
        named[body.name] = body
    return named


def _add_particles(
    sim: Simulation, spec: CaseSpec, case: CaseContext, named: dict[str, Body]
) -> None:
    """The case's particles (Simulation.add_particle); named ones join `named`."""
    for p in spec.particles:
        g = case.grain(p.grain)
        if p.scale is not None and p.radius is not None:
            raise InputError(f"particle of grain {p.grain!r}: give scale or radius, not both")
        scale = p.radius / g.radius if p.radius is not None else (p.scale or 1.0)
        body = sim.add_particle(
            g.reference,
            g.material,
            position=p.position,
            rotation=p.rotation,
            scale=scale,
            velocity=p.velocity,
            angular_velocity=p.angular_velocity,
            name=p.name,
        )
        if p.name:
            named[p.name] = body


def _add_packings(sim: Simulation, spec: CaseSpec, case: CaseContext) -> None:
    """The generated packings, then the placements read from files."""
    for pk in spec.packings:
        result = packing.pack(
            case.shape(pk.container),
            [case.grain(g) for g in pk.grains],
            pk.count,
            by=pk.by,
            method=pk.method,
            gap=pk.gap,
            seed=pk.seed,
            attempts=pk.attempts,
        )
        sim.add_packing(result, velocity=pk.velocity)
    for pl in spec.placements:
        placements = packing.read_placements(
            case.path(pl.file), dimension=spec.dimension, seed=pl.seed
        )
        sim.add_placements(
            placements, {z: case.grain(g) for z, g in pl.zones.items()}, velocity=pl.velocity
        )


def _set_contact(
    sim: Simulation, spec: CaseSpec, case: CaseContext, named: dict[str, Body]
) -> None:
    """The contact law, its material pairs, PeriDEM's damping and the neighbour skin."""
    sim.contact = None if spec.contact is None else spec.contact.make()
    for pair in spec.contact_pairs:
        sim.set_contact(
            case.material(pair.materials[0]),
            case.material(pair.materials[1]),
            None if pair.contact is None else pair.contact.make(),
        )
    if spec.peridem_damping is not None:
        for damping in spec.peridem_damping.pairs:
            sim.set_peridem_damping(
                case.material(damping.materials[0]),
                case.material(damping.materials[1]),
                epsilon=damping.epsilon,
                beta_factor=damping.beta_factor,
            )
        sim.set_peridem_walls(
            [
                _named(w, named, "peridem_damping.walls names body")
                for w in spec.peridem_damping.walls
            ]
        )
    if spec.neighbor_skin is not None:
        sim.set_neighbor_skin(spec.neighbor_skin)


def _set_outputs(
    sim: Simulation,
    spec: CaseSpec,
    named: dict[str, Body],
    output: str | Path | None,
    *,
    resume: bool,
    overwrite: bool,
) -> None:
    """Frames, history and tracked bodies (to `output` if given), and checkpoints."""
    if spec.output is not None or output is not None:
        o = spec.output or OutputSpec()
        sim.output(
            output if output is not None else o.directory,
            o.every,
            fields=tuple(o.fields),
            overwrite=overwrite,
            resume=resume,
            history_every=o.history_every,
            track=[_named(t, named, "output.track") for t in o.track],
            track_areas=o.track_areas,
            pieces=o.pieces,
        )
    if spec.checkpoint is not None:
        sim.checkpoint_every(spec.checkpoint.every_steps, minutes=spec.checkpoint.every_minutes)


def _vector(values: list[float], dimension: int, name: str) -> list[float]:
    if len(values) not in (dimension, 3):
        raise InputError(f"{name} needs {dimension} components, got {len(values)}")
    return list(values)


def _surface(s: BaseModel, case: CaseContext) -> walls.Surface:
    kind = s.type  # type: ignore[attr-defined]
    if kind == "plane":
        return walls.Plane(s.point, s.normal)  # type: ignore[attr-defined]
    if kind in ("box_container", "box_obstacle"):
        cls = walls.BoxContainer if kind == "box_container" else walls.BoxObstacle
        return cls(s.lower, s.upper)  # type: ignore[attr-defined]
    if kind in ("circle_container", "circle_obstacle"):
        cls2 = walls.CircleContainer if kind == "circle_container" else walls.CircleObstacle
        return cls2(s.center, s.radius, s.axis)  # type: ignore[attr-defined]
    if kind in ("polygon_container", "polygon_obstacle"):
        cls3 = walls.PolygonContainer if kind == "polygon_container" else walls.PolygonObstacle
        return cls3(s.vertices)  # type: ignore[attr-defined]
    if kind == "triangle_mesh":
        return walls.TriangleMesh.from_file(case.path(s.file), inside=s.inside, scale=s.scale)  # type: ignore[attr-defined]
    shape = case.shape(s.shape)  # type: ignore[attr-defined]
    return walls.container(shape) if kind == "container" else walls.obstacle(shape)


def _wall(w: WallSpec, case: CaseContext) -> walls.Wall:
    motion: walls.Translation | walls.Rotation | None = None
    if isinstance(w.motion, TranslationSpec):
        motion = walls.Translation(w.motion.direction, make_function(w.motion.function))
    elif isinstance(w.motion, RotationSpec):
        motion = walls.Rotation(make_function(w.motion.angle), w.motion.center, w.motion.axis)
    elif isinstance(w.motion, SteadyRotationSpec):
        motion = walls.Rotation.steady(w.motion.angular_velocity, w.motion.center, w.motion.axis)
    return walls.Wall(
        tuple(_surface(s, case) for s in w.surfaces),
        motion,
        w.name,
        None if w.contact is None else w.contact.make(),
        w.center,
        w.area,
    )


def _restart(sim: Simulation, path: Path, step: int) -> None:
    """Positions and velocities of a VTU frame, at ``step`` (see RestartSpec)."""
    from granulate.io.vtu import read_vtu_point_data

    existing_file(path, "restart file")
    _, data = read_vtu_point_data(path)
    missing = [name for name in ("Displacement", "Velocity") if name not in data]
    if missing:
        raise InputError(
            f"restart file {path} has no {' or '.join(missing)} point data; restart needs both"
        )
    displacement, velocity = data["Displacement"], data["Velocity"]
    if displacement.shape != (sim.node_count, 3) or velocity.shape != (sim.node_count, 3):
        raise InputError(
            f"restart file {path} holds {len(displacement)} nodes, the case has "
            f"{sim.node_count}: it belongs to another set-up"
        )
    # Before the core is built, so that its start checks judge the frame's positions (a
    # restart may move a wall close to grains that have settled since the reference).
    sim.start_from(sim.reference_positions + displacement, velocity, step=step)


def _named(name: str, named: dict[str, Body], what: str) -> Body:
    if name not in named:
        raise InputError(f"{what} {name!r}{_closest(name, named)}")
    return named[name]


def _load(sim: Simulation, load: BaseModel, case: CaseContext, named: dict[str, Body]) -> None:
    select: SelectSpec = load.nodes  # type: ignore[attr-defined]
    region = None if select.region is None else case.shape(select.region)
    ids = None if select.ids is None else np.asarray(select.ids, dtype=np.int64)
    if select.body is not None:  # any of the bodies named
        chosen = [select.body] if isinstance(select.body, str) else select.body
        body_nodes = np.concatenate(
            [_named(b, named, "loading selects body").nodes for b in chosen]
        )
        ids = body_nodes if ids is None else np.intersect1d(ids, body_nodes)
    if select.exclude:
        left_out = np.concatenate(
            [_named(b, named, "loading excludes body").nodes for b in select.exclude]
        )
        ids = np.setdiff1d(np.arange(sim.node_count) if ids is None else ids, left_out)
    nodes = sim.select(region, ids=ids)
    if isinstance(load, FixSpec):
        sim.fix(nodes, load.components)
    elif isinstance(load, DisplacementSpec):
        sim.prescribe_displacement(
            nodes, load.direction, make_function(load.function), components=load.components
        )
    elif isinstance(load, VelocitySpec):
        sim.prescribe_velocity(
            nodes, load.velocity, ramp_time=load.ramp_time, components=load.components
        )
    elif isinstance(load, RotationLoadSpec):
        sim.prescribe_rotation(nodes, load.center, make_function(load.angle), axis=load.axis)
    elif isinstance(load, ForceDensitySpec):
        sim.add_force_density(
            nodes, load.vector, None if load.function is None else make_function(load.function)
        )
