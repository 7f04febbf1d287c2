"""What rank 0 of a distributed run relies on from the core when it takes the ranks' grains
(granulate.parallel.whole_state), checked serially: per-node contact terms that sum to the
core's totals in node order, and bonds assigned whole."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import granulate as gr
from test_checkpoint import tumbling_drum


@pytest.mark.parametrize("options", [{}, {"grid": True, "law": "surface"}])
def test_the_per_node_contact_terms_sum_to_the_cores_totals(
    options: dict[str, object], tmp_path: Path
) -> None:
    """What a distributed run sums on rank 0 (core.node_contact_terms): per node the contact
    energy, whose sum in node order is the core's contact_energy to the bit, and the node pairs
    (counted at the smaller node, a probe at its node) and wall contacts, which sum to the
    statistics; in the tumbling drum, with pairs and walls touching at these steps."""
    sim = tumbling_drum(tmp_path, **options)  # type: ignore[arg-type]
    touched = 0
    for _ in range(6):
        sim.core.run(300)
        energy, pairs, walls = (np.asarray(a) for a in sim.core.node_contact_terms())
        statistics = sim.core.contact_statistics
        assert np.add.accumulate(energy)[-1] == sim.core.contact_energy()
        assert (pairs.sum(), walls.sum()) == (statistics.node_contacts, statistics.wall_contacts)
        touched += int(pairs.sum() > 0) + int(walls.sum() > 0)
    assert touched >= 6


def test_bonds_assigned_whole_set_the_broken_count(tmp_path: Path) -> None:
    """core.assign_bonds (rank 0 takes the ranks' bonds): the states of another run's step,
    with its broken count; the wrong length is refused."""
    broken, fresh = tumbling_drum(tmp_path / "a"), tumbling_drum(tmp_path / "b")
    broken.core.run(900)
    assert broken.broken_bonds() > 100
    fresh.core.assign_bonds(np.asarray(broken.core.bond_intact))
    assert fresh.broken_bonds() == broken.broken_bonds()
    assert np.array_equal(fresh.core.bond_intact, broken.core.bond_intact)
    with pytest.raises(gr.InputError, match="one byte per bond copy"):
        fresh.core.assign_bonds(np.ones(3, dtype=np.uint8))
