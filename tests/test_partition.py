"""Whole grains over ranks (granulate.parallel.partition): the recursive coordinate bisection
balances the work and cuts space into compact blocks, the broad phase finds exactly the pairs
of grains in reach, and each rank's ghosts are exactly the other ranks' grains near its own."""

from __future__ import annotations

import numpy as np
import pytest

import granulate as gr
from granulate.parallel import bisect, ghosts, near_pairs
from granulate.parallel.partition import near_nodes, near_pairs_with_large
from granulate.parallel.work_load import BOND_COPY, LIST_ENTRY, node_work


def grains(count: int, dimension: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Random centres in a box of side 50 mm and radii from 0.5 to 2 mm (they may overlap:
    the partition only looks at centres and bounding spheres)."""
    rng = np.random.default_rng(seed)
    return rng.uniform(0, 0.05, (count, dimension)), rng.uniform(0.5e-3, 2e-3, count)


def brute_force_pairs(centres: np.ndarray, radii: np.ndarray, reach: float) -> np.ndarray:
    distance = np.linalg.norm(centres[:, None] - centres[None], axis=2)
    close = np.triu(distance <= radii[:, None] + radii[None] + reach, 1)
    return np.argwhere(close)


@pytest.mark.parametrize("dimension", [2, 3])
@pytest.mark.parametrize("reach", [0.0, 0.3e-3, 3e-3])
def test_near_pairs_are_the_pairs_in_reach(dimension: int, reach: float) -> None:
    centres, radii = grains(1500, dimension)
    first, last = near_pairs(centres, radii, reach)
    expected = brute_force_pairs(centres, radii, reach)
    assert len(expected) > 100
    np.testing.assert_array_equal(np.column_stack([first, last]), expected)


@pytest.mark.parametrize("dimension", [2, 3])
@pytest.mark.parametrize("ranks", [1, 2, 3, 7, 16])
def test_bisection_gives_every_rank_its_share_of_the_work(dimension: int, ranks: int) -> None:
    centres, radii = grains(2000, dimension)
    work = (radii / radii.min()) ** dimension  # nodes grow as the grain's volume
    partition = bisect(centres, work, ranks)
    assert partition.owner.shape == (2000,)
    assert set(np.unique(partition.owner)) == set(range(ranks))
    loads = partition.loads(work)
    assert loads.sum() == pytest.approx(work.sum(), rel=1e-12)
    levels = int(np.ceil(np.log2(ranks)))
    assert np.all(np.abs(loads - work.sum() / ranks) <= levels * work.max() + 1e-12 * work.sum())


def test_bisection_of_a_cubic_lattice_gives_cubic_blocks() -> None:
    """8 x 8 x 8 equal grains on 8 ranks: each rank gets one 4 x 4 x 4 octant."""
    axis = np.arange(8) * 2.5e-3
    centres = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1).reshape(-1, 3)
    partition = bisect(centres, np.ones(len(centres)), 8)
    for rank in range(8):
        block = np.round(centres[partition.grains_of(rank)] / 2.5e-3).astype(int)
        assert len(block) == 64
        assert np.all(block.max(axis=0) - block.min(axis=0) == 3)


def test_bisection_does_not_depend_on_the_order_of_the_grains() -> None:
    centres, radii = grains(1000, 3)
    permutation = np.random.default_rng(1).permutation(1000)
    first = bisect(centres, radii**3, 6).owner
    again = bisect(centres, radii**3, 6).owner
    permuted = bisect(centres[permutation], radii[permutation] ** 3, 6).owner
    np.testing.assert_array_equal(first, again)
    np.testing.assert_array_equal(permuted, first[permutation])


def wall_nodes(dimension: int, axis: int) -> np.ndarray:
    """A box wall's nodes, 0.5 mm apart (1 mm in 3D) over its 50 mm side(s): the plane where
    coordinate `axis` is 0."""
    line = np.arange(0, 0.05, 0.5e-3 if dimension == 2 else 1e-3)
    grid = np.meshgrid(*[line] * (dimension - 1), indexing="ij")
    nodes = np.zeros((grid[0].size, 3))
    others = [k for k in range(dimension) if k != axis]
    for k, g in zip(others, grid, strict=True):
        nodes[:, k] = g.ravel()
    return nodes


@pytest.mark.parametrize("dimension", [2, 3])
def test_a_large_bodys_pairs_are_the_grains_its_nodes_come_near(dimension: int) -> None:
    """Two large bodies (the floor and a side of a box of 50 mm, as nodes) among 1,500 grains:
    a grain is paired with a wall when one of the wall's nodes lies within the largest grain
    radius plus the reach of its centre (not when the walls' bounding spheres, which hold the
    whole box, reach it); other pairs as near_pairs finds them."""
    centres, radii = grains(1500, dimension)
    reach = 0.3e-3
    walls = [wall_nodes(dimension, 1), wall_nodes(dimension, 0)]
    large = np.array([1500, 1501])
    every_centre = np.vstack([centres, [w[len(w) // 2, :dimension] for w in walls]])
    every_radius = np.concatenate([radii, [0.04, 0.04]])
    found = [
        near_nodes(every_centre, every_radius, reach, g, w, large)
        for g, w in zip(large, walls, strict=True)
    ]
    large_pairs = tuple(np.concatenate([f[k] for f in found]) for k in (0, 1))
    first, last = near_pairs_with_large(every_centre, every_radius, reach, large, large_pairs)
    expected = [tuple(pair) for pair in brute_force_pairs(centres, radii, reach)]
    expected.append((1500, 1501))
    for k, w in enumerate(walls):
        c, x = centres, w[:, :dimension]
        gap2 = (c**2).sum(1)[:, None] - 2 * c @ x.T + (x**2).sum(1)[None]
        near = np.flatnonzero(gap2.min(axis=1) <= (radii.max() + reach) ** 2)
        assert 20 < len(near) < 300
        expected += [(int(g), 1500 + k) for g in near]
    assert sorted(zip(first.tolist(), last.tolist(), strict=True)) == sorted(expected)


@pytest.mark.parametrize("dimension", [2, 3])
def test_ghosts_are_the_other_ranks_grains_in_reach(dimension: int) -> None:
    centres, radii = grains(1200, dimension)
    reach = 0.5e-3
    partition = bisect(centres, np.ones(1200), 5)
    needed = ghosts(partition, near_pairs(centres, radii, reach))
    distance = np.linalg.norm(centres[:, None] - centres[None], axis=2)
    close = distance <= radii[:, None] + radii[None] + reach
    for rank in range(5):
        own = partition.owner == rank
        expected = np.flatnonzero(close[own].any(axis=0) & ~own)
        assert len(expected) > 0
        np.testing.assert_array_equal(needed[rank], expected)


def test_bad_partition_input_is_refused() -> None:
    centres, radii = grains(10, 2)
    with pytest.raises(gr.InputError, match="at least one grain"):
        bisect(centres, np.ones(10), 11)
    with pytest.raises(gr.InputError, match="ranks"):
        bisect(centres, np.ones(10), 0)
    with pytest.raises(gr.InputError, match="positive number per grain"):
        bisect(centres, -np.ones(10), 2)
    with pytest.raises(gr.InputError, match="shape"):
        bisect(centres[:, :1], np.ones(10), 2)
    with pytest.raises(gr.InputError, match="reach"):
        near_pairs(centres, radii, -1.0)


def test_a_grains_work_counts_its_nodes_bonds_and_the_contact_entries_near_its_partner() -> None:
    """work_load.node_work of two discs pressed 0.05 mm into each other: per node 1 + 0.06
    intact bond copies + 1.5 list entries; some nodes have entries, and only nodes within the
    contact reach of the other disc's edge."""
    rock = gr.Material(density=1200, youngs_modulus=1e8, poisson_ratio=0.25, fracture=False)
    sim = gr.Simulation(2)
    sim.contact = gr.Contact(restitution=0.5)
    for x in (0.0, 1.95e-3):
        sim.add_body(gr.Disc((x, 0.0), 1e-3), rock, 0.2e-3)
    sim.core.run(0)
    nodes = np.arange(sim.node_count, dtype=np.int64)
    copies = np.asarray(sim.core.intact_bond_copies(nodes), dtype=float)
    entries = np.asarray(sim.core.contact_list_entries(nodes), dtype=float)
    work = node_work(sim.core, nodes, 2)
    assert np.array_equal(work, 1 + BOND_COPY[2] * copies + LIST_ENTRY * entries)
    x = np.asarray(sim.core.positions)[:, 0]
    first = nodes < sim.bodies[1].node_slice.start
    gap_to_other = np.where(first, 0.95e-3 - x, x - 1.0e-3)  # from the other disc's edge
    reach = sim.core.contact_reach
    assert entries.sum() > 0 and np.all(gap_to_other[entries > 0] <= reach)
    with pytest.raises(gr.InputError, match="out of range"):
        sim.core.contact_list_entries(np.array([sim.node_count], dtype=np.int64))
