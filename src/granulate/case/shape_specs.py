"""Case-file shapes: one spec per granulate.shapes class, made into the shape by `make`."""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated, Literal

from pydantic import Field

from granulate import meshes, shapes
from granulate.case.spec_types import Finite, Positive, Spec
from granulate.input_errors import NOT_BOOL

if TYPE_CHECKING:
    from granulate.case.builder import CaseContext


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


for _model in list(globals().values()):
    if isinstance(_model, type) and issubclass(_model, Spec) and _model is not Spec:
        _model.model_rebuild()
