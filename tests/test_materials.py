"""Material parameters: conversions between elastic constants, validation messages."""

from __future__ import annotations

import math

import pytest

import granulate as gr

E, NU = 70e9, 0.22
K, G = E / (3 * (1 - 2 * NU)), E / (2 * (1 + NU))


@pytest.mark.parametrize(
    "given",
    [
        {"youngs_modulus": E, "poisson_ratio": NU},
        {"bulk_modulus": K, "shear_modulus": G},
        {"bulk_modulus": K, "youngs_modulus": E},
        {"shear_modulus": G, "youngs_modulus": E},
        {"bulk_modulus": K, "poisson_ratio": NU},
        {"shear_modulus": G, "poisson_ratio": NU},
    ],
)
def test_any_two_elastic_constants_give_the_same_moduli(given: dict[str, float]) -> None:
    material = gr.Material(density=2500, fracture=False, **given)
    k, g = material.elastic_moduli()
    assert math.isclose(k, K, rel_tol=1e-12) and math.isclose(g, G, rel_tol=1e-12)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"youngs_modulus": E}, "exactly two elastic constants"),
        ({"youngs_modulus": E, "poisson_ratio": NU, "bulk_modulus": K}, "exactly two"),
        ({"youngs_modulus": -1.0, "poisson_ratio": NU}, "greater than 0"),
        ({"youngs_modulus": E, "poisson_ratio": 0.5}, "less than 0.5"),
        ({"bulk_modulus": 1e9, "youngs_modulus": 1e10, "fracture": False}, "below 9 bulk_modulus"),
        ({"shear_modulus": 1e9, "youngs_modulus": 4e9, "fracture": False}, "below 3 shear_modulus"),
        ({"youngs_modulus": E, "poisson_ratio": NU, "fracture": True}, "fracture_energy"),
        (
            {
                "youngs_modulus": E,
                "poisson_ratio": NU,
                "fracture": False,
                "horizon": 1e-3,
                "horizon_factor": 3,
            },
            "not both",
        ),
        ({"youngs_modulus": E, "poisson_ratio": NU, "fracture": False, "modle": "lps"}, "modle"),
        (
            {"youngs_modulus": E, "poisson_ratio": NU, "fracture": False, "influence": "cubic"},
            "influence",
        ),
    ],
)
def test_bad_materials_are_refused_with_a_clear_message(kwargs: dict, message: str) -> None:
    with pytest.raises(gr.InputError, match=message):
        gr.Material(density=2500, **kwargs)


def test_horizon_is_absolute_or_relative_to_the_mesh() -> None:
    relative = gr.Material(density=1, youngs_modulus=1, poisson_ratio=0.2, fracture=False)
    assert relative.resolved_horizon(2e-3) == pytest.approx(6e-3)
    absolute = gr.Material(
        density=1, youngs_modulus=1, poisson_ratio=0.2, fracture=False, horizon=5e-3
    )
    assert absolute.resolved_horizon(2e-3) == 5e-3


def test_critical_stretch_follows_gc_and_horizon() -> None:
    """s0 ~ sqrt(Gc / delta): four times Gc doubles s0, four times delta halves it."""
    base = dict(density=1000, youngs_modulus=1e9, poisson_ratio=0.25)
    s0 = gr.Material(**base, fracture_energy=10.0).critical_stretch(1e-3, 2)
    assert gr.Material(**base, fracture_energy=40.0).critical_stretch(1e-3, 2) == pytest.approx(
        2 * s0
    )
    assert gr.Material(**base, fracture_energy=10.0).critical_stretch(4e-3, 2) == pytest.approx(
        s0 / 2
    )


def test_horizon_smaller_than_mesh_is_refused() -> None:
    material = gr.Material(
        density=1000, youngs_modulus=1e9, poisson_ratio=0.25, fracture=False, horizon=0.5e-3
    )
    sim = gr.Simulation(2)
    sim.add_body(gr.Rectangle((0, 0), (0.01, 0.01)), material, 1e-3)
    with pytest.raises(gr.InputError, match=r"horizon .* is smaller than the mesh size"):
        sim.run(1)


def test_a_failed_build_fails_again_the_same_way() -> None:
    """An input error while building leaves no half-built state: a retry fails the same way."""
    material = gr.Material(
        density=1000, youngs_modulus=1e9, poisson_ratio=0.25, fracture=False, horizon=0.5e-3
    )
    sim = gr.Simulation(2)
    sim.add_body(gr.Rectangle((0, 0), (0.01, 0.01)), material, 1e-3)
    for _ in range(2):
        with pytest.raises(gr.InputError, match="smaller than the mesh size"):
            sim.run(1)
