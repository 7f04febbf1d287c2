"""history.csv: one row per output step (time series of energies and counters)."""

from __future__ import annotations

import csv
import io
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from granulate.errors import InputError


class HistoryWriter:
    """Appends rows to a CSV file with a fixed header; every row is flushed to disk."""

    def __init__(self, path: str | os.PathLike[str], columns: Sequence[str]) -> None:
        self.path = Path(path)
        self.columns = list(columns)
        self._handle = self.path.open("w", newline="")
        self._writer = csv.writer(self._handle)
        self._writer.writerow(self.columns)
        self._handle.flush()

    @classmethod
    def resume(cls, path: str | os.PathLike[str], last_step: int) -> HistoryWriter:
        """Reopen a history for appending, keeping its rows up to ``last_step`` (a run resumed
        from a checkpoint rewrites the rows after it)."""
        from granulate.io.atomic import atomic_write

        target = Path(path)
        with target.open(newline="") as handle:
            rows = list(csv.reader(handle))
        if not rows or "step" not in rows[0]:
            raise ValueError(f"{target} is not a history file")
        column = rows[0].index("step")
        kept = [rows[0]] + [
            r for r in rows[1:] if len(r) == len(rows[0]) and int(r[column]) <= last_step
        ]
        buffer = io.StringIO()
        csv.writer(buffer).writerows(kept)
        atomic_write(target, buffer.getvalue().encode())
        writer = cls.__new__(cls)
        writer.path = target
        writer.columns = list(rows[0])
        writer._handle = target.open("a", newline="")
        writer._writer = csv.writer(writer._handle)
        return writer

    def write(self, row: Mapping[str, float | int]) -> None:
        self._writer.writerow(
            [repr(row[c]) if isinstance(row[c], float) else row[c] for c in self.columns]
        )
        self._handle.flush()

    def close(self) -> None:
        self._handle.close()


def read_history(directory: str | Path) -> dict[str, np.ndarray]:
    """history.csv as columns of floats."""
    path = Path(directory) / "history.csv"
    if not path.is_file():
        raise InputError(f"{path} does not exist; give the output directory of a run")
    with path.open(newline="") as handle:
        rows = list(csv.reader(handle))
    if len(rows) < 2:
        raise InputError(f"{path} has no rows yet")
    header = rows[0]
    try:
        data = np.array([[float(v) for v in row] for row in rows[1:] if len(row) == len(header)])
    except ValueError as error:
        raise InputError(f"{path} is not a granulate history ({error})") from None
    return {name: data[:, k] for k, name in enumerate(header)}
