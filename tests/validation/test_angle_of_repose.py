"""A pile's angle of repose rises with friction (issue 13): a column of polydisperse discs
collapses against a wall onto a rough floor, and the slope of the heap it leaves is measured
(docs/validation/angle_of_repose.py, which draws the heaps)."""

from __future__ import annotations

import itertools
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "docs" / "validation"))
import angle_of_repose


def settled_angle(friction: float, width: float, until: float, rolling: float = 0.0) -> float:
    """The heap's angle [degrees], once its kinetic energy is under 1 % of the column's weight
    times its width (the heap has stopped)."""
    heap, sim = angle_of_repose.collapse(
        friction, width=width, rolling_friction=rolling, until=until
    )
    weight = sum(float(sim.volumes[b.nodes].sum()) for b in sim.bodies)
    weight *= angle_of_repose.GRAIN.density * angle_of_repose.GRAVITY
    assert sim.kinetic_energy() < 0.01 * weight * width, "the heap is still moving"
    return heap.angle


@pytest.mark.validation
def test_the_heap_of_a_collapsed_column_is_steeper_with_friction(full: bool) -> None:
    """--full: a 16 mm x 48 mm column (121 grains) after 0.14 s; measured 5.2, 7.4 and 10.6
    degrees for mu = 0, 0.2 and 0.5, and 18.5 with mu = 0.5 and rolling resistance mu_r = 0.3:
    each case at least 1.5 degrees steeper than the one before. The smoke test collapses an 8 mm
    x 24 mm column (28 grains) for 0.1 s: 4.1 degrees for mu = 0 and 11.7 for mu = 0.5 (kinetic
    energy 3e-4 and 1e-4 of the weight times the width), asserted at least 4 degrees apart (one
    heap of 28 grains is a noisy measure: grains of E = 5 MPa gave 6.7 degrees for mu = 0.5)."""
    if full:
        angles = [
            settled_angle(friction, 16e-3, 0.14, rolling)
            for friction, rolling in angle_of_repose.CASES
        ]
        assert all(b > a + 1.5 for a, b in itertools.pairwise(angles)), angles
    else:
        frictionless, frictional = (settled_angle(mu, 8e-3, 0.1) for mu in (0.0, 0.5))
        assert frictional > frictionless + 4.0, (frictionless, frictional)
