"""The Python API's habits: every mistake in a call is an InputError naming the argument (with a
suggestion for a misspelt one), as in case files; progress bars; readable reprs."""

from __future__ import annotations

import pytest

import granulate as gr

ROCK = {"density": 2500, "youngs_modulus": 5e9, "poisson_ratio": 0.25, "fracture": False}


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: gr.Material(**{**ROCK, "young_modulus": 1}), "did you mean 'youngs_modulus'"),
        (lambda: gr.Material(**{**ROCK, "youngs_modulus": "50 GPa"}), "youngs_modulus"),
        (lambda: gr.Material(**{**ROCK, "density": -1}), "density"),
        (lambda: gr.Material(density=1, youngs_modulus=1e9, fracture=False), "exactly two"),
        (lambda: gr.Disc((0, 0), radus=1e-3), "Disc: unknown argument 'radus'; did you mean"),
        (lambda: gr.Disc((0, 0)), "Disc: the argument 'radius' is missing"),
        (lambda: gr.Disc((0, 0), "1e-3"), "radius must be a number (without quotes)"),
        (lambda: gr.Disc((0, 0), 1e-3, 2), "too many positional arguments"),
        (lambda: gr.Contact(restitutio=0.5), "did you mean 'restitution'"),
        (lambda: gr.Contact(friction="0.3"), "friction must be a number"),
        (lambda: gr.Contact(friction=True), "friction must be a number"),
        (lambda: gr.Sphere((0, 0, 0), radius=None), "radius must be a number"),
        (lambda: gr.Plane((0, 0), normall=(0, 1)), "did you mean 'normal'"),
        (lambda: gr.Linear(slope=2.0), "unknown argument 'slope'"),
        (lambda: gr.Uniform(0.1, hi=0.2), "unknown argument 'hi'"),
        (lambda: gr.stopping.KineticEnergyBelow(1e-6, afer=0.1), "did you mean 'after'"),
        (lambda: gr.RegularPolygon((0, 0), 1e-3, sides=6, angel=0.1), "did you mean 'angle'"),
        (lambda: gr.set_num_threads(0), "positive integer"),
        (lambda: gr.LoadBalance(evry=50), "did you mean 'every'"),
        (lambda: gr.LoadBalance(every=-1), "every must be a number of steps >= 0"),
        (lambda: gr.LoadBalance(every=2.5), "every must be an integer"),
        (lambda: gr.LoadBalance(threshold=0.9), "threshold must be a ratio >= 1"),
        (lambda: gr.LoadBalance(threshold=float("nan")), "threshold must be a ratio >= 1"),
        (lambda: gr.LoadBalance(weight="timing"), "weight must be 'work' or 'time'"),
        (lambda: setattr(gr.Simulation(2), "load_balance", 100), "granulate.LoadBalance("),
        (lambda: gr.LoadBalance.from_text("evry=5"), "did you mean 'every'"),
        (lambda: gr.LoadBalance.from_text("every=5,,"), "'' is not KEY=VALUE"),
        (lambda: gr.LoadBalance.from_text("every"), "'every' is not KEY=VALUE"),
        (lambda: gr.LoadBalance.from_text("every=ten"), "every must be an integer, got 'ten'"),
        (lambda: gr.LoadBalance.from_text("threshold=high"), "threshold must be a number"),
    ],
)
def test_mistakes_in_api_calls_are_input_errors(call, message: str) -> None:
    """Before: pydantic's ValidationError (not an InputError) or a TypeError from Python."""
    with pytest.raises(gr.InputError) as caught:
        call()
    assert message in str(caught.value)
    assert "Traceback" not in str(caught.value)


def disc_simulation() -> gr.Simulation:
    sim = gr.Simulation(2)
    sim.add_body(gr.Disc((0, 0), 1e-3), gr.Material(**ROCK), 2e-4)
    return sim


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ({"steps": 2.5}, "steps must be an integer, got 2.5"),
        ({"steps": "10"}, "steps must be an integer (without quotes)"),
        ({"steps": True}, "steps must be an integer"),
        ({"until": "1e-3"}, "until must be a number"),
        ({"steps": 5, "progress": "yes"}, "progress must be True, False or a function"),
    ],
)
def test_bad_run_arguments_are_input_errors(arguments: dict, message: str) -> None:
    sim = disc_simulation()
    with pytest.raises(gr.InputError, match=message.replace("(", r"\(").replace(")", r"\)")):
        sim.run(**arguments)
    assert sim.step == 0


def test_progress_true_reports_the_run(capsys: pytest.CaptureFixture[str]) -> None:
    """progress=True draws a bar in a terminal or notebook; in a captured stream, lines."""
    sim = disc_simulation()
    sim.run(50, progress=True)
    printed = capsys.readouterr().out
    assert "step 50 (100 %)" in printed
    assert sim.step == 50


