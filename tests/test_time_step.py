"""Stable time-step estimate, warnings for a large dt, and a clear stop on blow-up."""

from __future__ import annotations

import numpy as np
import pytest

import granulate as gr


def plate(model: str = "lps", **kwargs) -> gr.Simulation:
    shear = 2e9 if model == "lps" else 1.8e9  # PMB's Poisson ratio is 1/4: G = 0.6 K
    material = gr.Material(
        density=1500, bulk_modulus=3e9, shear_modulus=shear, fracture=False, model=model
    )
    sim = gr.Simulation(2, **kwargs)
    sim.add_body(gr.Rectangle((0, 0), (0.02, 0.02)), material, 1e-3)
    rng = np.random.default_rng(1)
    sim.velocities[:, :2] = rng.normal(scale=0.01, size=(sim.node_count, 2))
    return sim


@pytest.mark.parametrize("model", ["lps", "pmb"])
def test_estimate_is_stable_and_not_far_too_small(model: str) -> None:
    """At the estimate the run is stable; at 4x it is not (the bound is within a factor 4)."""
    stable = plate(model)
    stable.dt = stable.stable_dt
    stable.run(3000)
    assert np.abs(stable.velocities).max() < 1.0
    unstable = plate(model)
    with pytest.warns(gr.GranulateWarning, match="exceeds the stable estimate"):
        unstable.dt = 4 * unstable.stable_dt
    with pytest.raises(gr.InstabilityError, match="use a smaller time step"):
        unstable.run(3000)


def test_default_dt_is_safety_times_estimate() -> None:
    sim = plate(dt_safety=0.5)
    assert sim.dt == pytest.approx(0.5 * sim.stable_dt, rel=1e-15)


def test_large_user_dt_warns_when_the_model_is_built() -> None:
    with pytest.warns(gr.GranulateWarning, match="exceeds the stable estimate"):
        plate(dt=1.0)  # setting the initial velocities builds the model


def test_a_time_step_far_above_the_estimate_is_refused_before_running() -> None:
    """dt = 1e-3 s (thousands of times the estimate): an InputError when the run starts,
    before anything moves (it was accepted with a warning, and the run died in the core)."""
    with pytest.warns(gr.GranulateWarning):
        sim = plate(dt=1e-3)
    with pytest.raises(gr.InputError, match="times the stable estimate"):
        sim.run(500)
    assert sim.step == 0
    with pytest.raises(gr.InputError, match="dt must be a number"):
        sim.dt = "1e-6"  # type: ignore[assignment]


def test_a_blow_up_is_caught_on_the_step_it_happens() -> None:
    """dt at 5 times the estimate (the most a run accepts): the run stops with an
    InstabilityError naming the step, the node and its speed. The check ran every 64 steps, so
    a 20-step run ended "finished" with an exploded state; it now runs every step (measured:
    stopped at step 4)."""
    probe = plate()
    with pytest.warns(gr.GranulateWarning, match="exceeds the stable estimate"):
        sim = plate(dt=5 * probe.stable_dt)
    with pytest.raises(gr.InstabilityError) as error:
        sim.run(20)
    message = str(error.value)
    assert "unstable at step" in message and "stable estimate" in message
    assert "m/s, more than its mesh size" in message
    assert sim.step < 20


def test_a_blow_up_quotes_the_estimate_it_is_given() -> None:
    """A distributed run's part quotes the whole run's stable estimate, which its own grains
    need not give (core.set_reported_stable_time_step; DistributedRun sets it); 0 restores
    the part's own."""
    probe = plate()
    for given, quoted in ((1.25e-7, "1.25e-07"), (0.0, f"{probe.stable_dt:.6g}")):
        with pytest.warns(gr.GranulateWarning, match="exceeds the stable estimate"):
            sim = plate(dt=5 * probe.stable_dt)
        sim.core.set_reported_stable_time_step(given)
        with pytest.raises(gr.InstabilityError, match=f"the stable estimate is {quoted} s"):
            sim.run(20)


def test_a_non_finite_velocity_stops_the_run_at_once() -> None:
    """An initial velocity of 1e308 m/s: an InstabilityError at step 1 (a 60-step run ended
    "finished" with NaN energies)."""
    sim = plate()
    sim.velocities[:, 0] = 1e308
    with pytest.raises(gr.InstabilityError, match=r"at step 1 .*non-finite"):
        sim.run(60)


@pytest.mark.parametrize("bad", [0.0, -1e-6, float("nan"), float("inf")])
def test_bad_dt_is_refused(bad: float) -> None:
    with pytest.raises(gr.InputError, match="time step"):
        gr.Simulation(2, dt=bad)
