"""Outputs: VTU frames that VTK readers load (checked with meshio), the PVD series, history.csv,
run.json, and protection of an existing run."""

from __future__ import annotations

import csv
import json
import os
import stat
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from pathlib import Path

import meshio
import numpy as np
import pytest

import granulate as gr
from granulate.plots import render


def pulled_plate(out: Path, steps: int = 100, **output) -> gr.Simulation:
    material = gr.Material(
        density=2500, youngs_modulus=70e9, poisson_ratio=0.22, fracture_energy=8.0
    )
    sim = gr.Simulation(2)
    sim.add_body(gr.Rectangle((0, 0), (0.02, 0.005)), material, 0.5e-3)
    sim.fix(sim.select(gr.Rectangle((-1, -1), (0.0015, 1))))
    sim.prescribe_velocity(sim.select(gr.Rectangle((0.0185, -1), (1, 1))), (10.0, 0))
    sim.output(out, every=25, **output)
    sim.run(steps)
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


def test_frames_in_pieces_are_the_one_file_frames(tmp_path: Path) -> None:
    """Simulation.output(pieces=True) in a serial run: each frame a .pvtu over one piece
    (frame_NNNNNN/piece_0.vtu) of every node with its number (Node_ID), listed in the PVD
    series; read back (Results, restart's reader) it is the one-file frame bit for bit, and
    the contact network's series keeps its .vtu names. --overwrite removes the pieces."""
    pulled_plate(tmp_path / "one")
    pulled_plate(tmp_path / "pieces", pieces=True)
    frames = tmp_path / "pieces" / "frames"
    assert sorted(f.name for f in frames.glob("frame_*.pvtu")) == [
        f"frame_{k:06d}.pvtu" for k in range(5)
    ]
    assert [p.name for p in (frames / "frame_000004").iterdir()] == ["piece_0.vtu"]
    piece = meshio.read(frames / "frame_000004" / "piece_0.vtu")
    np.testing.assert_array_equal(piece.point_data["Node_ID"], np.arange(len(piece.points)))
    one, pieces = gr.Results(tmp_path / "one"), gr.Results(tmp_path / "pieces")
    for k in range(5):
        a, b = one.frame(k), pieces.frame(k)
        np.testing.assert_array_equal(a.positions, b.positions)
        assert a.fields.keys() == b.fields.keys() == set(gr.FIELDS)
        for name, values in a.fields.items():
            assert values.dtype == b.fields[name].dtype
            np.testing.assert_array_equal(values, b.fields[name])
    chains = ET.parse(tmp_path / "pieces" / "contacts.pvd").getroot().iter("DataSet")
    assert [d.get("file") for d in chains][-1] == "frames/contacts_000004.vtu"
    (image,) = render(tmp_path / "pieces", frame=4)
    assert image.name == "frame_000004.png" and image.stat().st_size > 1000
    pulled_plate(tmp_path / "pieces", overwrite=True)
    assert not [p for p in frames.iterdir() if p.is_dir()]


def test_pieces_other_ranks_wrote_where_rank_0_cannot_see_them_stop_the_run(
    tmp_path: Path,
) -> None:
    """Rank 0 writes a frame's .pvtu once every rank has written its piece; a piece it cannot
    see (ranks on machines that do not share the output directory) stops the run with one
    InputError saying so, instead of a .pvtu naming files that are not there. Here rank 0's
    outputs are told that 2 ranks wrote pieces, and none did."""
    material = gr.Material(density=2500, youngs_modulus=70e9, poisson_ratio=0.22, fracture=False)
    sim = gr.Simulation(2)
    sim.add_body(gr.Rectangle((0, 0), (0.02, 0.005)), material, 1e-3)
    sim.output(tmp_path, every=10, pieces=True)
    sim._output.piece_ranks = 2
    with pytest.raises(gr.InputError, match=r"piece_0\.vtu, piece_1\.vtu written by the other"):
        sim.run(10)
    assert not list((tmp_path / "frames").glob("*.pvtu"))


