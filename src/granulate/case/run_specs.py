"""Case-file contact, walls, loading, time, output, restart and stop sections, and the
whole case (CaseSpec)."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, model_validator

from granulate.case.particle_specs import (
    BodySpec,
    FunctionSpec,
    GrainSpec,
    PackingSpec,
    ParticleSpec,
    PlacementSpec,
    PrecrackSpec,
)
from granulate.case.shape_specs import ShapeRef, ShapeSpec
from granulate.case.spec_types import Finite, NonNegative, Positive, Spec
from granulate.contact import Contact
from granulate.input_errors import NOT_BOOL
from granulate.load_balance import LoadBalance
from granulate.materials import Material
from granulate.simulation import FIELDS


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
        "surface",
        description="'surface': surface nodes probe the other particle's smooth surface; "
        "'granulate': every node a sphere (cheaper, node-scale bumps); "
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


class LoadBalanceSpec(Spec):
    """When the ranks of a distributed run compare their work and cut the grains anew
    (granulate.LoadBalance); a serial run ignores it."""

    every: Annotated[int, Field(ge=0), NOT_BOOL] = Field(
        100, description="steps between comparisons of the ranks' work (0: only at the start)"
    )
    threshold: Annotated[float, Field(ge=1), NOT_BOOL] = Field(
        1.1,
        description="the most loaded rank's work over the mean that cuts anew [-] (.inf: never)",
    )
    weight: Literal["work", "time"] = Field(
        "work",
        description="'work': grains weighed by their counts; 'time': times their rank's "
        "measured step seconds per unit of them",
    )

    def make(self) -> LoadBalance:
        return LoadBalance(**self.model_dump())


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
    pieces: bool = Field(
        False,
        description="frames as .pvtu over pieces, one written by each MPI rank (one serially)",
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
    load_balance: LoadBalanceSpec = LoadBalanceSpec()
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
