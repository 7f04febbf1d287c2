"""A subset's numbering of the whole assembly's nodes (Assembly.subset), kept per body: each
body's first node there and here. An array over every node of the whole assembly (8 bytes a
node) would be held by every rank of a distributed run whatever it owns."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray


class NodeMap:
    """node_map[g]: the subset's index of the whole assembly's node g, or -1 where the subset
    lacks its body; indexed like an array, by a node, an array of nodes or a slice."""

    def __init__(
        self, starts: NDArray[np.int64], counts: NDArray[np.int64], local: NDArray[np.int64]
    ) -> None:
        """Per body of the whole assembly, in order: its first node, its node count and its
        first node in the subset (-1: not in it)."""
        self._starts, self._counts, self._local = starts, counts, local
        self._node_count = int(starts[-1] + counts[-1]) if len(starts) else 0

    def __getitem__(self, nodes: ArrayLike | slice) -> NDArray[np.int64]:
        if isinstance(nodes, slice):
            nodes = np.arange(*nodes.indices(self._node_count))
        g = np.asarray(nodes, dtype=np.int64)
        if g.size == 0:  # most steps' breaks and joining nodes: no lookup
            return np.zeros(g.shape, dtype=np.int64)
        if g.min() < 0 or g.max() >= self._node_count:
            raise IndexError(f"node index out of range [0, {self._node_count})")
        body = np.searchsorted(self._starts, g, side="right") - 1
        first = self._local[body]
        return np.where(first >= 0, first + (g - self._starts[body]), -1)

    def kept(self) -> NDArray[np.int64]:
        """The whole assembly's nodes the subset holds, in its order (the whole's)."""
        held = np.flatnonzero(self._local >= 0)
        parts = [np.arange(self._starts[b], self._starts[b] + self._counts[b]) for b in held]
        return np.concatenate(parts) if parts else np.zeros(0, dtype=np.int64)
