"""PeriDEM's decks for the tests (copies in tests/data/peridem, see its README) and helpers to run
them, edit them and read PeriDEM's own results: shared by test_peridem.py (runs against PeriDEM)
and test_peridem_input.py (the decks as input)."""

from __future__ import annotations

import csv
import shutil
from pathlib import Path

import meshio
import numpy as np

from granulate.cli import main

DECKS = Path(__file__).parent / "data" / "peridem"
NAMES = [
    "twop_circ",
    "single_particle_rectangle_inbuilt_mesh",
    "compression_small_set",
    "attrition_mix_particles_small_set",
]


def reference(name: str) -> np.ndarray:
    """PeriDEM's frames_summary.csv: frame, step, time, particle, zone, nodes, cx, cy, ux, uy,
    vx, vy, max Z, mean Z, fx, fy."""
    return np.loadtxt(
        DECKS / name / "peridem_output" / "frames_summary.csv", delimiter=",", skiprows=1
    )


def summary(name: str) -> dict[str, str]:
    text = (DECKS / name / "peridem_output" / "run_summary_1thread.txt").read_text()
    return dict(line.split(" = ") for line in text.splitlines())


def run_deck(
    name: str, out: Path, steps: int | None, *extra: str, deck: Path | None = None
) -> Path:
    """Run PeriDEM's deck `name` (or an edited copy of it, `deck`) with granulate's CLI."""
    path = deck or DECKS / name / "input_0.yaml"
    args = ["run", str(path), "--out", str(out), "--quiet", *extra]
    if steps is not None:
        args += ["--steps", str(steps)]
    assert main(args) == 0
    return out


def frame(out: Path, k: int):
    return meshio.read(out / "frames" / f"frame_{k:06d}.vtu")


def centroids(mesh, count: int) -> np.ndarray:
    owner = mesh.point_data["Particle_ID"]
    return np.array([mesh.points[owner == p, :2].mean(axis=0) for p in range(count)])


def history(out: Path) -> list[dict[str, float]]:
    with (out / "history.csv").open() as handle:
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(handle)]


def broken_deck(tmp_path: Path, name: str, edit) -> Path:
    folder = tmp_path / name
    shutil.copytree(DECKS / name, folder)
    deck = folder / "input_0.yaml"
    deck.write_text(edit(deck.read_text()))
    return deck
