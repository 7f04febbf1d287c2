"""Reading a run back (gr.Results): history, frames by number and time, particle and fragment
tables, run.json, and clear errors for what is not there."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import granulate as gr


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, gr.Simulation]:
    """Two discs falling on a floor, one pre-cracked: 4 frames (steps 0, 40, 80, 100)."""
    rock = gr.Material(density=2000, youngs_modulus=1e8, poisson_ratio=0.25, fracture_energy=5)
    sim = gr.Simulation(2, gravity=(0, -9.81))
    sim.add_body(gr.Disc((0, 1.2e-3), 1e-3), rock, 2.5e-4, name="a")
    sim.add_body(gr.Disc((3e-3, 1.2e-3), 1e-3), rock, 2.5e-4, name="b")
    sim.add_wall(gr.Plane((0, 0), (0, 1)), name="floor")
    sim.precrack((3e-3, 0), (1, 0))
    folder = tmp_path_factory.mktemp("run")
    sim.output(folder, every=40)
    sim.run(100)
    return folder, sim


def test_frames_by_number_and_time_hold_what_was_written(run) -> None:
    folder, sim = run
    results = gr.Results(folder)
    assert len(results) == 4 and "4 frames" in repr(results)
    np.testing.assert_allclose(results.times, np.array([0, 40, 80, 100]) * sim.dt, rtol=1e-12)
    last = results.frame(-1)
    assert last.index == 3 and last.time == results.times[-1]
    np.testing.assert_array_equal(last.positions, sim.positions)
    np.testing.assert_array_equal(last["Velocity"], sim.velocities)
    assert results.frame(time=41 * sim.dt).index == 1
    with pytest.raises(gr.InputError, match="no field 'Stress'"):
        last["Stress"]


def test_history_and_tables_come_as_columns(run) -> None:
    folder, sim = run
    results = gr.Results(folder)
    history = results.history
    np.testing.assert_array_equal(history["step"], [0, 40, 80, 100])
    assert list(history["fragments"]) == [3, 3, 3, 3]  # the cut disc is two pieces
    particles = results.particles(-1)
    assert list(particles["particle"]) == [0, 1]
    assert particles["mass"] == pytest.approx(sim.model.volumes.sum() / 2 * 2000, rel=0.05)
    table = results.fragments(-1)
    for name, column in sim.fragment_table().items():
        np.testing.assert_array_equal(table[name], column)
    assert results.summary["steps"] == 100


def test_what_is_not_there_is_an_input_error(run, tmp_path: Path) -> None:
    folder, _ = run
    with pytest.raises(gr.InputError, match=r"no simulation\.pvd"):
        gr.Results(tmp_path)
    results = gr.Results(folder)
    with pytest.raises(gr.InputError, match="frame 4 does not exist: the run has 4 frames"):
        results.frame(4)
    with pytest.raises(gr.InputError, match="not both or neither"):
        results.frame()
    (tmp_path / "simulation.pvd").write_text("not xml")
    with pytest.raises(gr.InputError, match="not a ParaView collection"):
        gr.Results(tmp_path)
