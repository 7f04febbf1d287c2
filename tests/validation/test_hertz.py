"""Hertz's law emerges from resolved elastic grains (DESIGN.md section 6): a sphere squeezed
slowly between two rigid plates carries F = 4/3 E* sqrt(R) d^1.5 at each contact (E* = E / (1 -
nu^2) against a rigid plane, d the approach of one contact), once the contact layer is stiff
against the grain (see ARCHITECTURE.md, "Choosing kn")."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import granulate as gr

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "docs" / "validation"))
import normal_impact

E, NU, RADIUS = 3e7, 0.25, 1e-3


def squeeze(nodes_across_radius: int, stiffness_factor: float, approach: float) -> float:
    """Force on the plates over Hertz's at a plate approach of 2 d (d = approach x R per
    contact), reached at 0.2 m/s from first touch (the sphere touches both plates at t = 0).
    That is slow enough to be static: the sphere's wave crosses it about 90 times on the way,
    and at 0.05 m/s the ratios differ by under 0.002."""
    speed = 0.2
    sim = gr.Simulation(3)
    sim.contact = gr.Contact(restitution=1.0, stiffness_factor=stiffness_factor)
    grain = gr.Material(density=1200, youngs_modulus=E, poisson_ratio=NU, fracture=False)
    sim.add_body(
        gr.Sphere((0, RADIUS, 0), RADIUS),
        grain,
        RADIUS / nodes_across_radius,
        discretization="conforming",
    )
    sim.add_wall(gr.Plane((0, 0, 0), (0, 1, 0)), name="floor")
    top = gr.Plane((0, 2 * RADIUS, 0), (0, -1, 0))
    sim.add_wall(gr.Wall((top,), motion=gr.Translation((0, -1, 0), gr.Linear(speed))), name="top")
    d = approach * RADIUS
    sim.run(until=2 * d / speed)
    reactions = sim.wall_reactions()
    force = 0.5 * (reactions["top"][1] - reactions["floor"][1])
    hertz = 4 / 3 * E / (1 - NU**2) * np.sqrt(RADIUS) * d**1.5
    return float(force / hertz)


@pytest.mark.validation
def test_sphere_between_plates_follows_hertz(full: bool) -> None:
    """stiffness_factor 100: at d = 0.11 R the contact is 2 h (R/h = 6) or 2.65 h (R/h = 8,
    --full) in radius, and the force is Hertz's within 10 % (measured 0.949 and 0.991; at
    d = 0.1 R 0.932 and 0.968; at 0.05 m/s 0.950 and 0.988, and at d = 0.1 R 0.931 and 0.971).
    The default kn (factor 1) is far softer than the grain: 0.077 of Hertz's force at R/h = 8,
    0.49 with factor 10."""
    ratio = squeeze(8 if full else 6, 100.0, 0.11)
    assert ratio == pytest.approx(1.0, abs=0.10)


@pytest.mark.validation
def test_elastic_impact_on_a_plane_follows_hertz() -> None:
    """Chung & Ooi (2011) test 2 analogue (docs/validation/normal_impact.py draws the force
    against time): a sphere (R/h = 8, stiffness_factor 100) hits a rigid plane at 5 m/s
    (contact radius 2.6 h at the peak). Measured against Hertz: contact duration 0.943, peak
    force 1.094 (the grain's vibrations ripple the force; 1.055 / 1.114 at 2 / 10 m/s), e =
    0.997. Asserted: duration within 10 %, peak force within 15 %, e > 0.98."""
    run = normal_impact.simulate(8, 5.0)
    theory = normal_impact.hertz(run["mass"], 5.0)
    assert run["duration"] / theory["duration"] == pytest.approx(1.0, abs=0.10)
    assert run["peak"] / theory["peak"] == pytest.approx(1.0, abs=0.15)
    assert run["restitution"] > 0.98


@pytest.mark.validation
def test_elastic_impact_of_two_spheres_follows_hertz() -> None:
    """Chung & Ooi (2011) test 1 analogue (docs/validation/normal_impact.py draws the force
    against time): two equal spheres (R/h = 8, stiffness_factor 100) meet head-on at 5 m/s
    (contact radius 2.0 h at the peak; Hertz with R* = R/2, E* = E / (2 (1 - nu^2)), m* = m/2).
    Measured against Hertz: contact duration 0.964, peak force 1.119 (1.032 / 1.135 at 2 / 10
    m/s), e = 0.997. Asserted: duration within 10 %, peak force within 15 %, e > 0.98."""
    run = normal_impact.simulate_pair(8, 5.0)
    theory = normal_impact.hertz(run["mass"], 5.0, pair=True)
    assert run["duration"] / theory["duration"] == pytest.approx(1.0, abs=0.10)
    assert run["peak"] / theory["peak"] == pytest.approx(1.0, abs=0.15)
    assert run["restitution"] > 0.98


def disc_contact_half_width(
    nodes_across_radius: int, stiffness_factor: float, approach: float, pair_law: str
):
    """A conforming disc (plane strain) squeezed between two rigid plates at 0.05 m/s to a plate
    approach of 2 d (d = approach x R per contact): the contact half-width measured from the
    contact forces f_i on the nodes of the disc's lower half (net force less bond force:
    the floor's traction as the nodes carry it, whichever law), a = 2 sqrt(sum f x^2 / sum f)
    (Hertz's pressure p0 sqrt(1 - x^2/a^2) has second moment a^2/4), and Hertz's
    a = sqrt(4 P R / (pi E*)) for the measured load P per unit length, E* = E / (1 - nu^2)."""
    speed = 0.05
    h = RADIUS / nodes_across_radius
    sim = gr.Simulation(2)
    sim.contact = gr.Contact(restitution=1.0, stiffness_factor=stiffness_factor, pair_law=pair_law)
    grain = gr.Material(density=1200, youngs_modulus=E, poisson_ratio=NU, fracture=False)
    sim.add_body(gr.Disc((0, RADIUS), RADIUS), grain, h, discretization="conforming")
    sim.add_wall(gr.Plane((0, 0), (0, 1)), name="floor")
    top = gr.Plane((0, 2 * RADIUS), (0, -1))
    sim.add_wall(gr.Wall((top,), motion=gr.Translation((0, -1), gr.Linear(speed))), name="top")
    sim.run(until=2 * approach * RADIUS / speed)
    reactions = sim.wall_reactions()
    load = 0.5 * (reactions["top"][1] - reactions["floor"][1])
    contact = (sim.forces[:, 1] - sim.bond_forces()[:, 1]) * sim.volumes
    lower = sim.positions[:, 1] < RADIUS
    x, f = sim.positions[lower, 0], contact[lower]
    measured = 2 * np.sqrt(np.sum(f * x**2) / np.sum(f))
    return measured, np.sqrt(4 * load * RADIUS / (np.pi * E / (1 - NU**2)))


@pytest.mark.validation
@pytest.mark.parametrize(
    "pair_law", [pytest.param("granulate", marks=pytest.mark.full_only), "surface"]
)
def test_disc_between_plates_follows_hertz(pair_law: str) -> None:
    """2D: the contact of a disc on a plate widens as Hertz's line contact does. R/h = 10,
    stiffness_factor 100, at d = 0.06 R and 0.08 R (a = 2.1 h and 2.6 h, 5 and 6 nodes):
    measured a / Hertz 1.010 and 1.001 on the node spheres (R/h = 20: 1.007, 0.984 at a =
    4.3 h and 5.2 h, from the node springs' overlaps), 0.993 and 1.020 under the surface law.
    With the default kn the soft contact layer spreads the load: 2.2 times Hertz's width at
    R/h = 20. The node spheres' variant runs under --full only."""
    for approach in (0.06, 0.08):
        measured, hertz = disc_contact_half_width(10, 100.0, approach, pair_law)
        assert measured / hertz == pytest.approx(1.0, abs=0.10), approach
