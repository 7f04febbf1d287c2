"""YAML case files: a whole simulation described as data, mapping one-to-one onto the Python API.

    granulate check case.yaml          # validate and summarise
    granulate run case.yaml            # run it
    granulate schema                   # the reference of every key (units included)

A case is validated up front (pydantic): an error names the key path, what was expected, what
was found, and for a misspelt key the closest valid one. File paths (meshes, STL surfaces,
placement CSVs) are relative to the case file's folder. SI units throughout. Example::

    dimension: 2
    materials:
      rock: {density: 2600, youngs_modulus: 5.0e+9, poisson_ratio: 0.25, fracture_energy: 20}
    grains:
      pebble: {shape: {type: disc, radius: 1.0e-3}, material: rock, mesh_size: 2.0e-4,
               sizes: {distribution: uniform, low: 0.8e-3, high: 1.2e-3}}
    packings:
      - {container: {type: rectangle, lower: [0, 0], upper: [0.02, 0.02]}, grains: [pebble],
         count: 40, seed: 1}
    walls:
      - {name: box, surfaces: [{type: container, shape: {type: rectangle, lower: [0, 0],
                                                         upper: [0.02, 0.02]}}]}
    gravity: [0, -9.81]
    contact: {restitution: 0.5, friction: 0.4}
    time: {end: 0.01}
    output: {directory: out/pile, every: 500}
"""

from __future__ import annotations

import difflib
import hashlib
import json
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from granulate import functions, meshes, packing, shapes, stopping, walls
from granulate.contact import Contact
from granulate.errors import InputError
from granulate.input_errors import NOT_BOOL, describe
from granulate.io.files import existing_file, read_text
from granulate.materials import Material
from granulate.simulation import FIELDS, Body, Simulation
from granulate.yaml_input import load_yaml

Vector = list[Annotated[float, NOT_BOOL]]
Positive = Annotated[float, Field(gt=0, allow_inf_nan=False), NOT_BOOL]
NonNegative = Annotated[float, Field(ge=0, allow_inf_nan=False), NOT_BOOL]
Finite = Annotated[float, Field(allow_inf_nan=False), NOT_BOOL]


