"""What distributed runs will rest on (docs/parallel.md, issue 17): a grain's motion is a
function of the grains within reach and of nothing else, bit for bit. A rank that holds a grain
and, as ghosts, the grains near it, in the serial run's order and at the serial run's time step,
then computes that grain's steps exactly as the serial run does.

An assembly of grains pressed into each other and thrown at each other (so springs, dashpots,
friction and the surface law's probes all act from the first step) is run whole and cut down to
one grain and its neighbours; the grain's nodes must agree bit for bit. The forces at the end
of step s depend on the neighbours' positions then, which depend on their neighbours' forces a
step before, and so on: s + 1 hops from grain to touching grain, so the cut keeps the grains
within (s + 1) x 2.1 radii of the grain's centre (the lattices' spacing is 1.9)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import granulate as gr
from test_checkpoint import tumbling_drum

RADIUS = 1e-3
ROCK = gr.Material(
    density=1200, bulk_modulus=2.16e7, shear_modulus=1.296e7, fracture_energy=50, horizon=0.6e-3
)


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


@pytest.mark.filterwarnings("ignore:contact.*bodies pressed")  # placed pressed, on purpose
@pytest.mark.parametrize(("dimension", "steps"), [(2, 1), (2, 3), (3, 1)])
def test_a_grain_moves_as_its_neighbourhood_says_bit_for_bit(dimension: int, steps: int) -> None:
    centres, _ = layout(dimension)
    everything = np.arange(len(centres))
    whole = assembly(dimension, everything)
    middle = int(np.argmin(np.linalg.norm(centres - centres.mean(axis=0), axis=1)))
    reach = (steps + 1) * 2.1 * RADIUS
    near = np.flatnonzero(np.linalg.norm(centres - centres[middle], axis=1) < reach)
    assert 1 < len(near) < len(centres)  # a real cut
    part = assembly(dimension, near, dt=whole.dt)
    whole.run(steps)
    part.run(steps)
    a, b = whole.bodies[middle], part.bodies[int(np.flatnonzero(near == middle)[0])]
    nodes = slice(a.first_node, a.first_node + a.node_count)
    pushed = np.abs(whole.forces[nodes] - whole.bond_forces()[nodes]).max()
    assert pushed > 1e-3 * np.abs(whole.forces[nodes]).max()  # the grain is in contact
    for field in ("positions", "velocities", "forces"):
        ours = getattr(whole, field)[a.first_node : a.first_node + a.node_count]
        theirs = getattr(part, field)[b.first_node : b.first_node + b.node_count]
        np.testing.assert_array_equal(ours, theirs, err_msg=field)


# The shattered square's fragments hit hard enough to pass half the contact radius (warned).
@pytest.mark.filterwarnings("ignore:contact.*bodies pressed")
@pytest.mark.parametrize("fracture", [True, False])
def test_a_ghost_grain_needs_only_its_owners_motion(fracture: bool, tmp_path: Path) -> None:
    """A rank skips its ghosts' bond forces (core.set_ghost_particles), which its exchange
    overwrites. The tumbling drum run twice, once with grain 1 a ghost whose positions,
    velocities and forces are overwritten from the whole run after every step: the other
    grains' nodes agree bit for bit through 900 steps of contact and breaking, and so do all
    the bonds (a ghost that can break breaks as its owner's copy does: its fragments enter its
    partners' contact). The ghost's own forces are not computed: they differ before each
    overwrite while it is in contact, and an unbreakable ghost's dilatation is not summed."""
    whole = tumbling_drum(tmp_path / "whole", fracture=fracture)
    part = tumbling_drum(tmp_path / "part", fracture=fracture)
    whole.core.run(0)
    part.core.set_ghost_particles([1])
    part.core.run(0)
    ghost = part.bodies[1].node_slice
    others = np.ones(part.core.positions.shape[0], dtype=bool)
    others[ghost] = False
    differed = 0
    for _ in range(900):
        whole.core.run(1)
        part.core.run(1)
        for field in ("positions", "velocities", "forces"):
            ours, theirs = getattr(whole.core, field), getattr(part.core, field)
            np.testing.assert_array_equal(ours[others], theirs[others], err_msg=field)
        differed += int(not np.array_equal(whole.core.forces[ghost], part.core.forces[ghost]))
        for field in ("positions", "velocities", "forces"):
            getattr(part.core, field)[ghost] = getattr(whole.core, field)[ghost]
    assert differed == 900
    np.testing.assert_array_equal(whole.core.bond_intact, part.core.bond_intact)
    bonds = np.asarray(whole.model.bond_offsets)[[ghost.start, ghost.stop]]
    broken_in_ghost = np.count_nonzero(np.asarray(whole.core.bond_intact)[slice(*bonds)] == 0)
    assert (broken_in_ghost > 20) if fracture else (broken_in_ghost == 0)
    ghost_dilatation = np.abs(np.asarray(part.core.dilatation)[ghost]).max()
    assert (ghost_dilatation > 0) if fracture else (ghost_dilatation == 0)
    assert np.abs(np.asarray(whole.core.dilatation)[ghost]).max() > 0
    with pytest.raises(gr.InputError, match="ghost particle 4 does not exist"):
        part.core.set_ghost_particles([4])


def test_the_core_measures_how_far_the_nodes_travelled(tmp_path: Path) -> None:
    """core.largest_travel (a rank's check that its ghosts still hold): after each step, the
    largest distance of a node from where it was at set_travel_origin [m], as NumPy finds it;
    0 before the first step and with no origin set."""
    sim = tumbling_drum(tmp_path)
    sim.core.run(100)
    assert sim.core.largest_travel == 0.0
    origin = sim.core.positions.copy()
    sim.core.set_travel_origin()
    assert sim.core.largest_travel == 0.0
    for _ in range(5):
        sim.core.run(40)
        moved = np.linalg.norm(sim.core.positions - origin, axis=1).max()
        assert sim.core.largest_travel == pytest.approx(moved, rel=1e-14)
    assert sim.core.largest_travel > 1e-4  # the grains fall and tumble