def test_a_parallel_frame_with_bad_pieces_is_refused(tmp_path: Path) -> None:
    """A .pvtu whose piece is missing, or whose pieces number a node twice: one InputError
    naming the file."""
    pulled_plate(tmp_path, pieces=True)
    frame = tmp_path / "frames" / "frame_000001.pvtu"
    text = frame.read_text()
    frame.write_text(text.replace("piece_0.vtu", "piece_9.vtu"))
    with pytest.raises(gr.InputError, match=r"piece_9\.vtu"):
        gr.Results(tmp_path).frame(1)
    piece = '<Piece Source="frame_000001/piece_0.vtu"/>'
    frame.write_text(text.replace(piece, 2 * piece))
    with pytest.raises(gr.InputError, match=r"frame_000001\.pvtu: its pieces' Node_IDs"):
        gr.Results(tmp_path).frame(1)


def test_no_temporary_files_left(tmp_path: Path) -> None:
    pulled_plate(tmp_path)
    assert not list(tmp_path.rglob("*.tmp"))


def frame_steps(directory: Path, dt: float) -> list[int]:
    """The steps of the frames the PVD series lists."""
    collection = ET.parse(directory / "simulation.pvd").getroot().find("Collection")
    return [round(float(d.get("timestep")) / dt) for d in collection.findall("DataSet")]


def test_a_run_ending_between_output_steps_writes_its_last_step(tmp_path: Path) -> None:
    """Outputs every 25 steps, a run of 110: the frame and history row of step 110 are written
    (before, the outputs ended at step 100 and run.json said 100 steps and 0.0 s)."""
    sim = pulled_plate(tmp_path, steps=110)
    assert frame_steps(tmp_path, sim.dt) == [0, 25, 50, 75, 100, 110]
    mesh = meshio.read(tmp_path / "frames" / "frame_000005.vtu")
    np.testing.assert_array_equal(mesh.points, sim.positions)
    with (tmp_path / "history.csv").open() as handle:
        steps = [int(r["step"]) for r in csv.DictReader(handle)]
    assert steps == [0, 25, 50, 75, 100, 110]
    summary = json.loads((tmp_path / "run.json").read_text())
    assert summary["steps"] == 110 and summary["steps_run"] == 110
    assert summary["wall_seconds"] > 0
    sim.run(15)  # continuing: outputs on the every-25 grid again, and the new last step
    assert frame_steps(tmp_path, sim.dt) == [0, 25, 50, 75, 100, 110, 125]
    assert json.loads((tmp_path / "run.json").read_text())["steps_run"] == 125


def test_a_run_in_pieces_can_leave_out_the_last_step(tmp_path: Path) -> None:
    sim = pulled_plate(tmp_path, steps=0)
    for _ in range(11):
        sim.run(10, write_final=False)
    assert frame_steps(tmp_path, sim.dt) == [0, 25, 50, 75, 100]
    assert json.loads((tmp_path / "run.json").read_text())["steps"] == 110


@pytest.fixture
def umask() -> Iterator[None]:
    previous = os.umask(0o022)
    try:
        yield
    finally:
        os.umask(previous)


def file_modes(directory: Path) -> dict[str, int]:
    return {
        str(p.relative_to(directory)): stat.S_IMODE(p.stat().st_mode)
        for p in directory.rglob("*")
        if p.is_file()
    }


@pytest.mark.parametrize("mask", [0o022, 0o027, 0o077], ids=["022", "027", "077"])
def test_output_files_honour_the_umask(tmp_path: Path, umask: None, mask: int) -> None:
    """Frames, PVD, particle tables, history, run.json and checkpoints get 0666 less the umask,
    as open() gives (they were 0600 whatever the umask: colleagues could not read them)."""
    os.umask(mask)
    sim = pulled_plate(tmp_path, steps=0)
    sim.checkpoint_every(50, path=tmp_path / "checkpoint.npz")
    sim.run(60)
    modes = file_modes(tmp_path)
    assert {"simulation.pvd", "history.csv", "run.json", "checkpoint.npz"} <= set(modes)
    assert any(name.endswith(".csv") and "particles" in name for name in modes)
    assert set(modes.values()) == {0o666 & ~mask}, modes


def test_an_existing_file_keeps_its_mode_when_rewritten(tmp_path: Path, umask: None) -> None:
    sim = pulled_plate(tmp_path, steps=25)
    (tmp_path / "run.json").chmod(0o600)
    sim.run(5)  # rewrites run.json
    assert stat.S_IMODE((tmp_path / "run.json").stat().st_mode) == 0o600
