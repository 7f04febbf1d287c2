"""Each room behind Simulation used alone: the assembly, the core model made from it, the
loading, the interactions, the analysis and the run loop (ARCHITECTURE.md)."""

from __future__ import annotations

import numpy as np
import pytest

import granulate as gr
from granulate import _core, core_model, run_loop
from granulate.analysis import Analysis
from granulate.assembly import Assembly
from granulate.checkpoints import CheckpointPlan
from granulate.interactions import Interactions, core_law
from granulate.loading import Loading, component_mask
from granulate.run_loop import LoopParts, RunPlan, RunRecord

ROCK = gr.Material(density=2000, youngs_modulus=1e8, poisson_ratio=0.25, fracture_energy=5.0)
H = 2e-4


def two_discs() -> Assembly:
    """Two equal discs of radius 1 mm at y = 1 cm, 3 mm apart, the second moving at 1 m/s in x."""
    assembly = Assembly(2)
    for k, name in enumerate(("left", "right")):
        assembly.add_body(
            gr.Disc((3e-3 * k, 0.01), 1e-3),
            ROCK,
            H,
            discretization="lattice",
            jitter=0.0,
            seed=0,
            velocity=(1.0, 0) if k else None,
            angular_velocity=None,
            name=name,
        )
    return assembly


def test_an_assembly_numbers_bodies_and_selects_nodes() -> None:
    assembly = two_discs()
    left, right = assembly.bodies
    assert (left.first_node, right.first_node) == (0, left.node_count)
    assert assembly.node_count == 2 * left.node_count  # the same disc, moved
    assert assembly.body("right") is right
    with pytest.raises(gr.InputError, match="did you mean 'right'"):
        assembly.body("rigth")
    X = assembly.reference_positions()
    right_half = assembly.select(X, gr.Rectangle((1.5e-3, -1), (1, 1)), None, None)
    np.testing.assert_array_equal(right_half, right.nodes)
    assert len(assembly.select(X, None, left, [0, 1, right.first_node])) == 2


def test_translated_copies_share_one_core_shape() -> None:
    model, materials = core_model.build_model(two_discs(), "strain", outer_layers=False)
    assert model.node_count == two_discs().node_count
    assert (model.shape_count, model.family_count, len(materials)) == (1, 1, 1)


def test_a_horizon_in_the_wrong_unit_is_refused_before_any_bond() -> None:
    assembly = Assembly(2)
    wide = gr.Material(
        density=2000, youngs_modulus=1e8, poisson_ratio=0.25, fracture=False, horizon=0.01
    )
    assembly.add_body_from_nodes(
        np.zeros((1, 2)), [1e-8], wide, 1e-4, velocity=None, angular_velocity=None, name=None
    )
    with pytest.raises(gr.InputError, match="100 times its mesh size"):
        core_model.build_model(assembly, "strain", outer_layers=False)


def test_loading_hands_the_core_its_loads_in_order() -> None:
    assembly = two_discs()
    left = assembly.bodies[0]
    loading = Loading(assembly)
    loading.fix(left.nodes, "xyz")
    loading.prescribe_velocity(assembly.bodies[1].nodes, (0, 2.0), 0.0, None)
    assert [load.kind for load in loading.loads] == ["displacement", "displacement"]
    assert loading.loads[0].mask == component_mask("xy", 2) == 3
    np.testing.assert_array_equal(loading.loads[1].direction, (0, 1, 0))
    model, _ = core_model.build_model(assembly, "strain", outer_layers=False)
    core = _core.Simulation(model)
    core.time_step = 1e-8
    loading.apply(core)
    core.run(10)
    right = assembly.bodies[1].node_slice
    np.testing.assert_array_equal(
        core.positions[left.node_slice], model.reference_positions[left.node_slice]
    )
    moved = core.positions[right] - model.reference_positions[right]
    np.testing.assert_allclose(moved[:, 1], 2.0 * 10 * 1e-8, rtol=0, atol=1e-17)  # ulp(1 cm)
    with pytest.raises(gr.InputError, match="component 'z'"):
        component_mask("z", 2)


def test_interactions_refuse_a_wall_name_twice_and_resolve_laws() -> None:
    interactions = Interactions(two_discs())
    floor = gr.Plane((0, -2e-3), (0, 1))
    assert interactions.add_wall(floor, None, 2) == "wall0"
    with pytest.raises(gr.InputError, match="exists already"):
        interactions.add_wall(floor, "wall0", 2)
    assert interactions.uses_surface_law()  # the default law
    interactions.set_default(gr.Contact(pair_law="granulate"))
    assert not interactions.uses_surface_law()
    interactions.set_pair(ROCK, ROCK, gr.Contact(pair_law="surface"))
    assert interactions.uses_surface_law()
    law = core_law(gr.Contact(restitution=1.0, friction=0.3))
    assert (law.damping_ratio, law.friction) == (0.0, 0.3)


def test_analysis_counts_pieces_and_the_gravity_energy() -> None:
    assembly = two_discs()
    model, _ = core_model.build_model(assembly, "strain", outer_layers=False)
    core = _core.Simulation(model)
    analysis = Analysis(core, model, len(assembly.bodies))
    pieces = analysis.fragments(min_nodes=1)
    assert [len(p) for p in pieces] == [b.node_count for b in assembly.bodies]
    g = np.array([0.0, -9.81, 0.0])
    mass = np.asarray(model.node_density) * np.asarray(model.volumes)
    expected = -float(np.sum(mass * (core.positions @ g)))
    assert analysis.gravity_energy(g) == pytest.approx(expected, rel=1e-14)
    assert analysis.fully_broken_particles(assembly.bodies) == 0


def test_the_run_loop_drives_the_parts_it_is_given(tmp_path) -> None:
    """run_loop reads the simulation's public API and the LoopParts it is handed: its own run
    record, checkpoint plan and after-chunk check, not the simulation's."""
    sim = gr.Simulation(2)
    sim.add_body(gr.Disc((0, 0), 1e-3), ROCK, H)
    chunks = []
    plan = CheckpointPlan.create(40, None, tmp_path / "loop.npz", None)
    record = RunRecord()
    stepper = run_loop.CoreStepper(sim.core)
    parts = LoopParts(None, record, plan, None, lambda: chunks.append(sim.step), stepper)
    steps = run_loop.steps_to_run(sim.time, sim.dt, 100, None, 100)
    run_plan = RunPlan(steps, (), 100, None, write_final=True)
    assert run_loop.run_in_folder(sim, run_plan, parts) is None
    assert (sim.step, record.steps_run, sim.summary()["steps_run"]) == (100, 100, 0)
    assert chunks and chunks[-1] == 100 and chunks == sorted(set(chunks))
    assert 40 in chunks and 80 in chunks  # the loop stops at the plan's checkpoint steps
    restored = gr.Simulation(2)
    restored.add_body(gr.Disc((0, 0), 1e-3), ROCK, H)
    restored.load_checkpoint(tmp_path / "loop.npz")
    assert restored.step == 80
