"""Prescribed motion, rotation, body force, force densities and initial velocities."""

from __future__ import annotations

import numpy as np
import pytest

import granulate as gr

STEEL = gr.Material(density=7800, youngs_modulus=200e9, poisson_ratio=0.3, fracture=False)


def square(dimension: int = 2) -> gr.Simulation:
    sim = gr.Simulation(dimension)
    shape = (
        gr.Rectangle((0, 0), (0.01, 0.01)) if dimension == 2 else gr.Box((0, 0, 0), (0.006,) * 3)
    )
    sim.add_body(shape, STEEL, 1e-3)
    return sim


@pytest.mark.parametrize(
    "function",
    [
        gr.Linear(0.3),
        gr.Quadratic(0.1, 50.0),
        gr.Sine(1e-4, 2000.0),
        gr.SmoothRamp(1e-5, 2e-6),
        gr.VelocityRamp(0.2, 1e-6),
    ],
)
def test_prescribed_displacement_follows_its_time_function(function: gr.TimeFunction) -> None:
    sim = square()
    nodes = sim.select(gr.Rectangle((0.008, -1), (1, 1)))
    sim.prescribe_displacement(nodes, (0.6, 0.8), function)
    sim.run(50)
    u = sim.displacements[nodes]
    expected = function.at(sim.time)
    np.testing.assert_allclose(u[:, 0], 0.6 * expected, rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(u[:, 1], 0.8 * expected, rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(
        sim.velocities[nodes, 0], 0.6 * function.rate_at(sim.time), rtol=1e-12, atol=1e-15
    )


def test_fix_single_component_leaves_the_other_free() -> None:
    sim = square()
    nodes = sim.select(gr.Rectangle((-1, -1), (0.002, 1)))
    sim.fix(nodes, components="x")
    sim.gravity = (0, -9.81)
    sim.run(200)
    assert np.all(sim.displacements[nodes, 0] == 0)
    assert np.all(sim.displacements[nodes, 1] < 0)
    assert np.all(sim.core.fixity()[nodes] == 1)


def test_free_body_falls_with_gravity() -> None:
    """Momentum: with gravity only, the centre of mass moves as g t^2 / 2 (to round-off)."""
    for dimension in (2, 3):
        sim = square(dimension)
        g = np.array([0.0, -9.81, 0.0])
        sim.gravity = g[:dimension]
        sim.run(300)
        displacement = np.average(sim.displacements, axis=0, weights=sim.volumes)
        expected = 0.5 * g * sim.time**2
        # Round-off of the internal forces (zero in exact arithmetic) moves x by ~1e-18 m.
        np.testing.assert_allclose(
            displacement, expected, rtol=1e-9, atol=1e-9 * np.abs(expected).max()
        )


def test_force_density_accelerates_the_body() -> None:
    sim = square()
    b = np.array([1e6, -2e6, 0.0])  # N/m^3
    sim.add_force_density(sim.select(body=sim.bodies[0]), b[:2], gr.Constant(1.0))
    sim.run(100)
    velocity = np.average(sim.velocities, axis=0, weights=sim.volumes)
    np.testing.assert_allclose(velocity, b / 7800 * sim.time, rtol=1e-9)


def test_rigid_rotation_about_a_point() -> None:
    sim = square()
    everything = sim.select(body=sim.bodies[0])
    omega = 100.0  # rad/s
    sim.prescribe_rotation(everything, (0.005, 0.005), gr.Linear(omega))
    sim.run(100)
    X = sim.reference_positions - (0.005, 0.005, 0)
    angle = omega * sim.time
    rotated = np.column_stack(
        [
            X[:, 0] * np.cos(angle) - X[:, 1] * np.sin(angle),
            X[:, 0] * np.sin(angle) + X[:, 1] * np.cos(angle),
        ]
    )
    np.testing.assert_allclose(sim.positions[:, :2] - (0.005, 0.005), rotated, atol=1e-15)
    # Rigid motion strains nothing: forces are round-off, below those of a 1e-12 strain (E eps / h).
    assert np.abs(sim.forces).max() < 200e9 * 1e-12 / 1e-3


def test_initial_velocity_and_spin() -> None:
    sim = gr.Simulation(2)
    body = sim.add_body(
        gr.Disc((0, 0), 0.005), STEEL, 0.5e-3, velocity=(1.0, 2.0), angular_velocity=30.0
    )
    v = sim.velocities
    X = sim.reference_positions
    np.testing.assert_allclose(
        np.average(v, axis=0, weights=sim.volumes)[:2], (1.0, 2.0), atol=1e-12
    )
    np.testing.assert_allclose(v[:, 0] - 1.0, -30.0 * X[:, 1], atol=1e-12)
    assert body.node_count == sim.node_count


def test_two_bodies_with_different_materials_are_independent() -> None:
    """No global state: each body behaves bit for bit as if it were alone (no contact yet).
    The two rectangles differ in height: a translated copy would share the first one's bonds
    (shape_sharing.py) and match its lone self to round-off only."""
    soft = gr.Material(
        density=1000, bulk_modulus=1e8, shear_modulus=5e7, fracture_energy=5.0, influence="constant"
    )
    hard = gr.Material(
        density=3000, bulk_modulus=5e9, shear_modulus=3e9, fracture_energy=50.0, model="pmb"
    )
    bodies = {"soft": (soft, 0.0, 2.0, 0.01), "hard": (hard, 0.05, 3.0, 0.008)}

    def build(names: list[str]) -> gr.Simulation:
        sim = gr.Simulation(2, dt=2e-8)
        for name in names:
            material, x0, speed, height = bodies[name]
            body = sim.add_body(gr.Rectangle((x0, 0), (x0 + 0.01, height)), material, 1e-3)
            sim.prescribe_velocity(
                sim.select(gr.Rectangle((x0 + 0.008, -1), (x0 + 1, 1)), body=body), (speed, 0)
            )
            sim.fix(sim.select(gr.Rectangle((x0 - 1, -1), (x0 + 0.002, 1)), body=body))
        sim.run(300)
        return sim

    together = build(["soft", "hard"])
    alone_soft, alone_hard = build(["soft"]), build(["hard"])
    n = alone_soft.node_count
    assert alone_soft.broken_bonds() > 0 and alone_hard.broken_bonds() > 0
    np.testing.assert_array_equal(together.positions[:n], alone_soft.positions)
    np.testing.assert_array_equal(together.positions[n:], alone_hard.positions)
    np.testing.assert_array_equal(
        together.damage, np.concatenate([alone_soft.damage, alone_hard.damage])
    )


def test_loading_errors_are_clear() -> None:
    sim = square()
    with pytest.raises(gr.InputError, match="no node"):
        sim.select(gr.Rectangle((1, 1), (2, 2)))
    with pytest.raises(gr.InputError, match="component 'z'"):
        sim.fix(sim.select(body=sim.bodies[0]), components="z")
    with pytest.raises(gr.InputError, match="node ids"):
        sim.fix([10_000])
    with pytest.raises(gr.InputError, match="ramp time"):
        sim.prescribe_displacement([0], (1, 0), gr.SmoothRamp(1.0, 0.0))
        sim.run(1)
