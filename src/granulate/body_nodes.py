"""Where the Assembly keeps each body's nodes until the core is built: the arrays of a body
discretised where it stands or given as nodes, and of a particle placed from a reference shape
only its placement, its nodes computed when asked. A packing of many grains then holds no node
arrays of its own (32 bytes a node): a distributed run's rank computes those of the grains it
builds, and a serial run those of every grain once, when it builds its model."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import overload

import numpy as np
from numpy.typing import NDArray

from granulate.reference_shapes import ReferenceShape


# eq=False: node arrays are compared by their owners, not as fields of these records.
@dataclass(frozen=True, eq=False)
class StoredNodes:
    """A body's node positions (n, 3) [m] and volumes (n,) [m^3; m^2 in 2D], as given."""

    position_array: NDArray[np.float64]
    volume_array: NDArray[np.float64]

    @property
    def node_count(self) -> int:
        return len(self.volume_array)

    def positions(self) -> NDArray[np.float64]:
        return self.position_array

    def volumes(self) -> NDArray[np.float64]:
        return self.volume_array


@dataclass(frozen=True, eq=False)
class PlacedNodes:
    """A particle placed from a reference shape: x = c + R (s p) for each node p of the shape
    [m] (z = 0 in 2D), and volumes s^d V; computed anew at each call, to the same bits."""

    reference: ReferenceShape
    centre: NDArray[np.float64]  # c, (3,)
    rotation: NDArray[np.float64]  # R, (3, 3)
    scale: float  # s
    dimension: int

    @property
    def node_count(self) -> int:
        return len(self.reference.volumes)

    def positions(self) -> NDArray[np.float64]:
        placed = self.centre + (self.scale * self.reference.positions) @ self.rotation.T
        if self.dimension == 2:
            placed[:, 2] = 0.0
        return placed

    def volumes(self) -> NDArray[np.float64]:
        return self.reference.volumes * self.scale**self.dimension


BodyNodes = StoredNodes | PlacedNodes


class NodeField(Sequence[NDArray[np.float64]]):
    """Per body, its positions or its volumes (`field`), read from `entries` when indexed."""

    def __init__(self, entries: list[BodyNodes], field: str) -> None:
        self._entries, self._field = entries, field

    def __len__(self) -> int:
        return len(self._entries)

    @overload
    def __getitem__(self, k: int) -> NDArray[np.float64]: ...

    @overload
    def __getitem__(self, k: slice) -> list[NDArray[np.float64]]: ...

    def __getitem__(self, k: int | slice) -> NDArray[np.float64] | list[NDArray[np.float64]]:
        if isinstance(k, slice):
            return [getattr(entry, self._field)() for entry in self._entries[k]]
        return getattr(self._entries[k], self._field)()

    def __iter__(self) -> Iterator[NDArray[np.float64]]:
        return (getattr(entry, self._field)() for entry in self._entries)
