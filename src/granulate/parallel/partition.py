"""Whole grains over ranks (DESIGN.md section 7): recursive coordinate bisection of the grains'
centres, weighted by their work, and the ghosts each rank needs for contact.

A grain belongs to one rank with all its nodes, so its bonds never cross ranks; only contact
needs another rank's grains, as ghosts. A rank needs grain j of another rank as a ghost when j's
bounding sphere comes within ``reach`` (the contact reach plus the neighbour skin) of a grain the
rank owns: |c_i - c_j| <= r_i + r_j + reach, the particle-level broad phase the contact lists
start from.

A meshed wall or container is a body too, but a large one: its bounding sphere would take every
grain in, so its pairs with the grains are found from its nodes (near_pairs_with_large,
near_nodes).

Everything here is deterministic: the same grains give the same owners and ghosts on every rank
and machine (ties are broken by grain index), so each rank can compute the partition itself.
NumPy and the core's point grid; no MPI is needed to partition or to measure a partition.

Reference: Berger & Bokhari (1987), "A partitioning strategy for nonuniform problems on
multiprocessors", IEEE Trans. Computers 36(5), for recursive coordinate bisection.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from granulate._core import points_within
from granulate.errors import InputError


@dataclass(frozen=True)
class Partition:
    """Owners of grains: ``owner[g]`` is the rank of grain g, in [0, ranks)."""

    owner: NDArray[np.int64]
    ranks: int

    def grains_of(self, rank: int) -> NDArray[np.int64]:
        """The grains rank `rank` owns, in grain order."""
        return np.flatnonzero(self.owner == rank)

    def loads(self, weights: ArrayLike) -> NDArray[np.float64]:
        """(ranks,) the sum of `weights` (per grain) over each rank's grains."""
        return np.bincount(self.owner, weights=np.asarray(weights, float), minlength=self.ranks)


