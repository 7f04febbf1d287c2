"""Contact and wall set-up: defaults, per-pair settings, wall motion and reactions, errors."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest

import granulate as gr

SOFT = gr.Material(density=1200, bulk_modulus=2.16e7, shear_modulus=1.296e7, fracture=False)


def two_discs(contact: gr.Contact | None) -> gr.Simulation:
    sim = gr.Simulation(2)
    sim.contact = contact
    sim.add_body(gr.Disc((0, 0), 1e-3), SOFT, 0.2e-3, velocity=(0.5, 0))
    sim.add_body(gr.Disc((2.4e-3, 0), 1e-3), SOFT, 0.2e-3, velocity=(-0.5, 0))
    return sim


def test_without_contact_particles_pass_through_each_other() -> None:
    sim = two_discs(None)
    sim.run(until=6e-3)
    first, second = sim.bodies
    assert sim.positions[first.nodes, 0].mean() > sim.positions[second.nodes, 0].mean()


def test_contact_keeps_particles_apart() -> None:
    sim = two_discs(gr.Contact())
    sim.run(until=6e-3)
    first, second = sim.bodies
    assert sim.positions[first.nodes, 0].max() < sim.positions[second.nodes, 0].min()
    assert sim.core.contact_statistics.rebuilds >= 2


def test_gravity_can_be_given_to_the_constructor() -> None:
    sim = gr.Simulation(2, gravity=(0, -9.81))
    np.testing.assert_array_equal(sim.gravity, (0, -9.81, 0))


def test_per_pair_contact_overrides_the_default() -> None:
    other = gr.Material(density=1200, bulk_modulus=2.16e7, shear_modulus=1.296e7, fracture=False)
    sim = gr.Simulation(2)
    sim.contact = gr.Contact()
    sim.set_contact(SOFT, other, None)
    sim.add_body(gr.Disc((0, 0), 1e-3), SOFT, 0.2e-3, velocity=(0.5, 0))
    sim.add_body(gr.Disc((2.4e-3, 0), 1e-3), other, 0.2e-3, velocity=(-0.5, 0))
    sim.run(until=6e-3)
    first, second = sim.bodies
    assert sim.positions[first.nodes, 0].mean() > sim.positions[second.nodes, 0].mean()


def test_translating_wall_pushes_and_reports_its_reaction(tmp_path: Path) -> None:
    """A piston moving down onto a disc resting on the floor: both walls see the load."""
    sim = gr.Simulation(2, gravity=(0, -9.81), viscous_damping=50.0)
    sim.contact = gr.Contact(restitution=0.5)
    sim.add_body(gr.Disc((0, 1.3e-3), 1e-3), SOFT, 0.2e-3)
    sim.add_wall(gr.Plane((0, 0), (0, 1)), name="floor")
    piston = gr.Wall(
        (gr.Plane((0, 2.6e-3), (0, -1)),), motion=gr.Translation((0, -1), gr.Linear(0.02))
    )
    sim.add_wall(piston, name="piston")
    sim.output(tmp_path, every=500)
    sim.run(until=0.03)
    reactions = sim.wall_reactions()
    assert reactions["piston"][1] > 0 > reactions["floor"][1]  # pushed up, pushed down
    with (tmp_path / "history.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert {"floor_fx", "floor_fy", "floor_tz", "piston_fy", "piston_displacement"} <= set(rows[0])
    assert float(rows[-1]["piston_displacement"]) == pytest.approx(0.02 * float(rows[-1]["time"]))


@pytest.mark.parametrize(
    ("build", "message"),
    [
        (lambda: gr.Contact(restitution=0.0), "restitution"),
        (lambda: gr.Contact(restitution=1.2), "restitution"),
        (lambda: gr.Contact(friction=-0.1), "friction"),
        (lambda: gr.Contact(contact_radius_factor=0.0), "contact_radius_factor"),
        (lambda: gr.Contact(normal_stiffness=-1.0), "normal_stiffness"),
    ],
)
def test_bad_contact_parameters(build, message: str) -> None:
    with pytest.raises(gr.InputError, match=message):
        build()


def test_bad_walls_are_refused() -> None:
    sim = gr.Simulation(2)
    sim.add_wall(gr.Plane((0, 0), (0, 1)), name="floor")
    with pytest.raises(gr.InputError, match="exists already"):
        sim.add_wall(gr.Plane((0, 1), (0, -1)), name="floor")
    with pytest.raises(gr.InputError, match="letters, digits"):
        sim.add_wall(gr.Plane((0, 1), (0, -1)), name="top wall")
    with pytest.raises(gr.InputError, match="at least 3"):
        sim.add_wall(gr.PolygonContainer(((0, 0), (1, 1))))
    with pytest.raises(gr.InputError, match="Translation or a Rotation"):
        sim.add_wall(gr.Wall((gr.Plane((0, 0), (0, 1)),), motion="up"))  # type: ignore[arg-type]
    bad_normal = gr.Simulation(2)
    bad_normal.add_body(gr.Disc((0, 1e-3), 1e-3), SOFT, 0.25e-3)
    bad_normal.add_wall(gr.Plane((0, 0), (0, 0)))
    with pytest.raises(gr.InputError, match="non-zero vector"):
        bad_normal.run(1)


def test_break_bonds_refuses_unbonded_pairs_and_the_state_view_is_read_only() -> None:
    sim = gr.Simulation(2)
    sim.add_body(gr.Rectangle((0, 0), (4e-3, 1e-3)), SOFT, 0.25e-3)
    with pytest.raises(gr.InputError, match="are not bonded"):
        sim.core.break_bonds(np.array([[0, sim.node_count - 1]], dtype=np.uint32))
    with pytest.raises(ValueError, match="read-only"):
        sim.core.bond_intact[0] = 0
    assert sim.precrack((2e-3, 0), (1, 0), region=gr.Rectangle((1e-3, -1), (3e-3, 0.5e-3))) > 0
    assert len(sim.fragments()) == 1  # a partial crack leaves the block in one piece
