"""Bodies added one by one that are translated copies of each other share one core shape.

`Simulation.add_body` discretises each shape where it stands, so six equal discs at six places
are six node sets. Each would get its own bond family (16 bytes a bond) although their bonds
are the same. `TranslatedShapes` recognises a body whose nodes are those of an earlier body
moved by one vector, with the same volumes, mesh size and surface data, and names that earlier
body, so that the core keeps one shape and bond family for all of them (as it does for
particles placed from one `ReferenceShape`), and the memory check counts that family once.

A copy is accepted when every node lies within ``TOLERANCE`` mesh sizes of the earlier body's
node moved by the vector between their first nodes. The shared family's reference lengths are
then those of the first body; the copy's own differ from them by at most 2 TOLERANCE h: a
strain of at most 2e-10 at rest. Round-off leaves about 1e-14 h between the copies of a lattice
near the origin, and 2e-12 h for coordinates of 1 m at h = 0.1 mm; bodies farther from exact
copies are given shapes of their own. Their surface data must match too: depths within
``TOLERANCE`` mesh sizes, and offsets (unit normals under the surface law, from central
differences of the shape's signed distance over h/1000, which round-off leaves eps |x| /
(h/1000) apart: 4e-12 for millimetre coordinates at h = 0.1 mm, 2e-9 at 1 m) within
``OFFSET_TOLERANCE``, which moves a surface point (at most h deep) by at most 1e-8 h.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

#: Largest deviation from an exact translated copy [mesh sizes].
TOLERANCE = 1e-10
#: Largest difference between the surface offsets of copies [-].
OFFSET_TOLERANCE = 1e-8


#: A body's surface data (offsets, depths), computed when asked: only a body whose nodes match
#: an earlier body's needs it, and a distributed run scans every grain of the whole assembly.
Surface = Callable[[], tuple[NDArray[np.float64], NDArray[np.float64]]]


@dataclass(eq=False)
class _Known:
    """An earlier body's arrays (references, not copies) and its surface data, computed once
    when first compared."""

    body: int
    positions: NDArray[np.float64]
    volumes: NDArray[np.float64]
    compute_surface: Surface

    @functools.cached_property
    def surface(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The body's surface data (offsets, depths), computed when first read."""
        return self.compute_surface()


class TranslatedShapes:
    """The bodies without a reference shape seen so far, by their nodes."""

    def __init__(self) -> None:
        self._known: dict[tuple[int, float], list[_Known]] = {}

    def find(
        self,
        positions: NDArray[np.float64],
        volumes: NDArray[np.float64],
        mesh_size: float,
        surface: Surface,
    ) -> int | None:
        """The earlier body these nodes are a translated copy of, or None. `surface` (this
        body's surface data) is called only when the nodes and volumes match an earlier
        body's, at most once."""
        tolerance = TOLERANCE * mesh_size
        arrays = None
        for known in self._known.get((len(positions), mesh_size), []):
            shift = positions[0] - known.positions[0]
            if not (
                np.max(np.abs(positions[-1] - known.positions[-1] - shift)) <= tolerance
                and np.array_equal(known.volumes, volumes)
                and np.max(np.abs(positions - known.positions - shift)) <= tolerance
            ):
                continue
            arrays = surface() if arrays is None else arrays
            if _same_surface(known.surface, arrays, tolerance):
                return known.body
        return None

    def remember(
        self,
        body: int,
        positions: NDArray[np.float64],
        volumes: NDArray[np.float64],
        mesh_size: float,
        surface: Surface,
    ) -> None:
        """Record body number `body` with these nodes (`surface`: its surface data, asked for
        when a later body's nodes match)."""
        known = _Known(body, positions, volumes, surface)
        self._known.setdefault((len(positions), mesh_size), []).append(known)


def _same_surface(
    known: tuple[NDArray[np.float64], NDArray[np.float64]],
    surface: tuple[NDArray[np.float64], NDArray[np.float64]],
    depth_tolerance: float,
) -> bool:
    """Offsets within OFFSET_TOLERANCE and depths within `depth_tolerance` [m] of an earlier
    body's (both empty where a body has none)."""
    (known_offsets, known_depths), (offsets, depths) = known, surface
    if known_offsets.shape != offsets.shape or known_depths.shape != depths.shape:
        return False
    return bool(
        np.all(np.abs(offsets - known_offsets) <= OFFSET_TOLERANCE)
        and np.all(np.abs(depths - known_depths) <= depth_tolerance)
    )
