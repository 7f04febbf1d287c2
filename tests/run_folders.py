"""Comparing a distributed run's output folder with the serial run's (tests/test_mpi_cli.py and
tests/mpi_check.py): the files that must be equal byte for byte, and history.csv's rows."""

from __future__ import annotations

import csv
from pathlib import Path

from granulate.io.run_folder import CHECKPOINT_PIECES

#: What a distributed run's folder may hold differently: its timings (run.json), and its
#: checkpoint (the same state in the ranks' pieces, with neighbour lists searched anew: it
#: restarts bit for bit).
DIFFERENT = {"run.json", "checkpoint.npz"}
#: The folder of a distributed run's checkpoint pieces.
PIECES = CHECKPOINT_PIECES
#: history.csv's count of neighbour-list searches, which each rank makes for its own part (the
#: largest over the ranks is written): a diagnostic of the run, not of its physics.
SEARCHES = "list_rebuilds"


def outputs(directory: Path) -> dict[str, bytes]:
    """Every file of a run's folder but those that may differ and history.csv, by relative
    path."""
    return {
        str(p.relative_to(directory)): p.read_bytes()
        for p in sorted(directory.rglob("*"))
        if p.is_file()
        and p.name not in DIFFERENT
        and p.name != "history.csv"
        and PIECES not in p.relative_to(directory).parts
    }


def differing(serial: Path, other: Path) -> list[str]:
    """The files of `outputs` that differ between two folders, or that one lacks."""
    expected, found = outputs(serial), outputs(other)
    names = sorted(set(expected) | set(found))
    return [name for name in names if expected.get(name) != found.get(name)]


def history(directory: Path) -> list[dict[str, str]]:
    """history.csv's rows, as text."""
    with open(directory / "history.csv", newline="") as table:
        return list(csv.DictReader(table))