class Spec(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


# ----------------------------------------------------------------------------- shapes
class RectangleSpec(Spec):
    """Axis-aligned rectangle (2D)."""

    type: Literal["rectangle"]
    lower: Annotated[list[Finite], Field(min_length=2, max_length=2, description="corner [m]")]
    upper: Annotated[list[Finite], Field(min_length=2, max_length=2, description="corner [m]")]

    def make(self, case: CaseContext) -> shapes.Shape:
        return shapes.Rectangle(tuple(self.lower), tuple(self.upper))  # type: ignore[arg-type]


class DiscSpec(Spec):
    """Disc (2D)."""

    type: Literal["disc"]
    center: Annotated[list[Finite], Field(min_length=2, max_length=2, description="[m]")] = [0, 0]
    radius: Positive = Field(description="[m]")

    def make(self, case: CaseContext) -> shapes.Shape:
        return shapes.Disc(tuple(self.center), self.radius)  # type: ignore[arg-type]


class EllipseSpec(Spec):
    """Ellipse (2D)."""

    type: Literal["ellipse"]
    center: Annotated[list[Finite], Field(min_length=2, max_length=2, description="[m]")] = [0, 0]
    semi_axes: Annotated[list[Positive], Field(min_length=2, max_length=2, description="[m]")]
    angle: Finite = Field(0.0, description="of the first semi-axis from x [rad]")

    def make(self, case: CaseContext) -> shapes.Shape:
        return shapes.Ellipse(tuple(self.center), tuple(self.semi_axes), self.angle)  # type: ignore[arg-type]


class PolygonSpec(Spec):
    """Simple polygon from its vertices in order, concave allowed (2D)."""

    type: Literal["polygon"]
    vertices: Annotated[
        list[Annotated[list[Finite], Field(min_length=2, max_length=2)]],
        Field(min_length=3, description="[m]"),
    ]

    def make(self, case: CaseContext) -> shapes.Shape:
        return shapes.Polygon(tuple(tuple(v) for v in self.vertices))  # type: ignore[arg-type]


class RegularPolygonSpec(Spec):
    """Regular polygon: sides 3 (triangle), 4, 6 (hexagon), ... (2D)."""

    type: Literal["regular_polygon"]
    center: Annotated[list[Finite], Field(min_length=2, max_length=2, description="[m]")] = [0, 0]
    radius: Positive = Field(description="circumradius [m]")
    sides: Annotated[int, Field(ge=3), NOT_BOOL] = Field(description="[-]")
    angle: Finite = Field(0.0, description="of the first vertex from x [rad]")

    def make(self, case: CaseContext) -> shapes.Shape:
        return shapes.RegularPolygon(tuple(self.center), self.radius, self.sides, self.angle)  # type: ignore[arg-type]


class StarSpec(Spec):
    """Star polygon (2D)."""

    type: Literal["star"]
    center: Annotated[list[Finite], Field(min_length=2, max_length=2, description="[m]")] = [0, 0]
    outer_radius: Positive = Field(description="tips [m]")
    inner_radius: Positive = Field(description="notches [m]")
    points: Annotated[int, Field(ge=3), NOT_BOOL] = Field(5, description="[-]")
    angle: Finite = Field(0.0, description="[rad]")

    def make(self, case: CaseContext) -> shapes.Shape:
        return shapes.Star(
            tuple(self.center), self.outer_radius, self.inner_radius, self.points, self.angle
        )  # type: ignore[arg-type]


class Drum2DSpec(Spec):
    """PeriDEM's drum: a hexagon pinched to a neck (2D)."""

    type: Literal["drum2d"]
    center: Annotated[list[Finite], Field(min_length=2, max_length=2, description="[m]")] = [0, 0]
    radius: Positive = Field(description="circumradius [m]")
    neck_half_width: Positive = Field(description="[m]")
    angle: Finite = Field(0.0, description="of the axis [rad]")

    def make(self, case: CaseContext) -> shapes.Shape:
        return shapes.Drum2D(tuple(self.center), self.radius, self.neck_half_width, self.angle)  # type: ignore[arg-type]


class BoxSpec(Spec):
    """Axis-aligned box (3D)."""

    type: Literal["box"]
    lower: Annotated[list[Finite], Field(min_length=3, max_length=3, description="corner [m]")]
    upper: Annotated[list[Finite], Field(min_length=3, max_length=3, description="corner [m]")]

    def make(self, case: CaseContext) -> shapes.Shape:
        return shapes.Box(tuple(self.lower), tuple(self.upper))  # type: ignore[arg-type]


class SphereSpec(Spec):
    """Sphere (3D)."""

    type: Literal["sphere"]
    center: Annotated[list[Finite], Field(min_length=3, max_length=3, description="[m]")] = [
        0,
        0,
        0,
    ]
    radius: Positive = Field(description="[m]")

    def make(self, case: CaseContext) -> shapes.Shape:
        return shapes.Sphere(tuple(self.center), self.radius)  # type: ignore[arg-type]


class EllipsoidSpec(Spec):
    """Ellipsoid (3D)."""

    type: Literal["ellipsoid"]
    center: Annotated[list[Finite], Field(min_length=3, max_length=3, description="[m]")] = [
        0,
        0,
        0,
    ]
    semi_axes: Annotated[list[Positive], Field(min_length=3, max_length=3, description="[m]")]
    rotation: (
        Annotated[
            list[Finite], Field(min_length=3, max_length=3, description="rotation vector [rad]")
        ]
        | None
    ) = Field(None, description="rotation vector [rad]")

    def make(self, case: CaseContext) -> shapes.Shape:
        return shapes.Ellipsoid(tuple(self.center), tuple(self.semi_axes), self.rotation)  # type: ignore[arg-type]


class CylinderSpec(Spec):
    """Solid cylinder (3D)."""

    type: Literal["cylinder"]
    center: Annotated[
        list[Finite], Field(min_length=3, max_length=3, description="mid-axis [m]")
    ] = [0, 0, 0]
    radius: Positive = Field(description="[m]")
    length: Positive = Field(description="[m]")
    axis: Annotated[list[Finite], Field(min_length=3, max_length=3)] = Field(
        [0, 0, 1], description="direction [-]"
    )

    def make(self, case: CaseContext) -> shapes.Shape:
        return shapes.Cylinder(tuple(self.center), self.radius, self.length, tuple(self.axis))  # type: ignore[arg-type]


class SurfaceSpec(Spec):
    """A solid bounded by a closed triangle surface file: STL, OBJ, PLY (3D)."""

    type: Literal["surface"]
    file: str = Field(description="path, relative to the case file")
    scale: Positive = Field(1.0, description="multiplies the coordinates (1e-3 for millimetres)")

    def make(self, case: CaseContext) -> shapes.Shape:
        return meshes.SurfaceMesh.from_file(case.path(self.file), scale=self.scale)


class UnionSpec(Spec):
    """Points in any of the shapes."""

    type: Literal["union"]
    shapes: Annotated[list[ShapeRef], Field(min_length=1)]

    def make(self, case: CaseContext) -> shapes.Shape:
        return shapes.Union(tuple(case.shape(s) for s in self.shapes))


class DifferenceSpec(Spec):
    """Points of `base` not in `removed` (notches, holes)."""

    type: Literal["difference"]
    base: ShapeRef
    removed: ShapeRef

    def make(self, case: CaseContext) -> shapes.Shape:
        return shapes.Difference(case.shape(self.base), case.shape(self.removed))


ShapeSpec = Annotated[
    RectangleSpec
    | DiscSpec
    | EllipseSpec
    | PolygonSpec
    | RegularPolygonSpec
    | StarSpec
    | Drum2DSpec
    | BoxSpec
    | SphereSpec
    | EllipsoidSpec
    | CylinderSpec
    | SurfaceSpec
    | UnionSpec
    | DifferenceSpec,
    Field(discriminator="type"),
]
#: A shape, or the name of one in the case's `shapes` section.
ShapeRef = ShapeSpec | str


# ------------------------------------------------------------------------ time functions
class ConstantSpec(Spec):
    type: Literal["constant"]
    value: Finite = Field(1.0, description="[the loading's unit: m, m/s, rad, or a factor]")


class LinearSpec(Spec):
    type: Literal["linear"]
    rate: Finite = Field(description="per second")


class QuadraticSpec(Spec):
    type: Literal["quadratic"]
    a: Finite = Field(description="f = a t + b t^2")
    b: Finite = Field(description="[the loading's unit / s^2]")


class SineSpec(Spec):
    type: Literal["sine"]
    amplitude: Finite = Field(description="[the loading's unit]")
    frequency: Positive = Field(description="[Hz]")


class SmoothRampSpec(Spec):
    type: Literal["smooth_ramp"]
    target: Finite = Field(description="[the loading's unit]")
    duration: Positive = Field(description="[s]")


class VelocityRampSpec(Spec):
    type: Literal["velocity_ramp"]
    rate: Finite = Field(description="final rate, per second")
    duration: Positive = Field(description="[s]")


FunctionSpec = Annotated[
    ConstantSpec | LinearSpec | QuadraticSpec | SineSpec | SmoothRampSpec | VelocityRampSpec,
    Field(discriminator="type"),
]
_FUNCTIONS = {
    "constant": functions.Constant,
    "linear": functions.Linear,
    "quadratic": functions.Quadratic,
    "sine": functions.Sine,
    "smooth_ramp": functions.SmoothRamp,
    "velocity_ramp": functions.VelocityRamp,
}


def make_function(spec: BaseModel) -> functions.TimeFunction:
    values = spec.model_dump()
    return _FUNCTIONS[values.pop("type")](**values)


# ------------------------------------------------------------------------ sizes, grains
class FixedSizeSpec(Spec):
    distribution: Literal["fixed"]
    radius: Positive = Field(description="bounding radius [m]")


class UniformSizeSpec(Spec):
    distribution: Literal["uniform"]
    low: Positive = Field(description="[m]")
    high: Positive = Field(description="[m]")


class NormalSizeSpec(Spec):
    distribution: Literal["normal"]
    mean: Positive = Field(description="[m]")
    std: NonNegative = Field(description="[m]")
    low: Positive | None = Field(None, description="[m]")
    high: Positive | None = Field(None, description="[m]")


class LogNormalSizeSpec(Spec):
    distribution: Literal["lognormal"]
    median: Positive = Field(description="[m]")
    sigma: NonNegative = Field(description="of ln r")
    low: Positive | None = Field(None, description="[m]")
    high: Positive | None = Field(None, description="[m]")


class SieveSizeSpec(Spec):
    distribution: Literal["sieve"]
    diameters: list[Positive] = Field(description="sieve openings, increasing [m]")
    passing: list[NonNegative] = Field(description="mass fraction passing, 0 ... 1")
    dimension: Literal[2, 3] = 3


SizeSpec = Annotated[
    FixedSizeSpec | UniformSizeSpec | NormalSizeSpec | LogNormalSizeSpec | SieveSizeSpec,
    Field(discriminator="distribution"),
]
_SIZES = {
    "fixed": packing.Fixed,
    "uniform": packing.Uniform,
    "normal": packing.Normal,
    "lognormal": packing.LogNormal,
    "sieve": packing.Sieve,
}


class MeshSpec(Spec):
    """A particle mesh made elsewhere: gmsh .msh (v2/v4), .vtu or a CSV of points with volumes."""

    file: str = Field(description="path, relative to the case file")
    dimension: Literal[2, 3] | None = None
    mesh_size: Positive | None = Field(None, description="default: median element size [m]")
    center: list[Finite] | None = Field(None, description="moved to the local origin [m]")


class GrainSpec(Spec):
    """A kind of particle: a shape (discretized once) or a mesh, and its material."""

    shape: ShapeRef | None = None
    mesh: MeshSpec | None = None
    material: str = Field(description="name in `materials`")
    mesh_size: Positive | None = Field(None, description="at the reference size [m]")
    discretization: Literal["lattice", "conforming", "grid"] = "lattice"
    sizes: SizeSpec | None = Field(None, description="bounding radii, for packings")
    fraction: NonNegative = Field(1.0, description="share in packings (by number or volume)")
    reference_radius: Positive | None = Field(None, description="default: bounding radius [m]")

    @model_validator(mode="after")
    def _one_source(self) -> GrainSpec:
        if (self.shape is None) == (self.mesh is None):
            raise ValueError("give either shape or mesh")
        if self.shape is not None and self.mesh_size is None:
            raise ValueError("a grain made from a shape needs mesh_size [m]")
        return self


# ------------------------------------------------------------------ bodies and particles
class BodySpec(Spec):
    """One body: a shape filled with nodes (Simulation.add_body)."""

    name: str | None = None
    shape: ShapeRef
    material: str
    mesh_size: Positive = Field(description="[m]")
    discretization: Literal["lattice", "conforming", "grid"] = "lattice"
    jitter: Annotated[float, Field(ge=0, lt=0.5), NOT_BOOL] = Field(0.0, description="[mesh sizes]")
    seed: Annotated[int, Field(ge=0), NOT_BOOL] = Field(0, description="random seed of the jitter")
    velocity: list[Finite] | None = Field(None, description="[m/s]")
    angular_velocity: Finite | list[Finite] | None = Field(None, description="[rad/s]")


class ParticleSpec(Spec):
    """One placed grain (Simulation.add_particle)."""

    name: str | None = None
    grain: str = Field(description="name in `grains`")
    position: list[Finite] = Field(description="[m]")
    rotation: Finite | list[Finite] | None = Field(
        None, description="angle or rotation vector [rad]"
    )
    scale: Positive | None = Field(None, description="[-] times the grain's reference size")
    radius: Positive | None = Field(None, description="bounding radius [m] (instead of scale)")
    velocity: list[Finite] | None = Field(None, description="[m/s]")
    angular_velocity: Finite | list[Finite] | None = Field(None, description="[rad/s]")


class PackingSpec(Spec):
    """A generated packing (granulate.pack)."""

    container: ShapeRef
    grains: Annotated[list[str], Field(min_length=1)]
    count: Annotated[int, Field(gt=0), NOT_BOOL] = Field(description="[particles]")
    by: Literal["number", "volume"] = "number"
    method: Literal["random", "lattice"] = "random"
    gap: NonNegative = Field(0.0, description="[m]")
    seed: Annotated[int, Field(ge=0), NOT_BOOL] = Field(0, description="random seed")
    attempts: Annotated[int, Field(gt=0), NOT_BOOL] = Field(
        2000, description="placement attempts per particle"
    )
    velocity: list[Finite] | None = Field(None, description="[m/s]")


class PlacementSpec(Spec):
    """Particles from a PeriDEM placement CSV (i, x, y, z, r[, o])."""

    file: str = Field(description="path, relative to the case file")
    zones: dict[int, str] = Field(description="zone id -> grain name")
    seed: Annotated[int, Field(ge=0), NOT_BOOL] = Field(
        0, description="random seed of the orientations"
    )
    velocity: list[Finite] | None = Field(None, description="[m/s]")


class PrecrackSpec(Spec):
    point: list[Finite] = Field(description="[m]")
    normal: list[Finite] = Field(description="[-]")
    region: ShapeRef | None = None


# ----------------------------------------------------------------------- contact, walls
class ContactSpec(Spec):
    """Contact parameters (see granulate.Contact)."""

    restitution: Annotated[float, Field(gt=0, le=1), NOT_BOOL] = Field(
        1.0, description="e [-] of a head-on collision"
    )
    friction: NonNegative = Field(0.0, description="Coulomb mu [-]")
    contact_radius_factor: Positive = Field(
        0.95, description="each node's contact radius is factor x h / 2 of its particle"
    )
    contact_radius: Positive | None = Field(None, description="absolute Rc [m]")
    normal_stiffness: Positive | None = Field(None, description="absolute kn")
    stiffness_factor: Positive = Field(1.0, description="times the default kn [-]")
    tangential_stiffness_ratio: Annotated[float, Field(gt=0, le=1), NOT_BOOL] = Field(
        2.0 / 7.0, description="kt / kn of the friction spring"
    )
    rolling_friction: NonNegative = Field(
        0.0, description="rolling resistance mu_r [-]: torque capped at mu_r R* F_n"
    )
    rolling_damping: Annotated[float, Field(ge=0, le=1), NOT_BOOL] = Field(
        0.3, description="eta_r [-]: the rolling dashpot's share of critical damping"
    )
    friction_law: Literal["coulomb", "peridem"] = Field(
        "coulomb", description="'peridem': PeriDEM's friction (speeds sliding up), comparisons only"
    )
    pair_law: Literal["granulate", "surface", "peridem"] = Field(
        "granulate",
        description="'surface': surface nodes probe the other particle's smooth surface; "
        "'peridem': PeriDEM's node-pair law (one Rc from the finer mesh, springs kn V_i V_j), "
        "comparisons only",
    )

    def make(self) -> Contact:
        return Contact(**self.model_dump())


class PairContactSpec(Spec):
    materials: Annotated[list[str], Field(min_length=2, max_length=2)]
    contact: ContactSpec | None = Field(description="null: the materials pass through each other")


class PeridemDampingPairSpec(Spec):
    materials: Annotated[list[str], Field(min_length=2, max_length=2)]
    epsilon: Annotated[float, Field(gt=0, le=1), NOT_BOOL] = Field(description="PeriDEM's Epsilon")
    beta_factor: NonNegative = Field(1.0, description="PeriDEM's Beta_n_Factor")


class PeridemDampingSpec(Spec):
    """PeriDEM's particle-centre contact damping, for comparisons with PeriDEM only (it does
    not give the restitution epsilon names; Simulation.set_peridem_damping)."""

    pairs: list[PeridemDampingPairSpec]
    walls: list[str] = Field([], description="bodies PeriDEM treats as walls")


class PlaneSurfaceSpec(Spec):
    type: Literal["plane"]
    point: list[Finite] = Field(description="[m]")
    normal: list[Finite] = Field(description="towards the particles")


class BoxSurfaceSpec(Spec):
    type: Literal["box_container", "box_obstacle"]
    lower: list[Finite] = Field(description="[m]")
    upper: list[Finite] = Field(description="[m]")


class CircleSurfaceSpec(Spec):
    type: Literal["circle_container", "circle_obstacle"]
    center: list[Finite] = Field(description="[m]")
    radius: Positive = Field(description="[m]")
    axis: list[Finite] = Field([0, 0, 1], description="cylinder axis (3D)")


class PolygonSurfaceSpec(Spec):
    type: Literal["polygon_container", "polygon_obstacle"]
    vertices: Annotated[list[list[Finite]], Field(min_length=3, description="[m]")]


class MeshSurfaceSpec(Spec):
    type: Literal["triangle_mesh"]
    file: str = Field(description="STL/OBJ/PLY, relative to the case file")
    inside: bool = True
    scale: Positive = Field(1.0, description="[-]")


class ShapeSurfaceSpec(Spec):
    type: Literal["container", "obstacle"]
    shape: ShapeRef


SurfaceSpecs = Annotated[
    PlaneSurfaceSpec
    | BoxSurfaceSpec
    | CircleSurfaceSpec
    | PolygonSurfaceSpec
    | MeshSurfaceSpec
    | ShapeSurfaceSpec,
    Field(discriminator="type"),
]


class TranslationSpec(Spec):
    type: Literal["translation"]
    direction: list[Finite] = Field(description="[-]")
    function: FunctionSpec = Field(description="distance [m] along direction")


class RotationSpec(Spec):
    type: Literal["rotation"]
    angle: FunctionSpec = Field(description="[rad]")
    center: list[Finite] = Field([0, 0, 0], description="[m]")
    axis: list[Finite] = Field([0, 0, 1], description="[-]")


class SteadyRotationSpec(Spec):
    type: Literal["steady_rotation"]
    angular_velocity: Finite = Field(description="[rad/s]")
    center: list[Finite] = Field([0, 0, 0], description="[m]")
    axis: list[Finite] = Field([0, 0, 1], description="[-]")


MotionSpec = Annotated[
    TranslationSpec | RotationSpec | SteadyRotationSpec,
    Field(discriminator="type"),
]


class WallSpec(Spec):
    """A rigid wall: surfaces moving together."""

    name: str
    surfaces: Annotated[list[SurfaceSpecs], Field(min_length=1)]
    motion: MotionSpec | None = None
    contact: ContactSpec | None = None
    center: list[Finite] = Field([0, 0, 0], description="torque reference [m]")
    area: Positive | None = Field(
        None, description="nominal area for <name>_stress in history.csv [m^2; m in 2D]"
    )


# ----------------------------------------------------------------------------- loading
class SelectSpec(Spec):
    """Nodes by region (reference positions), body name(s) and/or node ids; all must hold."""

    region: ShapeRef | None = None
    body: str | list[str] | None = Field(None, description="a body name, or a list (any of them)")
    exclude: list[str] = Field([], description="bodies whose nodes are left out")
    ids: list[Annotated[int, Field(ge=0), NOT_BOOL]] | None = Field(None, description="node ids")


class FixSpec(Spec):
    type: Literal["fix"]
    nodes: SelectSpec
    components: str = "xyz"


class DisplacementSpec(Spec):
    type: Literal["displacement"]
    nodes: SelectSpec
    direction: list[Finite] = Field(description="[-], times the function's value [m]")
    function: FunctionSpec = Field(description="displacement [m] along direction")
    components: str | None = None


class VelocitySpec(Spec):
    type: Literal["velocity"]
    nodes: SelectSpec
    velocity: list[Finite] = Field(description="[m/s]")
    ramp_time: NonNegative = Field(0.0, description="[s]")
    components: str | None = None


class RotationLoadSpec(Spec):
    type: Literal["rotation"]
    nodes: SelectSpec
    center: list[Finite] = Field(description="[m]")
    angle: FunctionSpec = Field(description="[rad]")
    axis: list[Finite] = Field([0, 0, 1], description="[-]")


class ForceDensitySpec(Spec):
    type: Literal["force_density"]
    nodes: SelectSpec
    vector: list[Finite] = Field(description="[N/m^3]")
    function: FunctionSpec | None = None


LoadSpec = Annotated[
    FixSpec | DisplacementSpec | VelocitySpec | RotationLoadSpec | ForceDensitySpec,
    Field(discriminator="type"),
]


# ------------------------------------------------------------------- time, output, stop
class TimeSpec(Spec):
    """Time stepping: dt (default: dt_safety x the stable estimate) and the run length."""

    dt: Positive | None = Field(None, description="[s]")
    dt_safety: Annotated[float, Field(gt=0, le=1), NOT_BOOL] = Field(
        0.8, description="dt / stable estimate [-]"
    )
    end: Positive | None = Field(None, description="simulated time to reach [s]")
    steps: Annotated[int, Field(gt=0), NOT_BOOL] | None = Field(None, description="[steps]")

    @model_validator(mode="after")
    def _length(self) -> TimeSpec:
        if (self.end is None) == (self.steps is None):
            raise ValueError("give the run length as either end [s] or steps")
        return self


class OutputSpec(Spec):
    directory: str = Field("out", description="relative to the working directory")
    every: Annotated[int, Field(gt=0), NOT_BOOL] = Field(1000, description="steps between frames")
    fields: list[Literal[FIELDS]] = list(FIELDS)  # type: ignore[valid-type]
    history_every: Annotated[int, Field(gt=0), NOT_BOOL] | None = Field(
        None, description="steps between history.csv rows (default: every)"
    )
    track: list[str] = Field(
        [], description="bodies whose force resultant and mean displacement history.csv records"
    )
    track_areas: dict[str, Positive] = Field(
        {},
        description="nominal areas of tracked bodies, for <name>_stress in history.csv "
        "[m^2; m in 2D]",
    )

    @model_validator(mode="after")
    def _areas_of_tracked(self) -> OutputSpec:
        untracked = sorted(set(self.track_areas) - set(self.track))
        if untracked:
            raise ValueError(
                f"track_areas names {untracked}, which output.track does not list; track them too"
            )
        return self


class RestartSpec(Spec):
    """Start from positions and velocities read from a VTU frame (granulate's or PeriDEM's), at
    a given step: x = X + Displacement, v = Velocity, t = step dt. Bonds start intact (a VTU frame
    does not hold their states; granulate's checkpoints do, see --resume)."""

    file: str = Field(description="VTU file with Displacement and Velocity, relative to the case")
    step: Annotated[int, Field(ge=0), NOT_BOOL] = Field(
        description="the step the frame was written at"
    )


class CheckpointSpec(Spec):
    every_steps: Annotated[int, Field(gt=0), NOT_BOOL] | None = Field(None, description="[steps]")
    every_minutes: Positive | None = Field(None, description="[minutes of wall time]")


class KineticEnergyStopSpec(Spec):
    energy: Positive = Field(description="[J; J/m in 2D]")
    after: NonNegative = Field(0.0, description="not before this time [s]")


class WallDisplacementStopSpec(Spec):
    wall: str
    distance: Positive = Field(description="[m]")


class StopSpec(Spec):
    """Criteria that end the run early (checked every check_every steps)."""

    kinetic_energy_below: KineticEnergyStopSpec | None = Field(None, description="[J; J/m in 2D]")
    wall_displacement: WallDisplacementStopSpec | None = None
    particles_broken: Annotated[int, Field(gt=0), NOT_BOOL] | None = Field(
        None, description="particles with every bond broken"
    )
    broken_bonds: Annotated[int, Field(gt=0), NOT_BOOL] | None = None
    node_distance: Positive | None = Field(
        None, description="a node farther than this from the origin [m]"
    )
    check_every: Annotated[int, Field(gt=0), NOT_BOOL] = Field(100, description="[steps]")


class CaseSpec(Spec):
    """A granulate case."""

    dimension: Literal[2, 3]
    plane: Literal["strain", "stress", "peridem"] = Field(
        "strain", description="2D: 'peridem' = PeriDEM's 3D constants in 2D, comparisons only"
    )
    materials: Annotated[dict[str, Material], Field(min_length=1)]
    shapes: dict[str, ShapeSpec] = {}
    grains: dict[str, GrainSpec] = {}
    bodies: list[BodySpec] = []
    particles: list[ParticleSpec] = []
    packings: list[PackingSpec] = []
    placements: list[PlacementSpec] = []
    precracks: list[PrecrackSpec] = []
    contact: ContactSpec | None = ContactSpec()
    contact_pairs: list[PairContactSpec] = []
    peridem_damping: PeridemDampingSpec | None = None
    walls: list[WallSpec] = []
    loading: list[LoadSpec] = []
    gravity: list[Finite] | None = Field(None, description="[m/s^2]")
    viscous_damping: NonNegative = Field(0.0, description="[1/s]")
    neighbor_skin: Positive | None = Field(None, description="[m]")
    time: TimeSpec
    output: OutputSpec | None = None
    checkpoint: CheckpointSpec | None = None
    restart: RestartSpec | None = None
    stop: StopSpec | None = None

    @model_validator(mode="after")
    def _something(self) -> CaseSpec:
        if not (self.bodies or self.particles or self.packings or self.placements):
            raise ValueError(
                "the case has no particles: add bodies, particles, packings or placements"
            )
        return self

    @model_validator(mode="after")
    def _names_once(self) -> CaseSpec:
        """A name says one thing: bodies and particles, walls, and material pairs of contact
        laws each once; tracked bodies not named like walls (history.csv columns)."""
        bodies = [b.name for b in [*self.bodies, *self.particles] if b.name is not None]
        walls = [w.name for w in self.walls if w.name is not None]
        pairs = [tuple(sorted(pair.materials)) for pair in self.contact_pairs]
        for what, names in (("bodies and particles", bodies), ("walls", walls)):
            twice = sorted({n for n in names if names.count(n) > 1})
            if twice:
                raise ValueError(f"{what} named {twice} more than once; give each its own name")
        twice_pairs = sorted({p for p in pairs if pairs.count(p) > 1})
        if twice_pairs:
            raise ValueError(f"contact_pairs give the material pairs {twice_pairs} twice; keep one")
        tracked = set(self.output.track) if self.output is not None else set()
        if tracked & set(walls):
            raise ValueError(
                f"output.track names {sorted(tracked & set(walls))}, which are walls too; their "
                "history.csv columns would overwrite each other: rename them"
            )
        return self


for _model in list(globals().values()):
    if isinstance(_model, type) and issubclass(_model, Spec) and _model is not Spec:
        _model.model_rebuild()


# --------------------------------------------------------------------------- building
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
                source: shapes.Shape | shapes.ReferenceShape = shapes.ReferenceShape.from_mesh(
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
        return hashlib.sha256(
            json.dumps(self.spec.model_dump(mode="json"), sort_keys=True).encode()
        ).hexdigest()

    def build(
        self,
        *,
        output: str | Path | None = None,
        resume: bool = False,
        overwrite: bool = False,
        outputs: bool = True,
    ) -> Simulation:
        """The Simulation the case describes (not yet run). ``output`` overrides the output
        directory; ``resume`` keeps an existing run there for load_checkpoint; ``outputs=False``
        sets up no output or checkpoints (``granulate check``)."""
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
        )
        sim.case_fingerprint = self.fingerprint
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
        for c in spec.precracks:
            region = None if c.region is None else case.shape(c.region)
            sim.precrack(c.point, c.normal, region=region)
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
        for w in spec.walls:
            sim.add_wall(_wall(w, case), name=w.name)
        for load in spec.loading:
            _load(sim, load, case, named)
        if spec.restart is not None and not resume:
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
            )
        if spec.checkpoint is not None:
            sim.checkpoint_every(spec.checkpoint.every_steps, minutes=spec.checkpoint.every_minutes)
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
    sim.positions[:] = sim.model.reference_positions + displacement
    sim.velocities[:] = velocity
    sim.core.step = step
    sim.core.time = step * sim.dt


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


