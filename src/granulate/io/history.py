"""history.csv: one row per output step (time series of energies and counters)."""

from __future__ import annotations

import csv
import os
from collections.abc import Mapping, Sequence
from pathlib import Path


class HistoryWriter:
    """Appends rows to a CSV file with a fixed header; every row is flushed to disk."""

    def __init__(self, path: str | os.PathLike[str], columns: Sequence[str]) -> None:
        self.path = Path(path)
        self.columns = list(columns)
        self._handle = self.path.open("w", newline="")
        self._writer = csv.writer(self._handle)
        self._writer.writerow(self.columns)
        self._handle.flush()

    def write(self, row: Mapping[str, float | int]) -> None:
        self._writer.writerow(
            [repr(row[c]) if isinstance(row[c], float) else row[c] for c in self.columns]
        )
        self._handle.flush()

    def close(self) -> None:
        self._handle.close()
