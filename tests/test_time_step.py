"""Stable time-step estimate, warnings for a large dt, and a clear stop on blow-up."""

from __future__ import annotations

import numpy as np
import pytest

import granulate as gr


def plate(model: str = "lps", **kwargs) -> gr.Simulation:
    material = gr.Material(
        density=1500, bulk_modulus=3e9, shear_modulus=2e9, fracture=False, model=model
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


def test_blow_up_message_names_step_and_dt() -> None:
    with pytest.warns(gr.GranulateWarning):
        sim = plate(dt=1e-3)
    with pytest.raises(gr.InstabilityError) as error:
        sim.run(500)
    message = str(error.value)
    assert "unstable at step" in message and "stable estimate" in message


@pytest.mark.parametrize("bad", [0.0, -1e-6, float("nan"), float("inf")])
def test_bad_dt_is_refused(bad: float) -> None:
    with pytest.raises(gr.InputError, match="time step"):
        gr.Simulation(2, dt=bad)
