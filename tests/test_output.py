"""Outputs: VTU frames that VTK readers load (checked with meshio), the PVD series, history.csv,
run.json, and protection of an existing run."""

from __future__ import annotations

import csv
import json
import xml.etree.ElementTree as ET
from pathlib import Path

import meshio
import numpy as np
import pytest

import granulate as gr


def pulled_plate(out: Path, **output) -> gr.Simulation:
    material = gr.Material(
        density=2500, youngs_modulus=70e9, poisson_ratio=0.22, fracture_energy=8.0
    )
    sim = gr.Simulation(2)
    sim.add_body(gr.Rectangle((0, 0), (0.02, 0.005)), material, 0.5e-3)
    sim.fix(sim.select(gr.Rectangle((-1, -1), (0.0015, 1))))
    sim.prescribe_velocity(sim.select(gr.Rectangle((0.0185, -1), (1, 1))), (10.0, 0))
    sim.output(out, every=25, **output)
    sim.run(100)
    return sim


def test_frames_pvd_history_and_run_json(tmp_path: Path) -> None:
    sim = pulled_plate(tmp_path)
    frames = sorted((tmp_path / "frames").glob("frame_*.vtu"))
    assert [f.name for f in frames] == [f"frame_{k:06d}.vtu" for k in range(5)]
    mesh = meshio.read(frames[-1])
    np.testing.assert_array_equal(mesh.points, sim.positions)
    np.testing.assert_array_equal(mesh.point_data["Displacement"], sim.displacements)
    np.testing.assert_array_equal(mesh.point_data["Velocity"], sim.velocities)
    np.testing.assert_array_equal(mesh.point_data["Damage"], sim.damage)
    np.testing.assert_array_equal(mesh.point_data["Nodal_Volume"], sim.volumes)
    assert set(mesh.point_data) == set(gr.FIELDS)
    assert mesh.cells[0].type == "vertex" and len(mesh.cells[0].data) == sim.node_count
    assert mesh.point_data["Fixity"].max() == 3

    collection = ET.parse(tmp_path / "simulation.pvd").getroot().find("Collection")
    datasets = collection.findall("DataSet")
    assert [d.get("file") for d in datasets] == [f"frames/{f.name}" for f in frames]
    times = [float(d.get("timestep")) for d in datasets]
    np.testing.assert_allclose(times, [k * 25 * sim.dt for k in range(5)], rtol=1e-12)

    with (tmp_path / "history.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert [int(r["step"]) for r in rows] == [0, 25, 50, 75, 100]
    last = rows[-1]
    assert float(last["kinetic_energy"]) == pytest.approx(sim.kinetic_energy(), rel=1e-15)
    assert float(last["strain_energy"]) == pytest.approx(sim.strain_energy(), rel=1e-15)
    assert int(last["broken_bonds"]) == sim.broken_bonds()

    summary = json.loads((tmp_path / "run.json").read_text())
    assert summary["nodes"] == sim.node_count and summary["steps"] == 100


def test_selected_fields_only(tmp_path: Path) -> None:
    pulled_plate(tmp_path, fields=("Damage", "Velocity"))
    mesh = meshio.read(tmp_path / "frames" / "frame_000004.vtu")
    assert set(mesh.point_data) == {"Damage", "Velocity"}


def test_existing_run_is_not_overwritten(tmp_path: Path) -> None:
    pulled_plate(tmp_path)
    before = (tmp_path / "history.csv").read_bytes()
    with pytest.raises(gr.InputError, match="already holds a run"):
        pulled_plate(tmp_path)
    assert (tmp_path / "history.csv").read_bytes() == before
    pulled_plate(tmp_path, overwrite=True)


def test_bad_output_requests(tmp_path: Path) -> None:
    sim = gr.Simulation(2)
    with pytest.raises(gr.InputError, match="unknown output fields"):
        sim.output(tmp_path, every=10, fields=("Damage", "Stress"))
    with pytest.raises(gr.InputError, match="positive number of steps"):
        sim.output(tmp_path, every=0)


def test_no_temporary_files_left(tmp_path: Path) -> None:
    pulled_plate(tmp_path)
    assert not list(tmp_path.rglob("*.tmp"))
