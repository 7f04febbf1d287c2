"""What rank 0 of a distributed run relies on from the core when it takes the ranks' grains
(granulate.parallel.whole_state), checked serially: per-node contact terms that sum to the
core's totals, and bonds assigned whole."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import granulate as gr
from assemblies import tumbling_drum
from granulate.analysis import GivenMeasures
from granulate.parallel.whole_state import require_room


@pytest.mark.parametrize("options", [{}, {"grid": True, "law": "surface"}])
def test_the_per_node_contact_terms_sum_to_the_cores_totals(
    options: dict[str, object], tmp_path: Path
) -> None:
    """What a distributed run sums on rank 0 (core.node_contact_terms): per node the contact
    energy, whose sum in node order is the core's contact_energy to the bit and whose correctly
    rounded sum the outputs give (Evaluation), and the node pairs (counted at the smaller node,
    a probe at its node) and wall contacts, which sum to the statistics; in the tumbling drum,
    with pairs and walls touching at these steps."""
    sim = tumbling_drum(tmp_path, **options)  # type: ignore[arg-type]
    touched = 0
    for _ in range(6):
        sim.core.run(300)
        energy, pairs, walls = (np.asarray(a) for a in sim.core.node_contact_terms())
        statistics = sim.core.contact_statistics
        assert np.add.accumulate(energy)[-1] == sim.core.contact_energy()
        assert sim.evaluation().contact_energy == math.fsum(energy)
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


def test_the_strain_energy_is_the_correctly_rounded_sum_of_its_densities(tmp_path: Path) -> None:
    """What rank 0 sums of the densities the ranks measure: sum_i W_i V_i rounded once (as
    math.fsum rounds it), within 1e-12 of the core's sum in node order, in the tumbling drum as
    it breaks."""
    sim = tumbling_drum(tmp_path)
    for _ in range(3):
        sim.core.run(300)
        density = np.asarray(sim.core.strain_energy_density())
        terms = density * np.asarray(sim.model.volumes)
        assert sim.strain_energy() == math.fsum(terms) > 0
        assert sim.strain_energy() == pytest.approx(sim.core.strain_energy(), rel=1e-12)


def test_given_measures_stand_for_the_cores_until_the_state_changes(tmp_path: Path) -> None:
    """Analysis.give (rank 0 takes the measures the ranks made of their grains): the damage, Z,
    fragment labels, strain energy and particle motion given are what the simulation reports
    at that step, and the core's again once a step is taken or when None is given."""
    sim = tumbling_drum(tmp_path)
    sim.core.run(600)
    nodes, grains = sim.node_count, len(sim.bodies)
    columns = sim.analysis.particles(sim.contact_table(), None)[0]  # motion's among them
    motion = {key: np.full(grains, 7.0) for key in columns}
    density = np.full(nodes, 2.0)
    given = GivenMeasures(
        np.full(nodes, 0.25), np.full(nodes, 0.5), np.zeros(nodes, np.uint32), density, motion
    )
    sim.analysis.give(given)
    assert np.all(sim.damage == 0.25) and np.all(sim.damage_z == 0.5)
    assert sim.strain_energy() == math.fsum(2.0 * np.asarray(sim.model.volumes))
    assert len(sim.fragment_table()["fragment"]) == 1  # every node labelled 0
    assert np.all(sim.particle_table()["vx"] == 7.0)
    sim.analysis.give(None)
    core_density = np.asarray(sim.core.strain_energy_density())
    assert sim.strain_energy() == math.fsum(core_density * np.asarray(sim.model.volumes)) > 0
    sim.analysis.give(given)
    sim.core.run(1)
    assert np.array_equal(sim.damage, sim.core.damage()[0])
    assert np.all(sim.particle_table()["vx"] != 7.0)


def test_rank_0_is_told_at_the_start_when_the_whole_model_will_not_fit(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """whole_state.require_room (every distributed run's rank 0, once its part is built): the
    model's memory check on the whole assembly, without building it; its message says why
    rank 0 needs the whole model and what to do."""
    sim = tumbling_drum(tmp_path, outputs=False)
    require_room(sim)  # this machine holds the drum
    assert sim._core is None  # nothing was built
    monkeypatch.setattr(gr.resources, "available_memory", lambda: 1000)
    with pytest.raises(gr.InputError, match=r"would need about .* of memory") as refused:
        require_room(sim)
    assert "rank 0 holds the whole model at the end of a run" in str(refused.value)
