"""Numeric CSV tables (points with volumes, particle placements) with clear errors."""

from __future__ import annotations

import csv
import io
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from granulate.errors import InputError
from granulate.io.atomic import atomic_write
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


def write_columns(
    path: str | Path, table: Mapping[str, NDArray], columns: Sequence[str], integers: Sequence[str]
) -> None:
    """A table of columns as CSV with a header row (``pandas.read_csv`` reads it), atomically:
    `integers` as integers, the others to 17 significant digits (doubles exactly); a table
    without rows is the header alone."""
    buffer = io.StringIO()
    buffer.write(",".join(columns) + "\n")
    if len(table[columns[0]]):
        formats = ["%d" if name in integers else "%.17g" for name in columns]
        rows = np.column_stack([np.asarray(table[name], dtype=np.float64) for name in columns])
        np.savetxt(buffer, rows, delimiter=",", fmt=formats)
    atomic_write(path, buffer.getvalue().encode())


def read_columns(
    path: str | Path, *, what: str, columns: Sequence[str], integers: Sequence[str]
) -> dict[str, NDArray]:
    """A table written by ``write_columns`` with these `columns` (InputError for another
    file); a header alone gives empty columns."""
    file = existing_file(path, f"{what} file")
    if file.read_text().split() == [",".join(columns)]:
        data = np.zeros((0, len(columns)))
    else:
        data = read_table(file, what=what, widths=(len(columns),), columns=", ".join(columns))
    table = {name: data[:, k] for k, name in enumerate(columns)}
    for name in integers:
        table[name] = table[name].astype(np.int64)
    return table
