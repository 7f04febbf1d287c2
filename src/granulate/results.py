"""A run's output folder read back: ``gr.Results("out/run")``.

The history is a dict of NumPy columns (``pandas.DataFrame(results.history)`` makes it a data
frame), frames are picked by number or by time and come as positions and point-data arrays,
and each frame's particle, fragment and contact tables are dicts of columns too. Nothing needs
ParaView or a PVD parser.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from granulate import fragments, network, particle_table
from granulate.errors import InputError
from granulate.io.history import read_history
from granulate.io.vtu import read_pvd, read_vtu_point_data


@dataclass(frozen=True)
class Frame:
    """One output frame: its number, time [s], node positions [m] (n x 3) and point data
    (Displacement, Velocity, Damage, Fragment_ID, ... as written)."""

    index: int
    time: float
    positions: NDArray[np.float64]
    fields: dict[str, NDArray[Any]]

    def __getitem__(self, field: str) -> NDArray[Any]:
        if field not in self.fields:
            raise InputError(
                f"frame {self.index} has no field {field!r}; it has {list(self.fields)}"
            )
        return self.fields[field]


class Results:
    """The outputs of a run in `directory` (what ``Simulation.output`` or ``granulate run``
    wrote): ``history``, ``times``, ``frame(k)`` or ``frame(time=t)``, ``particles(k)``,
    ``fragments(k)`` and ``summary`` (run.json). Negative frame numbers count from the end."""

    def __init__(self, directory: str | Path) -> None:
        self.directory = Path(directory)
        if not (self.directory / "simulation.pvd").is_file():
            raise InputError(
                f"{self.directory} holds no simulation.pvd; give the output directory of a run"
            )
        entries = read_pvd(self.directory / "simulation.pvd")
        self.times = np.array([time for time, _ in entries])
        self._files = [path for _, path in entries]

    def __len__(self) -> int:
        return len(self._files)

    def __repr__(self) -> str:
        span = f", t = {self.times[0]:.4g} .. {self.times[-1]:.4g} s" if len(self) else ""
        return f"Results({str(self.directory)!r}: {len(self)} frames{span})"

    @property
    def history(self) -> dict[str, NDArray[np.float64]]:
        """history.csv as columns (step, time, energies, counts, wall forces, ...)."""
        return read_history(self.directory)

    @property
    def summary(self) -> dict[str, Any]:
        """run.json: counts, steps, wall time and the run's status."""
        path = self.directory / "run.json"
        try:
            return json.loads(path.read_text())
        except (OSError, ValueError) as error:
            raise InputError(f"cannot read {path}: {error}") from None

    def index(self, frame: int | None = None, *, time: float | None = None) -> int:
        """A frame number: `frame` itself (negative from the end), or the frame nearest `time`."""
        if (frame is None) == (time is None):
            raise InputError("give a frame number or a time, not both or neither")
        if not len(self):
            raise InputError(f"{self.directory} has no frames yet")
        if time is not None:
            return int(np.argmin(np.abs(self.times - float(time))))
        if not isinstance(frame, int | np.integer) or not -len(self) <= frame < len(self):
            raise InputError(f"frame {frame!r} does not exist: the run has {len(self)} frames")
        return int(frame) % len(self)

    def frame(self, frame: int | None = None, *, time: float | None = None) -> Frame:
        """Positions and point data of a frame (by number, or the nearest to `time`)."""
        k = self.index(frame, time=time)
        positions, fields = read_vtu_point_data(self._files[k])
        return Frame(k, float(self.times[k]), positions, fields)

    def particles(
        self, frame: int | None = None, *, time: float | None = None
    ) -> particle_table.Table:
        """The frame's particle table (granulate.particle_table.COLUMNS): particle, time,
        centre x y z [m], velocity vx vy vz [m/s], angular velocity wx wy wz [rad/s], mass
        [kg; kg/m in 2D], gyration_radius [m], damage, coordination and the Love-Weber stress
        sxx ... syz [Pa]."""
        k = self.index(frame, time=time)
        return particle_table.read_table(self._files[k].parent / f"particles_{self._number(k)}.csv")

    def contacts(self, frame: int | None = None, *, time: float | None = None) -> network.Table:
        """The frame's contact table (granulate.network.COLUMNS): the bodies in contact, the
        contact point, normal, force, and normal and tangential force."""
        k = self.index(frame, time=time)
        return network.read_table(self._files[k].parent / f"contacts_{self._number(k)}.csv")

    def fragments(self, frame: int | None = None, *, time: float | None = None) -> fragments.Table:
        """The frame's fragment table (granulate.fragments.COLUMNS)."""
        k = self.index(frame, time=time)
        return fragments.read_table(self._files[k].parent / f"fragments_{self._number(k)}.csv")

    def _number(self, k: int) -> str:
        """The NNNNNN of frame k's file name (frame_NNNNNN.vtu)."""
        return self._files[k].stem.rsplit("_", 1)[-1]
