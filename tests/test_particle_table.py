"""The particle table's motion columns (granulate.particle_table.motion, summed run by run:
run_sums.py): a rigid body's centre, velocity and angular velocity come back as they were
given, and its radius of gyration as its shape has it."""

from __future__ import annotations

import numpy as np
import pytest

from granulate import particle_table
from granulate.errors import InputError


def _rigid_motion(
    points: np.ndarray, velocity: np.ndarray, spin: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Node masses (uneven) and velocities v = V + w x (x - c) of a rigid body."""
    rng = np.random.default_rng(3)
    mass = 1e-6 * (1 + rng.random(len(points)))
    centre = (mass[:, None] * points).sum(axis=0) / mass.sum()
    return mass, velocity + np.cross(spin, points - centre)


def test_a_rigid_body_in_3d_gives_back_its_motion() -> None:
    """Nodes of a 6 x 5 x 4 lattice block, off the origin, turning about a tilted axis while
    it moves: centre, velocity and angular velocity to 1e-12 of their size."""
    axes = [np.arange(n) * 1e-3 for n in (6, 5, 4)]
    lattice = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    points = lattice + np.array([0.2, -0.1, 3.0])
    velocity, spin = np.array([0.3, -1.2, 0.5]), np.array([40.0, -15.0, 25.0])
    mass, v = _rigid_motion(points, velocity, spin)
    table = particle_table.motion(
        np.zeros(len(points)), np.arange(len(points)), mass, mass, points, v, 1
    )
    centre = (mass[:, None] * points).sum(axis=0) / mass.sum()
    np.testing.assert_allclose([table[a][0] for a in "xyz"], centre, rtol=1e-12)
    np.testing.assert_allclose([table["v" + a][0] for a in "xyz"], velocity, rtol=1e-12)
    np.testing.assert_allclose([table["w" + a][0] for a in "xyz"], spin, rtol=1e-12)
    assert table["mass"][0] == pytest.approx(mass.sum(), rel=1e-15)


def test_bodies_in_a_plane_turn_about_z_and_a_ring_has_its_radius_of_gyration() -> None:
    """Two particles in z = 0, numbered interleaved: a ring of 64 equal nodes of radius 2 mm
    (gyration radius 2 mm) spinning at -30 rad/s, and a single node (no rotation: 0)."""
    angle = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    ring = np.column_stack([2e-3 * np.cos(angle) + 0.5, 2e-3 * np.sin(angle), np.zeros(64)])
    spin = np.array([0.0, 0.0, -30.0])
    v = np.array([1.0, 2.0, 0.0]) + np.cross(spin, ring - ring.mean(axis=0))
    points = np.vstack([ring, [[9.0, 9.0, 0.0]]])
    velocities = np.vstack([v, [[0.5, 0.0, 0.0]]])
    owner = np.array([0] * 64 + [1], np.uint32)
    order = np.argsort(np.r_[np.arange(64) * 2, 7], kind="stable")  # the lone node among them
    table = particle_table.motion(
        owner[order], np.arange(65), *[np.full(65, 1e-6)] * 2, points[order], velocities[order], 2
    )
    assert table["wz"][0] == pytest.approx(-30.0, rel=1e-12)
    assert table["wx"][0] == table["wy"][0] == 0.0
    assert table["gyration_radius"][0] == pytest.approx(2e-3, rel=1e-12)
    assert (table["wz"][1], table["gyration_radius"][1], table["vx"][1]) == (0.0, 0.0, 0.5)


def test_a_node_of_a_particle_past_the_count_is_refused() -> None:
    with pytest.raises(InputError, match="past count"):
        particle_table.motion(
            np.array([0, 2]),
            np.arange(2),
            np.ones(2),
            np.ones(2),
            np.zeros((2, 3)),
            np.zeros((2, 3)),
            2,
        )
