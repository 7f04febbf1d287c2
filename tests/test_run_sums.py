"""Sums run by run (granulate.run_sums): the runs break where they should, and the particle and
fragment tables of nodes dealt to processes in whole blocks of 64, made of each process's runs,
are the serial tables to the bit; dealt node by node they are not."""

from __future__ import annotations

import numpy as np
import pytest

from granulate import fragments, particle_table
from granulate.run_sums import BLOCK, Runs

NODES = 1000


def test_a_run_ends_at_a_block_a_group_or_a_gap() -> None:
    nodes = np.array([0, 1, 2, 3, 5, 6, 62, 63, 64, 65, 66])
    groups = np.array([7, 7, 7, 8, 8, 8, 8, 8, 8, 8, 7])
    runs = Runs.of(groups, nodes, np.arange(len(nodes), dtype=float))
    assert runs.first.tolist() == [0, 3, 5, 62, 64, 66]
    assert runs.length.tolist() == [3, 1, 2, 2, 2, 1]
    assert runs.group.tolist() == [7, 8, 8, 8, 8, 7]
    assert runs.sums[:, 0].tolist() == [3.0, 3.0, 9.0, 13.0, 17.0, 10.0]
    assert runs.totals(9)[[7, 8], 0].tolist() == [13.0, 42.0]


def _state(seed: int) -> dict[str, np.ndarray]:
    """NODES nodes of 3 particles (node ranges), pieces interleaved within each, positions far
    from the origin and velocities of mixed sizes: sums whose bits follow their order."""
    rng = np.random.default_rng(seed)
    particle = np.repeat([0, 1, 2], [300, 450, 250])
    piece = 5 * particle + rng.integers(0, 5, NODES)  # five pieces a particle, interleaved
    _, first = np.unique(piece, return_index=True)
    labels = first[np.searchsorted(np.unique(piece), piece)]  # a piece's id: its first node
    return {
        "particle": particle,
        "labels": labels,
        "x": 1e3 + rng.normal(size=(NODES, 3)) * 10.0 ** rng.integers(-6, 0, (NODES, 1)),
        "v": rng.normal(size=(NODES, 3)) * 10.0 ** rng.integers(-3, 3, (NODES, 1)),
        "volume": 1e-9 * (1 + rng.random(NODES)),
        "density": np.full(NODES, 2500.0),
    }


def _parts(owner: np.ndarray, ranks: int) -> list[np.ndarray]:
    return [np.flatnonzero(owner == r) for r in range(ranks)]


def _dealt_tables(s: dict[str, np.ndarray], parts: list[np.ndarray]) -> tuple[dict, dict]:
    """The fragment and particle tables made of each part's runs, as ranks make them: the
    first sums, the centres sent back, the sums about them."""
    labels = [s["labels"][p] for p in parts]
    runs = [
        fragments.fragment_runs(lab, p, s["x"][p], s["v"][p], s["volume"][p], s["density"][p])
        for lab, p in zip(labels, parts, strict=True)
    ]
    ids = np.unique(np.concatenate(labels))
    pieces = fragments.table_of_runs(Runs.joined(runs), ids, s["particle"][ids], 3)
    mass = s["density"] * s["volume"]
    firsts = [
        Runs.first_sums(s["particle"][p], p, mass[p], s["volume"][p], s["x"][p], s["v"][p])
        for p in parts
    ]
    first = Runs.joined(firsts).totals(3)
    centre, velocity = particle_table.centres(first)
    moments = [
        Runs.moments(s["particle"][p], p, mass[p], s["x"][p], s["v"][p], centre, velocity)
        for p in parts
    ]
    return pieces, particle_table.table_of(first, Runs.joined(moments).totals(3))


def _serial_tables(s: dict[str, np.ndarray]) -> tuple[dict, dict]:
    nodes = np.arange(NODES)
    pieces = fragments.fragment_table(
        s["labels"], nodes, s["particle"], s["x"], s["v"], s["volume"], s["density"], 3
    )
    mass = s["density"] * s["volume"]
    motion = particle_table.motion(s["particle"], nodes, mass, s["volume"], s["x"], s["v"], 3)
    return pieces, motion


def _same_bits(a: dict[str, np.ndarray], b: dict[str, np.ndarray]) -> bool:
    return a.keys() == b.keys() and all(np.array_equal(a[k], b[k]) for k in a)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_tables_of_whole_blocks_dealt_to_ranks_are_the_serial_tables(seed: int) -> None:
    s = _state(seed)
    blocks = np.random.default_rng(seed).integers(0, 3, -(-NODES // BLOCK))
    dealt = _dealt_tables(s, _parts(blocks[np.arange(NODES) // BLOCK], 3))
    serial = _serial_tables(s)
    assert _same_bits(dealt[0], serial[0]) and _same_bits(dealt[1], serial[1])


def test_tables_of_nodes_dealt_one_by_one_are_not() -> None:
    """The same tables made of nodes dealt singly to 3 ranks differ in some bit: what whole
    blocks guard against (the data is sensitive to the order of its sums)."""
    s = _state(1)
    owner = np.random.default_rng(1).integers(0, 3, NODES)
    dealt, serial = _dealt_tables(s, _parts(owner, 3)), _serial_tables(s)
    assert not (_same_bits(dealt[0], serial[0]) and _same_bits(dealt[1], serial[1]))
