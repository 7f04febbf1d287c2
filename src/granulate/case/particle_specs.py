"""Case-file time functions, size distributions, grains, bodies, particles, packings,
placements and precracks."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, Field, model_validator

from granulate import functions, size_distributions
from granulate.case.shape_specs import ShapeRef
from granulate.case.spec_types import Finite, NonNegative, Positive, Spec
from granulate.input_errors import NOT_BOOL


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
    "fixed": size_distributions.Fixed,
    "uniform": size_distributions.Uniform,
    "normal": size_distributions.Normal,
    "lognormal": size_distributions.LogNormal,
    "sieve": size_distributions.Sieve,
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


for _model in list(globals().values()):
    if isinstance(_model, type) and issubclass(_model, Spec) and _model is not Spec:
        _model.model_rebuild()
