"""Numeric CSV tables (points with volumes, particle placements) with clear errors."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from granulate.errors import InputError
from granulate.io.files import existing_file


def read_table(
    path: str | Path, *, what: str, widths: tuple[int, ...], columns: str
) -> NDArray[np.float64]:
    """Rows of numbers from a CSV file: an optional header line, ``#`` comments and blank lines
    skipped; every row has one of ``widths`` values, the same on every line (``columns`` names
    them in messages). ``what`` names the file's content (``"points"``)."""
    file = existing_file(path, f"{what} file")
    rows: list[list[float]] = []
    with file.open(newline="") as handle:
        for number, row in enumerate(csv.reader(handle), start=1):
            cells = [c.strip() for c in row]
            if not any(cells) or cells[0].startswith("#"):
                continue
            try:
                values = [float(c) for c in cells]
            except ValueError:
                if not rows and number == 1:
                    continue  # the header
                raise InputError(f"{file}, line {number}: expected numbers, got {row}") from None
            if len(values) not in widths or (rows and len(values) != len(rows[0])):
                raise InputError(
                    f"{file}, line {number}: expected {' or '.join(map(str, widths))} columns "
                    f"({columns}) on every line, got {len(values)}"
                )
            rows.append(values)
    if not rows:
        raise InputError(f"{file} holds no {what}")
    return np.asarray(rows)
