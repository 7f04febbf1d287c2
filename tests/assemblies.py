"""The set-ups that test modules and the MPI scripts (tests/mpi_*.py, run under mpiexec)
share: the tumbling drum, the locality assembly and the pulled notched bodies. Kept apart from
the test modules so that a rank's start imports no pytest (0.1 CPU-s of each of the hundred or
so rank processes the suite starts)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import granulate as gr


def tumbling_drum(
    out: Path,
    *,
    resume: bool = False,
    grid: bool = False,
    law: str = "granulate",
    rolling: float = 0.0,
    comm: object | None = None,
    fracture: bool = True,
    outputs: bool = True,
) -> gr.Simulation:
    """Grains breaking in a rotating drum: contact, friction, damping, walls and fracture.
    ``grid``: the fourth grain is a brittle grid-meshed square instead of a lattice triangle:
    its surface nodes have their contact spheres centred inside them (surface anchors), and
    they lose them as its bonds break (it is damaged all through by step 2,000). ``law``: the
    contact's pair_law ("surface": probes of the grains' smooth surfaces, with their groups
    and the nodes opened by cracks joining the lists). ``rolling``: mu_r, the rolling
    resistance (its springs carried through the checkpoint). ``comm``: run it on MPI ranks
    (tests/mpi_check.py). ``fracture``: False makes the grains unbreakable. ``outputs``: False
    plans no outputs or checkpoints."""
    rock = gr.Material(
        density=2000, youngs_modulus=1e8, poisson_ratio=0.25, fracture_energy=0.5, fracture=fracture
    )
    sim = gr.Simulation(2, gravity=(0, -9.81), comm=comm)
    sim.contact = gr.Contact(restitution=0.5, friction=0.4, pair_law=law, rolling_friction=rolling)
    for k, (x, y) in enumerate([(-3e-3, -2e-3), (0, -4e-3), (3e-3, -2e-3), (0, 0)]):
        velocity = (0.2 * k - 0.3, -4.0)
        if k == 3 and grid:
            square = gr.Rectangle((-1e-3, -1e-3), (1e-3, 1e-3))
            brittle = rock.model_copy(update={"fracture_energy": 0.07})
            sim.add_body(square, brittle, 0.3e-3, velocity=velocity, discretization="grid")
            continue
        shape = (
            gr.Disc((x, y), 1.2e-3)
            if k < 3
            else gr.Polygon(((-1e-3, -1e-3), (1.2e-3, -1e-3), (0, 1.3e-3)))
        )
        sim.add_body(shape, rock, 0.3e-3, velocity=velocity)
    lifter = gr.PolygonObstacle(((-1e-3, -7.5e-3), (1e-3, -7.5e-3), (0, -5.5e-3)))
    drum = gr.Wall((gr.CircleContainer((0, 0), 7e-3), lifter), motion=gr.Rotation.steady(30.0))
    sim.add_wall(drum, name="drum")
    if outputs:
        sim.output(out, every=250, overwrite=not resume, resume=resume)
        sim.checkpoint_every(1000)
    return sim


RADIUS = 1e-3


def rock(horizon: float, fracture_energy: float = 50) -> gr.Material:
    """The grains' material (a soft rock), with this horizon [m] and fracture energy [J/m^2]."""
    return gr.Material(
        density=1200,
        bulk_modulus=2.16e7,
        shear_modulus=1.296e7,
        fracture_energy=fracture_energy,
        horizon=horizon,
    )


ROCK = rock(0.6e-3)


def layout(dimension: int) -> tuple[np.ndarray, np.ndarray]:
    """Centres on a hexagonal (2D) or cubic (3D) lattice 1.9 mm apart, radii 0.98-1 mm (so the
    grains are pressed up to 0.1 mm into each other), and a velocity of up to 0.5 m/s each."""
    rng = np.random.default_rng(7)
    spacing = 1.9 * RADIUS
    if dimension == 2:
        rows, columns = np.meshgrid(np.arange(9), np.arange(10), indexing="ij")
        x = spacing * (columns + 0.5 * (rows % 2))
        y = spacing * np.sqrt(3) / 2 * rows
        centres = np.column_stack([x.ravel(), y.ravel()])
    else:
        grid = np.meshgrid(*(np.arange(5),) * 3, indexing="ij")
        centres = spacing * np.column_stack([g.ravel() for g in grid]).astype(float)
    radii = RADIUS * rng.uniform(0.98, 1.0, len(centres))
    velocities = rng.uniform(-0.5, 0.5, (len(centres), dimension))
    return centres, np.column_stack([radii[:, None], velocities])


