"""Spinning bodies meeting head-on, the 2D analogues of Chung & Ooi (2011) tests 7 and 8
(docs/validation/pair_impact.py draws the whole curves, in 2D and 3D): in gross sliding the
rebound follows the rigid-body impulse theory with Coulomb friction (under the default contact,
the surface law)."""

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
    impulse mu (1 + e) m* v_n. Measured under the surface law v_t1' / v_n 0.2814 against
    0.2758, omega_1' R / v_n 2.4409 against 2.4484, e = 0.839: asserted within 0.03 v_n, as for
    a plane. On the node spheres (0.2612 against 0.2741, 2.4837 against 2.4519) the two rows of
    node spheres caught on each other (docs/validation/README.md). The two discs leave as
    mirror images (v_t2' = -v_t1', omega_2' = omega_1'; measured to 1e-4 v_n, asserted to 2e-3
    v_n)."""
    spin = 3.0 * SPEED
    row = pair_impact.pair_impact(2, (RADIUS, RADIUS), (spin, spin), 10)
    rigid = pair_impact.pair_theory(2, row, row["e"])
    for key in ("v_t_after", "spin_after"):
        assert abs(row[key][0] - rigid[key][0]) < 0.03 * SPEED, key
    assert abs(row["v_t_after"][0] + row["v_t_after"][1]) < 2e-3 * SPEED
    assert abs(row["spin_after"][0] - row["spin_after"][1]) < 2e-3 * SPEED
    assert abs(row["e"] - pair_impact.RESTITUTION) < 0.05


@pytest.mark.validation
def test_a_spinning_disc_on_a_larger_one_slides_as_rigid_theory_says() -> None:
    """Test 8: a disc (R = 1 mm, R/h = 10) spinning at omega R = 3 v_n hits one of 5 mm at rest,
    meshed 5 times coarser (R/h = 10 too). Measured under the surface law v_t1' / v_n 0.5185
    against 0.5162, omega_1' R / v_n 1.9654 against 1.9676, the large disc within 2e-4 v_n of
    the theory, e = 0.789: asserted within 0.03 v_n. On the node spheres the fine disc's nodes
    caught on the coarse disc's node row (0.5603 against 0.5122: the tangential impulse 9 %
    over Coulomb's)."""
    spin = 3.0 * SPEED
    row = pair_impact.pair_impact(2, (RADIUS, pair_impact.LARGE * RADIUS), (spin, 0.0), 10)
    rigid = pair_impact.pair_theory(2, row, row["e"])
    for key in ("v_t_after", "spin_after"):
        for body in (0, 1):
            assert abs(row[key][body] - rigid[key][body]) < 0.03 * SPEED, (key, body)
    assert abs(row["e"] - pair_impact.RESTITUTION) < 0.05