# ----------------------------------------------------------------------------- loading
def load_case(path: str | Path, *, peridem_compat: bool = False) -> Case:
    """Read and validate a YAML case file (InputError with every problem found). A PeriDEM
    input deck is recognised and translated (granulate.peridem); ``peridem_compat`` selects
    PeriDEM's formulas where granulate has them. It is refused for a native case."""
    source = Path(path)
    text = read_text(source, "case file")
    data = load_yaml(text, source)
    from granulate import peridem

    if peridem.is_deck(data):
        translation = peridem.translate(source, compat=peridem_compat)
        case = parse_case(peridem.to_yaml(translation, peridem_compat), source)
        case.text = text + "\n---\n" + case.text
        case.notes = translation.notes
        return case
    if peridem_compat:
        raise InputError(
            f"{source} is a granulate case, not a PeriDEM deck: --peridem-compat applies to "
            "decks (a case sets plane: peridem and friction_law: peridem itself)"
        )
    return parse_case(text, source)


def parse_case(text: str, source: Path = Path("case.yaml")) -> Case:
    data = load_yaml(text, source)
    if not isinstance(data, dict):
        raise InputError(
            f"{source}: a case file is a mapping of keys (dimension, materials, ...), got "
            f"{type(data).__name__}"
        )
    try:
        spec = CaseSpec.model_validate(data)
    except ValidationError as error:
        raise InputError(f"{source}: " + describe(error, data, _ALL_SPECS)) from None
    return Case(spec, source.resolve(), text)


