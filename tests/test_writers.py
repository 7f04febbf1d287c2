"""The output writers' registry: a frame writer or a history section is one small class,
registered once, and every run's outputs then include it."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest

import granulate as gr
from granulate import writers
from granulate.writers import vtu_frame
from granulate.writers.step_data import StepData


class MaxSpeed:
    """History columns: the largest node speed [m/s]."""

    def columns(self, data: StepData, outputs: writers.Outputs) -> dict[str, float | int]:
        speeds = np.linalg.norm(data.simulation.velocities, axis=1)
        return {"max_speed": float(speeds.max())}


class FrameLog:
    """A frame writer that writes frames/log_NNNNNN.txt with the frame's step."""

    def write(self, data: StepData, outputs: writers.Outputs) -> None:
        path = outputs.directory / "frames" / f"log_{outputs.frames:06d}.txt"
        path.write_text(str(data.simulation.step))


@pytest.fixture
def registries(monkeypatch: pytest.MonkeyPatch) -> None:
    """The registries as shipped, restored after the test."""
    monkeypatch.setattr(writers.registry, "FRAME_WRITERS", list(writers.FRAME_WRITERS))
    monkeypatch.setattr(writers.registry, "HISTORY_SECTIONS", list(writers.HISTORY_SECTIONS))


def falling_disc(out: Path) -> gr.Simulation:
    material = gr.Material(density=2500, youngs_modulus=1e8, poisson_ratio=0.25, fracture=False)
    sim = gr.Simulation(2, gravity=(0, -9.81))
    sim.add_body(gr.Disc((0, 0), 1e-3), material, 2.5e-4)
    sim.output(out, every=50)
    sim.run(200)
    return sim


def test_registered_writers_join_every_frame_and_row(tmp_path: Path, registries: None) -> None:
    writers.register_frame_writer(FrameLog())
    writers.register_history_section(MaxSpeed())
    sim = falling_disc(tmp_path / "out")
    logs = sorted((tmp_path / "out" / "frames").glob("log_*.txt"))
    assert [p.read_text() for p in logs] == ["0", "50", "100", "150", "200"]
    with (tmp_path / "out" / "history.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert list(rows[0])[-1] == "max_speed"  # after the built-in columns
    dt = sim.dt
    for row in rows:  # free fall from rest: v = g t, to round-off
        assert float(row["max_speed"]) == pytest.approx(
            9.81 * int(row["step"]) * dt, rel=1e-9, abs=1e-15
        )


def test_the_built_in_writers_alone_by_default(tmp_path: Path) -> None:
    falling_disc(tmp_path / "out")
    assert not list((tmp_path / "out" / "frames").glob("log_*"))
    with (tmp_path / "out" / "history.csv").open() as handle:
        assert "max_speed" not in next(csv.reader(handle))


@pytest.mark.parametrize("fields", [vtu_frame.FIELDS, ("Displacement", "Damage", "Fixity")])
def test_the_frame_size_rank_0_checks_is_the_rows_it_holds(
    tmp_path: Path, fields: tuple[str, ...]
) -> None:
    """vtu_frame.frame_bytes, which rank 0 of a distributed run checks against its free memory
    before joining frames of every node (twice: the ranks' rows and the frame), is the bytes
    of a frame's rows: positions, the fields and the nodes' numbers (169 bytes a node with
    every field)."""
    sim = falling_disc(tmp_path)
    sim.run(10)
    rows = vtu_frame.node_rows(sim, fields)
    held = rows.numbers.astype(np.int64).nbytes + rows.positions.nbytes
    held += sum(values.nbytes for values in rows.values.values())
    assert vtu_frame.frame_bytes(sim.node_count, fields) == held
    assert vtu_frame.frame_bytes(1, vtu_frame.FIELDS) == 169
