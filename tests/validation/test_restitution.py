"""Normal impacts on a plane with different coefficients of restitution, the 2D (3D) analogue of
Chung & Ooi (2011) test 3 (docs/validation/restitution.py draws the whole curve): the measured
rebound follows the requested e at slow and fast impacts, because the damping ratio is fitted
to each collision's force-approach law (power_law_damping.hpp), not taken from the linear
spring-dashpot's formula."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

import granulate as gr

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "docs" / "validation"))
import restitution


@pytest.mark.validation
@pytest.mark.parametrize("dimension", [2, 3])
def test_impacts_on_a_plane_rebound_with_the_requested_restitution(
    dimension: int, full: bool
) -> None:
    """Within 0.05 of the requested e (Issue 13's tolerance) at 0.05 and 5 m/s. Measured: 2D
    0.114 / 0.507 at 0.05 m/s and 0.114 / 0.507 at 5 m/s for e = 0.1 / 0.5; 3D 0.080 / 0.485
    and 0.100 / 0.499. With the linear formula's damping ratio 3D gave 0.171 / 0.568 at 5 m/s
    (the node springs of a sphere on a plane stiffen as F ~ x^2). The 3D smoke test leaves out
    the slow impact at e = 0.5 (the slow impacts take the longest to land)."""
    cases = [(speed, e) for speed in (0.05, 5.0) for e in (0.1, 0.5)]
    if dimension == 3 and not full:
        cases.remove((0.05, 0.5))
    for speed, requested in cases:
        measured = restitution.rebound(dimension, requested, speed)
        assert measured == pytest.approx(requested, abs=0.05), (speed, requested)


@pytest.mark.validation
def test_a_splittable_disc_rebounds_with_the_requested_restitution() -> None:
    """A disc of 4,300 nodes (R/h = 37) is splittable (core splittable_particle_nodes, 4,096):
    its rigid motion and its contact's sums are block sums added exactly, as a distributed run
    could cut it. Its rebound at 5 m/s with e = 0.5 is within 0.05 of it, as the default disc's
    is (measured: 0.502; the default disc, R/h = 10: 0.505)."""
    h = restitution.RADIUS / 37
    sim = gr.Simulation(2)
    sim.add_body(
        gr.Disc((0, 0), restitution.RADIUS), restitution.SOFT, h, discretization="conforming"
    )
    assert sim.node_count >= 4096
    assert restitution.rebound(2, 0.5, 5.0, nodes_across_radius=37) == pytest.approx(0.5, abs=0.05)
