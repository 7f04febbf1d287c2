"""granulate: granular media of deformable, breakable particles.

Peridynamics inside each particle (LPS or PMB, with fracture), velocity-Verlet time stepping in
a C++ core (OpenMP), set-up and output from Python.

    >>> import granulate as gr
    >>> rock = gr.Material(density=2600, youngs_modulus=50e9, poisson_ratio=0.25,
    ...                    fracture_energy=40.0)
    >>> sim = gr.Simulation(dimension=2)
    >>> body = sim.add_body(gr.Rectangle((0, 0), (0.05, 0.01)), rock, mesh_size=1e-3)
"""

from granulate import _core, fragments, stopping, threads, walls
from granulate._version import __version__
from granulate.contact import Contact
from granulate.errors import GranulateWarning, InputError, InstabilityError
from granulate.functions import (
    Constant,
    Linear,
    Quadratic,
    Sine,
    SmoothRamp,
    TimeFunction,
    VelocityRamp,
)
from granulate.load_balance import LoadBalance
from granulate.materials import Material
from granulate.meshes import SurfaceMesh, read_mesh
from granulate.packing import (
    Grain,
    Packing,
    Placements,
    pack,
    read_placements,
)
from granulate.reference_shapes import ReferenceShape
from granulate.results import Frame, Results
from granulate.shapes import (
    Box,
    Cylinder,
    Difference,
    Disc,
    Drum2D,
    Ellipse,
    Ellipsoid,
    Polygon,
    Rectangle,
    RegularPolygon,
    Shape,
    Sphere,
    Star,
    Union,
    conforming,
    lattice,
)
from granulate.simulation import FIELDS, Body, Progress, Simulation
from granulate.size_distributions import Fixed, LogNormal, Normal, Sieve, Uniform
from granulate.threads import get_num_threads, set_num_threads
from granulate.walls import (
    BoxContainer,
    BoxObstacle,
    CircleContainer,
    CircleObstacle,
    Plane,
    PolygonContainer,
    PolygonObstacle,
    Rotation,
    Translation,
    TriangleMesh,
    Wall,
)

if threads.is_adaptive():  # no OMP_NUM_THREADS: as many as the CPUs this process may use
    _core.set_num_threads(threads.available_cpus())


__all__ = [
    "FIELDS",
    "Body",
    "Box",
    "BoxContainer",
    "BoxObstacle",
    "CircleContainer",
    "CircleObstacle",
    "Constant",
    "Contact",
    "Cylinder",
    "Difference",
    "Disc",
    "Drum2D",
    "Ellipse",
    "Ellipsoid",
    "Fixed",
    "Frame",
    "Grain",
    "GranulateWarning",
    "InputError",
    "InstabilityError",
    "Linear",
    "LoadBalance",
    "LogNormal",
    "Material",
    "Normal",
    "Packing",
    "Placements",
    "Plane",
    "Polygon",
    "PolygonContainer",
    "PolygonObstacle",
    "Progress",
    "Quadratic",
    "Rectangle",
    "ReferenceShape",
    "RegularPolygon",
    "Results",
    "Rotation",
    "Shape",
    "Sieve",
    "Simulation",
    "Sine",
    "SmoothRamp",
    "Sphere",
    "Star",
    "SurfaceMesh",
    "TimeFunction",
    "Translation",
    "TriangleMesh",
    "Uniform",
    "Union",
    "VelocityRamp",
    "Wall",
    "__version__",
    "conforming",
    "fragments",
    "get_num_threads",
    "lattice",
    "pack",
    "read_mesh",
    "read_placements",
    "set_num_threads",
    "stopping",
    "walls",
]
