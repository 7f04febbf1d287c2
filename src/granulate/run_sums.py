"""Sums over groups of nodes (particles, fragments) whose bits do not depend on how the nodes are
dealt to processes: each group's nodes are added run by run, a run being consecutive nodes of
the group within one block of 64 node indices (the core's kRunBlock, run_sums.hpp), and a
group's runs are then added in node order.

A process that holds whole blocks (a distributed run's whole grains, or a body cut at node
level in blocks: parallel/node_split.py) makes the runs of its nodes exactly as one holding
every node does, so the runs of every process, joined in node order, add up to the serial
run's sums to the bit (np.bincount adds in the order given). The particle and fragment tables
are made of such sums (particle_table.py, fragments.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from granulate import _core
from granulate.errors import InputError

#: The node indices of a block: no run crosses a multiple of it (the core's kRunBlock).
BLOCK = 64


@dataclass(frozen=True)
class Runs:
    """Per run: its first node, its node count, its group and the sums of its values (r, m),
    in node order."""

    first: NDArray[np.int64]
    length: NDArray[np.int64]
    group: NDArray[np.int64]
    sums: NDArray[np.float64]

    @classmethod
    def of(cls, groups: ArrayLike, nodes: ArrayLike, values: ArrayLike) -> Runs:
        """The runs of `nodes` (increasing node indices) in their `groups`, summing the rows of
        `values` (n, m) in node order (_core.run_sums)."""
        table = np.ascontiguousarray(values, dtype=np.float64)
        first, length, group, sums = _core.run_sums(
            np.ascontiguousarray(groups, dtype=np.int64),
            np.ascontiguousarray(nodes, dtype=np.int64),
            table[:, None] if table.ndim == 1 else table,
        )
        return cls(first, length, group, sums)

    @classmethod
    def first_sums(
        cls,
        groups: ArrayLike,
        nodes: ArrayLike,
        mass: ArrayLike,
        volumes: ArrayLike,
        positions: ArrayLike,
        velocities: ArrayLike,
    ) -> Runs:
        """The runs of the first sums, 8 a run: m, V, m x (3), m v (3), from each
        node's mass [kg], volume, position [m] and velocity [m/s] (_core.first_runs)."""
        return cls(
            *_core.first_runs(
                _ints(groups), _ints(nodes), *_floats(mass, volumes, positions, velocities)
            )
        )

    @classmethod
    def moments(
        cls,
        groups: ArrayLike,
        nodes: ArrayLike,
        mass: ArrayLike,
        positions: ArrayLike,
        velocities: ArrayLike,
        centres: ArrayLike,
        centre_velocities: ArrayLike,
    ) -> Runs:
        """The runs of the sums about each group's centre and velocity (count, 3 each; groups
        0 .. count - 1), 10 a run: angular momentum (3), inertia tensor (xx, yy, zz, xy, xz,
        yz) and spread sum m |x - c|^2 (_core.moment_runs)."""
        arrays = _floats(mass, positions, velocities, centres, centre_velocities)
        return cls(*_core.moment_runs(_ints(groups), _ints(nodes), *arrays))

    @classmethod
    def joined(cls, parts: list[Runs]) -> Runs:
        """The runs of several processes' nodes (no node in two), in node order."""
        first = np.concatenate([part.first for part in parts])
        order = np.argsort(first, kind="stable")
        return cls(
            first[order],
            np.concatenate([part.length for part in parts])[order],
            np.concatenate([part.group for part in parts])[order],
            np.concatenate([part.sums for part in parts])[order],
        )

    def totals(self, count: int, places: NDArray[np.int64] | None = None) -> NDArray[np.float64]:
        """(count, m): per group its runs' sums added in node order. `places`: each run's row
        of the result; by default its group (groups 0 .. count - 1)."""
        rows = self.group if places is None else places
        if len(rows) and (rows.min() < 0 or rows.max() >= count):
            raise InputError(f"run sums: a run's group is past count ({count})")
        columns = self.sums.shape[1]
        out = np.empty((count, columns))
        for k in range(columns):
            out[:, k] = np.bincount(rows, self.sums[:, k], count)
        return out

    def nodes(self, count: int, places: NDArray[np.int64] | None = None) -> NDArray[np.int64]:
        """Per group its node count (`places` as for totals)."""
        return np.bincount(self.group if places is None else places, self.length, count)


def _ints(values: ArrayLike) -> NDArray[np.int64]:
    return np.ascontiguousarray(values, dtype=np.int64)


def _floats(*arrays: ArrayLike) -> list[NDArray[np.float64]]:
    return [np.ascontiguousarray(a, dtype=np.float64) for a in arrays]
