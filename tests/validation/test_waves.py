"""Longitudinal vibration of a free-free bar: the first mode's period is T = 2L / c with
c = sqrt(E_bar / rho); E_bar = E in plane stress and 3D, E / (1 - nu^2) in plane strain
(DESIGN.md section 6: within 3 %).

The bar starts with the mode's velocity field v_x = v0 cos(pi x / L); the modal displacement
a(t) = sum_i u_x,i cos(pi X_i / L) V_i follows sin(2 pi t / T), so its first zero after t = 0
is at T/2. In 3D the peridynamic surface layer (thickness delta) stiffens a thin bar by about
0.65 h/W; the smoke test extrapolates T(h) -> h = 0 from two resolutions, --full checks a bar
30 nodes across directly. The 3D bar is 5 widths long: its Pochhammer dispersion,
about 0.026 (W/L)^2, is then 0.1 %.
"""

from __future__ import annotations

import numpy as np
import pytest

import granulate as gr

E, NU, RHO = 1.0e9, 0.25, 1000.0


def first_mode_period(dimension: int, plane: str, length: float, width: float, h: float) -> float:
    material = gr.Material(density=RHO, youngs_modulus=E, poisson_ratio=NU, fracture=False)
    sim = gr.Simulation(dimension, plane)
    shape = (
        gr.Rectangle((0, 0), (length, width))
        if dimension == 2
        else gr.Box((0, 0, 0), (length, width, width))
    )
    sim.add_body(shape, material, h)
    X = sim.reference_positions
    mode = np.cos(np.pi * X[:, 0] / length)
    sim.velocities[:, 0] = 1e-3 * mode
    V = sim.volumes
    previous_time, previous = 0.0, 0.0
    while True:
        sim.run(5)
        amplitude = float(np.sum(sim.displacements[:, 0] * mode * V))
        if previous > 0 and amplitude <= 0:
            crossing = previous_time + previous * (sim.time - previous_time) / (
                previous - amplitude
            )
            return 2 * crossing
        previous_time, previous = sim.time, amplitude
        assert sim.time < 2 * length / np.sqrt(E / RHO), "no zero crossing within a period"


def bar_period(dimension: int, plane: str, length: float) -> float:
    modulus = E / (1 - NU**2) if (dimension == 2 and plane == "strain") else E
    return 2 * length / np.sqrt(modulus / RHO)


@pytest.mark.validation
@pytest.mark.parametrize("plane", ["strain", "stress"])
def test_bar_period_2d(plane: str, full: bool) -> None:
    length, width = 0.1, 0.01
    h = width / (40 if full else 20)
    period = first_mode_period(2, plane, length, width, h)
    error = period / bar_period(2, plane, length) - 1
    assert abs(error) < 0.03, f"period off by {error:.2%}"


@pytest.mark.validation
def test_bar_period_3d(full: bool) -> None:
    length, width = 0.025, 0.005
    expected = bar_period(3, "strain", length)
    if full:
        period = first_mode_period(3, "strain", length, width, width / 30)
        error = period / expected - 1
        assert abs(error) < 0.03, f"period off by {error:.2%}"
        return
    coarse, fine = 8, 10
    t_coarse = first_mode_period(3, "strain", length, width, width / coarse)
    t_fine = first_mode_period(3, "strain", length, width, width / fine)
    # Surface stiffening ~ 1/n: T(n) = T0 (1 - C/n)
    extrapolated = (fine * t_fine - coarse * t_coarse) / (fine - coarse)
    assert abs(t_fine / expected - 1) < abs(t_coarse / expected - 1) < 0.1
    error = extrapolated / expected - 1
    assert abs(error) < 0.03, f"extrapolated period off by {error:.2%}"
