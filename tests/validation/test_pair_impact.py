"""Spinning bodies meeting head-on, the 2D analogues of Chung & Ooi (2011) tests 7 and 8
(docs/validation/pair_impact.py draws the whole curves, in 2D and 3D): in gross sliding the
rebound follows the rigid-body impulse theory with Coulomb friction."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "docs" / "validation"))
import pair_impact

SPEED, RADIUS = pair_impact.SPEED, pair_impact.RADIUS


@pytest.mark.validation
def test_two_equal_spinning_discs_slide_as_rigid_theory_says() -> None:
    """Test 7: two equal discs (R/h = 10) spinning the same way at omega R = 3 v_n meet at v_n =
    0.5 m/s. The contact points slide all through the impact, so each body takes the Coulomb
    impulse mu (1 + e) m* v_n. Measured v_t1' / v_n 0.2612 against 0.2741, omega_1' R / v_n
    2.4837 against 2.4519: asserted within 0.05 v_n, looser than for a plane (0.03) because both
    surfaces are rows of node spheres that catch on each other (without friction such a pair
    still leaves with |v_t'| up to 0.24 v_n at R/h = 10 and 0.10 v_n at R/h = 20;
    docs/validation/README.md). The two discs leave as mirror images (v_t2' = -v_t1',
    omega_2' = omega_1'; measured to 1e-4 v_n, asserted to 2e-3 v_n)."""
    spin = 3.0 * SPEED
    row = pair_impact.pair_impact(2, (RADIUS, RADIUS), (spin, spin), 10)
    rigid = pair_impact.pair_theory(2, row, row["e"])
    for key in ("v_t_after", "spin_after"):
        assert abs(row[key][0] - rigid[key][0]) < 0.05 * SPEED, key
    assert abs(row["v_t_after"][0] + row["v_t_after"][1]) < 2e-3 * SPEED
    assert abs(row["spin_after"][0] - row["spin_after"][1]) < 2e-3 * SPEED
    assert abs(row["e"] - pair_impact.RESTITUTION) < 0.05


@pytest.mark.validation
def test_a_spinning_disc_on_a_larger_one_slides_as_rigid_theory_says() -> None:
    """Test 8: a disc (R = 1 mm, R/h = 10) spinning at omega R = 3 v_n hits one of 5 mm at rest,
    meshed 5 times coarser (R/h = 10 too). Measured v_t1' / v_n 0.5603 against 0.5122, omega_1' R
    / v_n 1.9455 against 1.9755, e = 0.776: asserted within 0.06 v_n (the fine disc's nodes
    catch on the coarse disc's node row: the tangential impulse is 9 % over Coulomb's)."""
    spin = 3.0 * SPEED
    row = pair_impact.pair_impact(2, (RADIUS, pair_impact.LARGE * RADIUS), (spin, 0.0), 10)
    rigid = pair_impact.pair_theory(2, row, row["e"])
    for key in ("v_t_after", "spin_after"):
        for body in (0, 1):
            assert abs(row[key][body] - rigid[key][body]) < 0.06 * SPEED, (key, body)
    assert abs(row["e"] - pair_impact.RESTITUTION) < 0.05