def assembly(dimension: int, keep: np.ndarray, dt: float | None = None) -> gr.Simulation:
    """The grains `keep` (in their order) with friction and damping; hexagons among the discs."""
    centres, rows = layout(dimension)
    sim = gr.Simulation(dimension)
    sim.contact = gr.Contact(restitution=0.6, friction=0.5)
    h = RADIUS / 5 if dimension == 2 else RADIUS / 3
    for k in keep:
        radius, velocity = rows[k, 0], rows[k, 1:]
        if dimension == 3:
            shape = gr.Sphere(tuple(centres[k]), radius)
        elif k % 3 == 0:
            shape = gr.RegularPolygon(tuple(centres[k]), radius, 6, angle=0.3 * k)
        else:
            shape = gr.Disc(tuple(centres[k]), radius)
        sim.add_body(shape, ROCK, h, velocity=velocity)
    if dt is not None:
        sim.dt = dt  # the stable estimate is the whole assembly's: a distributed run reduces it
    return sim


RATE = 60.0  # the strain rate [1/s]
GLASS = dict(density=2500, youngs_modulus=70e9, poisson_ratio=0.22, fracture_energy=8.0)


def pulled(shape: str, model: str, comm: object | None = None) -> gr.Simulation:
    """A notched plate or strip (2D, plane stress) or block (3D) of glass stretched along its
    length at the strain rate RATE: each node starts at v = RATE (x - c) along it (c its
    centre) and its ends keep their speed (0.6 m/s for the plate), so it deforms throughout and
    cracks from the notch within a few hundred steps. The strip stands upright, 10 nodes wide
    across the lattice's numbering, so that its nodes gather (each evaluates all its bonds;
    Model.particle_gathers); the plate's and the block's evaluate each bond once. ``comm``: run
    it on MPI ranks (tests/mpi_stop_check.py)."""
    poisson = {"pmb": 1 / 3, "lps": 0.22}[model]  # PMB's own in plane stress
    glass = gr.Material(**{**GLASS, "poisson_ratio": poisson}, model=model)
    axis = 1 if shape == "strip" else 0
    if shape == "plate":
        sim = gr.Simulation(dimension=2, plane="stress", comm=comm)
        notch = gr.Rectangle((9.5e-3, 6e-3), (10.5e-3, 1))
        sim.add_body(
            gr.Difference(gr.Rectangle((0, 0), (0.02, 0.01)), notch), glass, mesh_size=0.4e-3
        )
        ends = gr.Rectangle((-1, -1), (1e-3, 1)), gr.Rectangle((19e-3, -1), (1, 1))
    elif shape == "strip":
        sim = gr.Simulation(dimension=2, plane="stress", comm=comm)
        notch = gr.Rectangle((2.4e-3, 9.5e-3), (1, 10.5e-3))
        sim.add_body(
            gr.Difference(gr.Rectangle((0, 0), (4e-3, 0.02)), notch), glass, mesh_size=0.4e-3
        )
        ends = gr.Rectangle((-1, -1), (1, 1e-3)), gr.Rectangle((-1, 19e-3), (1, 1))
    else:
        sim = gr.Simulation(dimension=3, comm=comm)
        notch = gr.Box((4.7e-3, 3e-3, -1), (5.3e-3, 1, 1))
        sim.add_body(
            gr.Difference(gr.Box((0, 0, 0), (0.01, 5e-3, 3e-3)), notch), glass, mesh_size=0.5e-3
        )
        ends = gr.Box((-1, -1, -1), (0.6e-3, 1, 1)), gr.Box((9.4e-3, -1, -1), (1, 1, 1))
    sim.contact = None
    start = np.asarray(sim.reference_positions)
    x = start[:, axis]
    centre = 0.5 * (x.min() + x.max())
    velocities = np.zeros_like(start)
    velocities[:, axis] = RATE * (x - centre)
    sim.start_from(start, velocities)
    for end in ends:
        nodes = sim.select(end)
        velocity = np.zeros(sim.dimension)
        velocity[axis] = RATE * (x[nodes].mean() - centre)
        sim.prescribe_velocity(nodes, tuple(velocity))
    return sim
