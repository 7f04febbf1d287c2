"""Rolling resistance (Contact(rolling_friction=mu_r), the spring-dashpot of contact_law.hpp): a
disc on a slope of tan(a) <= mu_r stays put, above it rolls down at
g (sin a - mu_r cos a) / (1 + I / (m R^2)), and the torques, equal and opposite couples on the
two bodies, keep an isolated collision's angular momentum to round-off."""

from __future__ import annotations

import numpy as np
import pytest

import granulate as gr

from .test_contact import (
    SOFT,
    angular_momentum,
    momentum_scale,
    oblique_pair,
    rigid_spin,
    run_through_contact,
)
from .test_friction import rigid_motion

RADIUS = 1e-3
SPIN = 300.0  # rad/s: omega R = 0.3 m/s, half the approach speed


def ball_on_slope(
    dimension: int, slope: float, rolling_friction: float, nodes_across_radius: int = 10
) -> tuple[gr.Simulation, gr.Body]:
    """A conforming disc or sphere of 1 mm set on a floor, gravity tilted to a slope of tan(a) =
    `slope`, friction 1 (no slip), e = 0.5, the default rolling damping."""
    a, g = np.arctan(slope), 9.81
    sim = gr.Simulation(dimension, gravity=(g * np.sin(a), -g * np.cos(a), 0)[:dimension])
    sim.contact = gr.Contact(restitution=0.5, friction=1.0, rolling_friction=rolling_friction)
    zero = (0.0,) * (dimension - 2)
    shape = gr.Disc if dimension == 2 else gr.Sphere
    h = RADIUS / nodes_across_radius
    ball = sim.add_body(shape((0, RADIUS, *zero), RADIUS), SOFT, h, discretization="conforming")
    sim.add_wall(gr.Plane((0, 0, *zero), (0, 1, *zero)), name="floor")
    return sim, ball


@pytest.mark.validation
def test_a_ball_on_a_slope_below_its_rolling_resistance_stays_put(full: bool) -> None:
    """tan(a) = 0.5, mu_r = 0.6: once the rolling spring has taken the load (5 ms for a disc at
    R/h = 10; 15 ms for a sphere at R/h = 8, with --full, about 80 s more), the ball moves less
    than 1e-3 of its size in 10 ms (measured 1.7e-9 m and 5.3e-7 m). With mu_r below tan(a) it
    rolls down (the next test). A coarser sphere (R/h = 6) rests on one node and
    rocks: it drifted 2.3e-6 m in 10 ms after 30 ms, and 5.6e-6 m at tan(a) = 0.3 (1.4 % of its
    free rolling); see ARCHITECTURE.md."""
    cases = [(2, 10, 0.005)] + ([(3, 8, 0.015)] if full else [])
    for dimension, nodes_across_radius, settle in cases:
        sim, ball = ball_on_slope(dimension, 0.5, 0.6, nodes_across_radius)
        sim.run(until=settle)
        start = rigid_motion(sim, ball)[0]
        sim.run(until=sim.time + 0.01)
        drift = np.linalg.norm(rigid_motion(sim, ball)[0] - start)
        assert drift < 1e-3 * 2 * RADIUS, f"{dimension}D: rolled {drift:.3g} m"


def rolling_acceleration(sim: gr.Simulation, ball: gr.Body, until: float) -> float:
    """The ball's acceleration down the slope: least-squares slope of its velocity, sampled
    every 20 steps up to `until` (the ball's vibrations ripple single samples)."""
    times, speeds = [], []
    while sim.time < until:
        sim.run(20)
        times.append(sim.time)
        speeds.append(rigid_motion(sim, ball)[1][0])
    return float(np.polyfit(times, speeds, 1)[0])


@pytest.mark.validation
def test_a_ball_above_its_rolling_resistance_rolls_down_at_the_epsd_rate(full: bool) -> None:
    """tan(a) = 0.5, mu_r = 0.2: from 5 ms on (to 15 ms for a disc at R/h = 10; to 20 ms for a
    sphere at R/h = 8, with --full, about 70 s more) the ball rolls down at
    g (sin a - mu_r cos a) / (1 + k), k = 1/2 (disc) or 2/5 (sphere), within 5 % (measured
    0.972 and 0.998 of it). The deformable disc's own rolling resistance makes up most of the
    difference: without mu_r it rolls at 0.988 of g sin a / (1 + k), measured the same way. A
    coarser sphere (R/h = 6), rocking on one node, measured 0.924 (0.971 without mu_r)."""
    slope, mu_r = 0.5, 0.2
    a = np.arctan(slope)
    cases = [(2, 10, 0.015, 0.5)] + ([(3, 8, 0.02, 0.4)] if full else [])
    for dimension, nodes_across_radius, until, k in cases:
        sim, ball = ball_on_slope(dimension, slope, mu_r, nodes_across_radius)
        sim.run(until=0.005)
        acceleration = rolling_acceleration(sim, ball, until)
        expected = 9.81 * (np.sin(a) - mu_r * np.cos(a)) / (1 + k)
        assert acceleration == pytest.approx(expected, rel=0.05), f"{dimension}D"


@pytest.mark.validation
def test_rolling_torques_conserve_angular_momentum() -> None:
    """Two discs meet off-centre (friction 0, e = 0.6), the first spinning at 300 rad/s, with
    mu_r = 0.5: the rolling torques are
    equal and opposite couples on the two bodies, so the angular momentum is kept to round-off
    (1e-12 of its scale; measured 3.3e-16), and they change how the discs leave (their spins
    differ from the run without rolling resistance by more than 1 rad/s; measured 365 and 218
    rad/s against 444 and 139 without)."""
    spins = {}
    for mu_r in (0.0, 0.5):
        sim, a, b = oblique_pair(2, 0.0, rolling_friction=mu_r)
        arm = sim.positions[a.nodes, :2] - sim.positions[a.nodes, :2].mean(axis=0)
        sim.velocities[a.nodes, 0] -= SPIN * arm[:, 1]
        sim.velocities[a.nodes, 1] += SPIN * arm[:, 0]
        densities = np.full(sim.node_count, SOFT.density)
        before = angular_momentum(sim, densities)
        scale = momentum_scale(sim, densities)
        run_through_contact(sim)
        spins[mu_r] = np.array([rigid_spin(sim, body) for body in (a, b)])
        np.testing.assert_allclose(
            angular_momentum(sim, densities), before, rtol=0, atol=1e-12 * scale
        )
    assert np.max(np.abs(spins[0.5] - spins[0.0])) > 1.0, spins


def test_a_negative_rolling_friction_is_refused() -> None:
    with pytest.raises(gr.InputError, match="rolling_friction must be a non-negative number"):
        gr.Contact(rolling_friction=-0.1)
