"""Oblique impacts on a plane at constant speed and varying angle, the 2D (3D) analogue of Chung &
Ooi (2011) test 4 (docs/validation/oblique_impact.py draws the whole curve): in gross sliding the
rebound follows the rigid-body impulse theory with Coulomb friction; at small angles the contact
point springs back (tangential elasticity) without gaining energy."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "docs" / "validation"))
import hertz_mindlin
import oblique_impact


@pytest.mark.validation
def test_oblique_impact_in_gross_sliding_follows_the_rigid_body_theory(full: bool) -> None:
    """70 degrees (above the sliding limit, 58.6 degrees for a disc, 61.6 for a sphere):
    v_t' = v_t - mu (1 + e) v_n and omega' R = mu (1 + e) v_n / k within 3 % of v (e measured).
    2D measured: 0.7541 / 0.7536 and 0.3665 / 0.3721 (R/h = 10); the sphere (R/h = 6) with
    --full."""
    speed = oblique_impact.SPEED
    for dimension in (2, 3) if full else (2,):
        row = oblique_impact.impact(dimension, 70.0, 10 if dimension == 2 else 6)
        tangential, spin = oblique_impact.theory(dimension, row["v_n"], row["v_t"], row["e"])
        assert abs(row["v_t_after"] - tangential) < 0.03 * speed, dimension
        assert abs(row["spin_R"] - spin) < 0.03 * speed, dimension
        assert abs(row["e"] - oblique_impact.RESTITUTION) < 0.05, dimension


@pytest.mark.validation
def test_oblique_impact_at_a_small_angle_springs_back_without_gaining_energy() -> None:
    """10 degrees: the contact point sticks, and the friction springs turn its tangential
    velocity back (measured: v_t' - omega' R = -1.00 v_t), keeping, not gaining, the tangential
    and spin energy (measured 1.013 times the energy before; 2 % allowed)."""
    row = oblique_impact.impact(2, 10.0, 10)
    v_t, after, spin = row["v_t"], row["v_t_after"], row["spin_R"]
    assert -1.02 * v_t < after - spin < -0.5 * v_t
    energy_before = v_t**2
    energy_after = after**2 + 0.5 * spin**2  # disc: I = m R^2 / 2
    assert energy_after < 1.02 * energy_before


@pytest.mark.validation
def test_spinning_impact_in_gross_sliding_follows_the_rigid_body_theory() -> None:
    """Chung & Ooi (2011) test 6 analogue (oblique_impact.py --test 6 draws the whole curve): a
    disc (R/h = 10) dropped straight down at 0.5 m/s spinning at omega R = -3 and +3 v_n slides
    all through the impact, and rebounds with v_t' = -sign(u) mu (1 + e) v_n and omega' R =
    omega R + sign(u) mu (1 + e) v_n / k (u = -omega R, the contact point's slip). Measured:
    v_t' / v_n -0.5408 / 0.5418 against -0.5403 / 0.5422, omega' R / v_n -1.9241 / 1.9201
    against -1.9193 / 1.9156. Asserted within 3 % of v_n."""
    speed = oblique_impact.SPEED
    for spin in (-3.0, 3.0):
        row = oblique_impact.impact(2, 0.0, 10, spin=spin * speed)
        tangential, turned = oblique_impact.spinning_theory(
            2, row["v_n"], 0.0, spin * speed, row["e"]
        )
        assert abs(row["v_t_after"] - tangential) < 0.03 * speed, spin
        assert abs(row["spin_R"] - turned) < 0.03 * speed, spin


@pytest.mark.validation
def test_tangential_impact_follows_the_rigid_body_theory_or_springs_back() -> None:
    """Chung & Ooi (2011) test 5 analogue (oblique_impact.py --test 5 draws the whole curve): a
    disc (R/h = 10) hits the plane at v_n = 0.5 m/s with v_t = 3 v_n (gross sliding: the rigid
    theory within 3 % of v_n; measured v_t' / v_n 2.4599 against 2.4586, omega' R / v_n 1.0819
    against 1.0828) and with v_t = 0.5 v_n (the contact point sticks and springs back, measured
    v_t' - omega' R = -0.990 v_t; between -1.02 and -0.5 v_t asserted, as at 10 degrees)."""
    speed = oblique_impact.SPEED
    for ratio in (3.0, 0.5):
        angle = float(np.degrees(np.arctan(ratio)))
        row = oblique_impact.impact(2, angle, 10, speed=speed * float(np.hypot(1.0, ratio)))
        tangential, spin = oblique_impact.theory(2, row["v_n"], row["v_t"], row["e"])
        if ratio > oblique_impact.sliding_limit(2, row["e"]):
            assert abs(row["v_t_after"] - tangential) < 0.03 * speed
            assert abs(row["spin_R"] - spin) < 0.03 * speed
        else:
            slip_after = row["v_t_after"] - row["spin_R"]
            assert -1.02 * row["v_t"] < slip_after < -0.5 * row["v_t"]


@pytest.mark.validation
def test_hertz_mindlin_reference_gives_e_and_the_rigid_theory_in_gross_sliding() -> None:
    """The reference law itself (docs/validation/hertz_mindlin.py): Tsuji's dashpot, fitted at
    0.5 m/s, gives e = 0.8 at 0.05 and 5 m/s too (its restitution is speed-free; 1e-3 asserted),
    and a sliding impact at 75 degrees follows the rigid-body theory to 1e-3 of v."""
    sphere = oblique_impact.sphere()
    alpha = hertz_mindlin.damping_for(sphere, 0.5, 0.8)
    for speed in (0.05, 5.0):
        assert hertz_mindlin.rebound(sphere, speed, 0.0, 0.0, 0.0, alpha)[0] == pytest.approx(
            0.8, abs=1e-3
        )
    v_n, v_t = 0.5 * np.cos(np.radians(75.0)), 0.5 * np.sin(np.radians(75.0))
    e, tangential, spin = hertz_mindlin.rebound(sphere, v_n, v_t, 0.0, oblique_impact.MU, alpha)
    rigid = oblique_impact.theory(3, v_n, v_t, e)
    assert abs(tangential - rigid[0]) < 5e-4 and abs(spin - rigid[1]) < 5e-4


@pytest.mark.validation
def test_sticking_impact_of_a_sphere_with_mindlins_stiffness_ratio_is_near_hertz_mindlin() -> None:
    """20 degrees, in the sticking regime, a conforming sphere (R/h = 6) with Mindlin's
    tangential stiffness ratio 2 (1 - nu) / (2 - nu) = 0.857: v_t' 0.228 v and omega' R 0.295 v
    against the Hertz-Mindlin law's 0.267 and 0.189 (docs/validation/README.md; asserted within
    0.06 and 0.15 v). granulate's default ratio 2/7 gives a full reversal of the contact point
    instead, 0.145 and 0.500: 0.12 and 0.31 v from Hertz-Mindlin."""
    speed = oblique_impact.SPEED
    oblique_impact.CONTACT_OPTIONS["tangential_stiffness_ratio"] = 6 / 7  # nu = 0.25
    try:
        row = oblique_impact.impact(3, 20.0, 6)
    finally:
        oblique_impact.CONTACT_OPTIONS.clear()
    reference = oblique_impact.mindlin(3, [(row["v_n"], row["v_t"], 0.0)], row["e"])
    assert reference is not None
    assert abs(row["v_t_after"] - reference[0, 0]) < 0.06 * speed
    assert abs(row["spin_R"] - reference[0, 1]) < 0.15 * speed
