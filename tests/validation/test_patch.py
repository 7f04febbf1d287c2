"""LPS patch test: a homogeneous strain gives zero force at interior nodes and the classical
strain-energy density there (DESIGN.md section 6: within 2 %), in plane strain, plane stress
and 3D; and the body's total strain energy converges to the classical value as h -> 0 at a
fixed horizon ratio (the surface layer of thickness delta shrinks)."""

from __future__ import annotations

import numpy as np
import pytest

import granulate as gr

K, G = 2.0e9, 1.0e9
STRAIN_2D = np.array([[1e-4, 3e-5, 0], [3e-5, -2e-4, 0], [0, 0, 0]])
STRAIN_3D = np.array([[1e-4, 3e-5, -4e-5], [3e-5, -2e-4, 0], [-4e-5, 0, 1.5e-4]])


def classical_energy_density(strain: np.ndarray, dimension: int, plane: str) -> float:
    """W = lambda/2 (tr eps)^2 + mu eps:eps; plane stress: lambda* = 2 lambda mu/(lambda + 2 mu)."""
    lam = K - 2 * G / 3
    if dimension == 2 and plane == "stress":
        lam = 2 * lam * G / (lam + 2 * G)
    return 0.5 * lam * np.trace(strain) ** 2 + G * np.sum(strain * strain)


def strained_block(dimension: int, plane: str, cells: int, depth: int = 2, horizon_factor: int = 3):
    """A square/cube of cells^d nodes under STRAIN; also the mask of nodes at least depth
    horizons inside (2: forces are exactly interior; 1: the energy density already is)."""
    h = 1e-3
    material = gr.Material(
        density=1000, bulk_modulus=K, shear_modulus=G, fracture=False, horizon_factor=horizon_factor
    )
    sim = gr.Simulation(dimension, plane)
    size = cells * h
    shape = gr.Rectangle((0, 0), (size, size)) if dimension == 2 else gr.Box((0, 0, 0), (size,) * 3)
    sim.add_body(shape, material, h)
    strain = STRAIN_2D if dimension == 2 else STRAIN_3D
    X = sim.reference_positions
    centre = X.mean(axis=0)
    sim.positions[:] = centre + (X - centre) @ (np.eye(3) + strain).T
    if dimension == 2:
        sim.positions[:, 2] = 0
    sim.core.compute_forces()
    delta = material.resolved_horizon(h)
    lower, upper = X.min(axis=0), X.max(axis=0)
    d = dimension
    interior = np.all(
        (X[:, :d] - lower[:d] >= depth * delta - 1e-12)
        & (upper[:d] - X[:, :d] >= depth * delta - 1e-12),
        axis=1,
    )
    return sim, strain, interior


CASES = [(2, "strain"), (2, "stress"), (3, "strain")]


@pytest.mark.validation
@pytest.mark.parametrize(("dimension", "plane"), CASES)
def test_patch_interior_forces_vanish_and_energy_is_classical(dimension: int, plane: str) -> None:
    sim, strain, interior = strained_block(dimension, plane, 24 if dimension == 2 else 14)
    assert interior.sum() >= 8
    forces = sim.forces
    # Interior forces are round-off: 1e-9 of the boundary forces (which are ~1e8 N/m^3 here).
    assert np.abs(forces[interior]).max() < 1e-9 * np.abs(forces).max()
    density = sim.core.strain_energy_density()[interior]
    expected = classical_energy_density(strain, dimension, plane)
    error = abs(density.mean() / expected - 1)
    assert error < 0.02, f"interior energy density off by {error:.2%}"
    assert np.ptp(density) < 1e-9 * expected  # homogeneous


@pytest.mark.validation
@pytest.mark.parametrize(("dimension", "plane"), CASES)
def test_patch_surface_error_converges_first_order_in_h(
    dimension: int, plane: str, full: bool
) -> None:
    """At a fixed horizon ratio the interior energy density does not depend on h; what the
    surface layer (thickness delta = 3h) adds to the total energy must vanish like h:
    |E_total / (W_interior V) - 1| falls with a rate of at least 0.8 in h."""
    if dimension == 2:
        cells = [12, 24, 48, 96] if full else [12, 24, 48]
    else:
        cells = [10, 14, 20, 28] if full else [10, 14, 20]
    errors = []
    for n in cells:
        sim, _, interior = strained_block(dimension, plane, n, depth=1)
        interior_density = sim.core.strain_energy_density()[interior].mean()
        errors.append(abs(sim.strain_energy() / (interior_density * sim.volumes.sum()) - 1))
    rates = np.diff(np.log(errors)) / np.diff(np.log(1.0 / np.asarray(cells, dtype=float)))
    assert np.all(rates > 0.8), f"convergence rates {rates} (errors {errors})"


@pytest.mark.validation
@pytest.mark.parametrize(("dimension", "plane"), CASES)
def test_patch_interior_error_shrinks_with_horizon_ratio(dimension: int, plane: str) -> None:
    """m-convergence: the lattice error of the interior energy density is about 5 % at
    delta = 2h, at most 2 % for 3h and 4h, and at most 0.5 % for 5h and 6h."""
    errors = {}
    for m in (2, 3, 4, 5, 6):
        sim, strain, _ = strained_block(dimension, plane, 4 * m + 3, horizon_factor=m)
        X = sim.reference_positions
        middle = np.argmin(np.sum((X - X.mean(axis=0)) ** 2, axis=1))
        density = sim.core.strain_energy_density()[middle]
        errors[m] = abs(density / classical_energy_density(strain, dimension, plane) - 1)
    assert errors[2] > 0.03, errors
    assert max(errors[3], errors[4]) < 0.02, errors
    assert max(errors[5], errors[6]) < 0.005, errors