def test_reprs_say_what_objects_hold() -> None:
    sim = disc_simulation()
    sim.add_wall(gr.Plane((0, -2e-3), (0, 1)), name="floor")
    unbuilt = "not built yet (built by the first run); walls: floor)"
    assert repr(sim) == f"Simulation(2D; 1 bodies; 80 nodes; {unbuilt}"
    sim.run(3)
    assert "step 3;" in repr(sim) and "bonds" in repr(sim)
    material = gr.Material(**ROCK)
    assert repr(material) == (
        "Material(density=2500.0, youngs_modulus=5000000000.0, poisson_ratio=0.25, fracture=False)"
    )
    assert repr(sim.bodies[0]).startswith("Body('body0', nodes 0..79, mesh size 0.0002 m")
    grain = gr.Grain(gr.Disc((0, 0), 1e-3), material, 2e-4, gr.Uniform(0.5e-3, 1e-3))
    packing = gr.pack(gr.Rectangle((0, 0), (0.01, 0.01)), [grain], 10, seed=1)
    assert repr(packing).startswith("Packing(10 particles (10 x Disc); radius")


def test_load_balance_reads_what_it_writes_as_text() -> None:
    """The command line's form (granulate bench --ranks --load-balance): any of the
    attributes, the others their defaults, inf for a threshold that never cuts."""
    given = gr.LoadBalance.from_text(" every=50, threshold=inf ")
    assert given == gr.LoadBalance(every=50, threshold=float("inf"))
    assert given.as_text() == "every=50,threshold=inf,weight=work"
    timed = gr.LoadBalance(every=0, threshold=1.05, weight="time")
    assert gr.LoadBalance.from_text(timed.as_text()) == timed


def test_a_settling_criterion_waits_for_its_start_time() -> None:
    """A body at rest is below any kinetic energy at the first check: with ``after`` the run
    goes on to that time (the README's example)."""
    sim = disc_simulation()
    sim.gravity = (0.0, -9.81)
    dt = sim.dt
    reason = sim.run(
        400, stop=[gr.stopping.KineticEnergyBelow(1.0, after=300 * dt)], check_every=50
    )
    assert reason is not None and 300 <= sim.step <= 350


def test_add_body_names_swapped_or_mistyped_arguments() -> None:
    sim = gr.Simulation(2)
    material = gr.Material(**ROCK)
    with pytest.raises(gr.InputError, match="the order is shape, material, mesh_size"):
        sim.add_body(material, gr.Disc((0, 0), 1e-3), 2e-4)  # type: ignore[arg-type]
    with pytest.raises(gr.InputError, match=r"mesh_size must be a number \(without quotes\)"):
        sim.add_body(gr.Disc((0, 0), 1e-3), material, "2.5e-4")  # type: ignore[arg-type]
    with pytest.raises(gr.InputError, match=r"material must be a granulate\.Material"):
        sim.add_body(gr.Disc((0, 0), 1e-3), {"density": 1}, 2e-4)  # type: ignore[arg-type]
    assert not sim.bodies


def test_arrays_users_must_not_change_are_read_only() -> None:
    """volumes[:] = 0 or reference_positions *= 2 went through and the run went on with
    nonsense; positions and velocities stay writable (documented)."""
    sim = disc_simulation()
    for name in ("volumes", "reference_positions", "forces"):
        with pytest.raises(ValueError, match="read-only"):
            getattr(sim, name)[:] = 0
    sim.velocities[:, 0] = 1.0
    sim.positions[:, 1] += 1e-6
    sim.run(2)
    assert sim.velocities[0, 0] == pytest.approx(1.0, rel=1e-3)


def test_setting_an_attribute_simulation_does_not_have_is_an_input_error() -> None:
    """sim.viscous_damping = 200 after construction was stored as a new Python attribute and
    the grains fell undamped (a 40-grain pile bounced for a simulated second); a misspelt
    attribute is refused with the closest name, a read-only one too, and viscous_damping is a
    property that reaches the core."""
    sim = gr.Simulation(2, gravity=(0, -10))
    sim.viscous_damping = 200.0
    sim.add_body(
        gr.Disc((0, 0.1), 1e-3),
        gr.Material(density=1200, youngs_modulus=1e7, poisson_ratio=0.25, fracture=False),
        2e-4,
    )
    sim.run(until=0.02)
    assert float(sim.velocities[:, 1].mean()) == pytest.approx(-10 / 200, rel=0.02)
    with pytest.raises(gr.InputError, match="did you mean 'viscous_damping'"):
        sim.viscous_dampng = 1.0  # type: ignore[attr-defined]
    with pytest.raises(gr.InputError, match="'node_count' cannot be set"):
        sim.node_count = 3  # type: ignore[misc]
    with pytest.raises(gr.InputError, match="cannot change the viscous damping after"):
        sim.viscous_damping = 1.0