def bisect(centres: ArrayLike, weights: ArrayLike, ranks: int) -> Partition:
    """Recursive coordinate bisection: the grains are cut across the longest side of their
    bounding box at the weighted position that gives each side its share of the ranks (k // 2
    of k ranks to the lower side), and each side is cut again until one rank is left.

    centres: (grains, 2 or 3) [m]; weights: (grains,) the work of each grain (its nodes, or
    nodes plus bonds), positive. Each cut misses its target by less than one grain's weight, so
    a rank's load differs from the mean by at most about log2(ranks) of the heaviest grains.
    """
    points = np.asarray(centres, dtype=float)
    work = np.asarray(weights, dtype=float)
    _check_grains(points, work, ranks)
    owner = np.empty(len(points), dtype=np.int64)
    pending = [(np.arange(len(points)), 0, ranks)]
    while pending:
        grains, first, count = pending.pop()
        if count == 1:
            owner[grains] = first
            continue
        lower, upper = _cut(points[grains], work[grains], grains, count)
        pending.append((lower, first, count // 2))
        pending.append((upper, first + count // 2, count - count // 2))
    return Partition(owner, ranks)


def _check_grains(points: NDArray[np.float64], work: NDArray[np.float64], ranks: int) -> None:
    if points.ndim != 2 or points.shape[1] not in (2, 3):
        raise InputError(f"centres must be an array of shape (grains, 2 or 3), got {points.shape}")
    if work.shape != (len(points),) or not np.all(np.isfinite(work)) or np.any(work <= 0):
        raise InputError("weights must be one positive number per grain")
    if not (isinstance(ranks, int | np.integer) and 1 <= ranks <= len(points)):
        raise InputError(
            f"ranks must be a whole number from 1 to the number of grains ({len(points)}), "
            f"got {ranks!r}: a rank must own at least one grain"
        )


def _cut(
    points: NDArray[np.float64], work: NDArray[np.float64], grains: NDArray[np.int64], count: int
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """One bisection of `grains` (their points and work) for `count` ranks: the lower side gets
    count // 2 of them and about that share of the work, each side at least as many grains as
    ranks."""
    extent = points.max(axis=0) - points.min(axis=0)
    axis = int(np.argmax(extent))  # the first of equally long sides
    order = np.lexsort((grains, points[:, axis]))  # by coordinate, then by grain index
    cumulative = np.cumsum(work[order])
    target = cumulative[-1] * (count // 2) / count
    split = int(np.searchsorted(cumulative, target))  # cumulative[split] >= target
    if split > 0 and target - cumulative[split - 1] < cumulative[split] - target:
        split -= 1  # the nearer of the two sums to the target
    split = int(np.clip(split + 1, count // 2, len(order) - (count - count // 2)))
    return grains[order[:split]], grains[order[split:]]


def near_pairs(
    centres: ArrayLike, radii: ArrayLike, reach: float
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """The pairs of grains (i < j) whose bounding spheres come within `reach` [m] of each
    other, |c_i - c_j| <= r_i + r_j + reach, found through a cell grid of cells one largest
    diameter plus `reach` wide (each grain is compared with the grains of its own and the
    neighbouring cells only: linear in the number of grains)."""
    points = np.asarray(centres, dtype=float)
    size = np.asarray(radii, dtype=float)
    if not (np.isfinite(reach) and reach >= 0):
        raise InputError(f"reach must be a non-negative distance in m, got {reach!r}")
    dimension = points.shape[1]
    cell = 2 * size.max() + reach
    index = np.floor((points - points.min(axis=0)) / cell).astype(np.int64)
    shape = index.max(axis=0) + 2
    strides = np.cumprod(np.concatenate([[1], shape[:0:-1]]))[::-1]
    key = index @ strides
    order = np.argsort(key, kind="stable")
    sorted_keys = key[order]
    firsts, lasts = [], []
    for offset in _half_neighbourhood(dimension):
        wanted = key + offset @ strides
        begin = np.searchsorted(sorted_keys, wanted, side="left")
        end = np.searchsorted(sorted_keys, wanted, side="right")
        counts = end - begin
        i = np.repeat(np.arange(len(points)), counts)
        starts = np.repeat(begin - np.cumsum(counts) + counts, counts)
        j = order[np.arange(len(i)) + starts]
        same_cell = not np.any(offset)
        keep = (i < j) if same_cell else np.ones(len(i), dtype=bool)
        i, j = i[keep], j[keep]
        close = np.linalg.norm(points[i] - points[j], axis=1) <= size[i] + size[j] + reach
        firsts.append(np.minimum(i[close], j[close]))
        lasts.append(np.maximum(i[close], j[close]))
    first, last = np.concatenate(firsts), np.concatenate(lasts)
    by_pair = np.lexsort((last, first))
    return first[by_pair], last[by_pair]


def near_pairs_with_large(
    centres: ArrayLike,
    radii: ArrayLike,
    reach: float,
    large: ArrayLike,
    large_pairs: tuple[NDArray[np.int64], NDArray[np.int64]],
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """near_pairs for an assembly with a few `large` bodies (grain indices: meshed walls and
    containers, whose bounding spheres would make them near every grain, and the grid's cells
    as wide as them): between two other grains or two large bodies, their bounding spheres;
    between a large body and another grain, `large_pairs` (near_nodes). Sorted as near_pairs
    sorts them."""
    points = np.asarray(centres, dtype=float)
    size = np.asarray(radii, dtype=float)
    large = np.asarray(large, dtype=np.int64)
    if len(large) == 0:
        return near_pairs(points, size, reach)
    big = np.zeros(len(points), dtype=bool)
    big[large] = True
    firsts, lasts = [large_pairs[0]], [large_pairs[1]]
    for group in (np.flatnonzero(~big), np.flatnonzero(big)):
        if len(group) > 1:
            first, last = near_pairs(points[group], size[group], reach)
            firsts.append(group[first])
            lasts.append(group[last])
    first, last = np.concatenate(firsts), np.concatenate(lasts)
    pairs = np.unique(np.column_stack([first, last]), axis=0)
    return pairs[:, 0], pairs[:, 1]


def near_nodes(
    centres: ArrayLike,
    radii: ArrayLike,
    reach: float,
    body: int,
    nodes: ArrayLike,
    large: ArrayLike,
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """The pairs (i < j) of the large body `body`, whose nodes are at `nodes` (k, 3), with the
    grains not in `large` that one of its nodes comes within `reach` [m] of: |x - c_g| <= r +
    reach for a node x, r the largest of those grains' radii (so that every pair whose nodes
    come within `reach` is found)."""
    points = np.asarray(centres, dtype=float)
    size = np.asarray(radii, dtype=float)
    others = np.setdiff1d(np.arange(len(points)), np.asarray(large, dtype=np.int64))
    if len(others) == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    probes = np.zeros((len(others), 3))
    probes[:, : points.shape[1]] = points[others]
    targets = np.ascontiguousarray(np.asarray(nodes, dtype=float).reshape(-1, 3))
    close = np.asarray(points_within(probes, targets, size[others].max() + reach), dtype=bool)
    near = others[close]
    return np.minimum(near, body), np.maximum(near, body)


def _half_neighbourhood(dimension: int) -> NDArray[np.int64]:
    """The cell offsets of one half of the 3^d neighbourhood and the cell itself (each pair of
    neighbouring cells is visited once)."""
    grid = np.meshgrid(*[[-1, 0, 1]] * dimension, indexing="ij")
    offsets = np.array(grid).reshape(dimension, -1).T
    positive = [tuple(o) >= (0,) * dimension for o in offsets]
    return offsets[np.array(positive)]


def ghosts(
    partition: Partition, pairs: tuple[NDArray[np.int64], NDArray[np.int64]]
) -> list[NDArray[np.int64]]:
    """Per rank, the grains of other ranks it needs as ghosts (sorted): the partners, owned
    elsewhere, of its grains in `pairs` (near_pairs)."""
    first, last = pairs
    owner = partition.owner
    crossing = owner[first] != owner[last]
    needs_rank = np.concatenate([owner[first[crossing]], owner[last[crossing]]])
    needs_grain = np.concatenate([last[crossing], first[crossing]])
    order = np.lexsort((needs_grain, needs_rank))
    needs_rank, needs_grain = needs_rank[order], needs_grain[order]
    bounds = np.searchsorted(needs_rank, np.arange(partition.ranks + 1))
    return [np.unique(needs_grain[bounds[r] : bounds[r + 1]]) for r in range(partition.ranks)]