_ALL_SPECS: list[type[BaseModel]] = [
    m
    for m in list(globals().values())
    if isinstance(m, type) and issubclass(m, Spec) and m is not Spec
] + [Material]


def schema() -> dict[str, Any]:
    """The JSON Schema of case files (for editors)."""
    return CaseSpec.model_json_schema()


def reference() -> str:
    """A readable reference of every key, with types, defaults and units."""
    out = ["granulate case file reference (SI units)", ""]
    document = schema()
    definitions = document.get("$defs", {})

    def describe_type(prop: dict[str, Any]) -> str:
        if "$ref" in prop:
            return prop["$ref"].split("/")[-1].removesuffix("Spec")
        if "anyOf" in prop:
            return " | ".join(describe_type(p) for p in prop["anyOf"])
        if "oneOf" in prop:
            return " | ".join(describe_type(p) for p in prop["oneOf"])
        if "enum" in prop:
            return " | ".join(map(repr, prop["enum"]))
        if "const" in prop:
            return repr(prop["const"])
        if prop.get("type") == "array":
            return f"list of {describe_type(prop.get('items', {}))}"
        if prop.get("type") == "object" and "additionalProperties" in prop:
            return f"mapping of name -> {describe_type(prop['additionalProperties'])}"
        return str(prop.get("type", "any"))

    def section(name: str, body: dict[str, Any]) -> None:
        out.append(
            f"{name}:"
            + (f"  {body['description'].splitlines()[0]}" if body.get("description") else "")
        )
        required = set(body.get("required", []))
        for key, prop in body.get("properties", {}).items():
            line = f"  {key}: {describe_type(prop)}"
            if key in required:
                line += " (required)"
            elif "default" in prop:
                line += f" = {json.dumps(prop['default'])}"
            if prop.get("description"):
                line += f"  -- {prop['description']}"
            out.append(line)
        out.append("")

    section("case", document)
    for name, body in definitions.items():
        section(name.removesuffix("Spec"), body)
    return "\n".join(out)
