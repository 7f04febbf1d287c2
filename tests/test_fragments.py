"""Breakage analytics (granulate.fragments): fragments of cut particles, the fragment table and
history columns a run writes, grading curves and the breakage indices Br, B and t10 against
hand-computed values."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest

import granulate as gr
from granulate import fragments
from granulate.io.vtu import read_vtu_point_data

DENSITY = 2000.0


def rock() -> gr.Material:
    return gr.Material(density=DENSITY, youngs_modulus=1e9, poisson_ratio=0.25, fracture=False)


def block(dimension: int, side: float):
    """A rectangle (2D) or box (3D) of 2 x 1 (x 1) sides, an even number of cells along x."""
    if dimension == 2:
        return gr.Rectangle((0, 0), (2 * side, side))
    return gr.Box((0, 0, 0), (2 * side, side, side))


@pytest.mark.parametrize("dimension", [2, 3])
def test_a_block_cut_in_half_is_two_fragments_of_half_the_mass(dimension: int) -> None:
    """Breaking exactly the bonds that cross x = side leaves two pieces, each of mass
    rho x (the block's measure) / 2 (to round-off), centred at x = side / 2 and 3 side / 2."""
    side, h = 2e-3, 2.5e-4
    sim = gr.Simulation(dimension)
    sim.add_body(block(dimension, side), rock(), h)
    before = sim.fragment_table()
    assert len(before["fragment"]) == 1 and before["debris"][0] == 0
    sim.precrack((side, 0, 0)[:dimension], (1, 0, 0)[:dimension])
    table = sim.fragment_table()
    half = DENSITY * side**dimension
    assert len(table["fragment"]) == 2
    np.testing.assert_allclose(table["mass"], [half, half], rtol=1e-12)
    np.testing.assert_allclose(table["x"], [side / 2, 1.5 * side], rtol=1e-12)
    assert list(table["particle"]) == [0, 0] and list(table["debris"]) == [0, 0]
    assert table["fragment"][0] == 0  # a piece is named by its smallest node
    measure = side**dimension
    expected = (
        2 * math.sqrt(measure / math.pi) if dimension == 2 else (6 * measure / math.pi) ** (1 / 3)
    )
    np.testing.assert_allclose(table["diameter"], [expected, expected], rtol=1e-12)
    assert len(sim.fragments()) == 2


def test_damage_and_fragments_follow_the_bonds_back_to_a_checkpoint(tmp_path: Path) -> None:
    """The fragment labels and damage, kept while no bond changes (core.bond_changes), are
    made anew when bonds break by hand and when a checkpoint of the intact block is loaded."""
    side = 2e-3
    sim = gr.Simulation(2)
    sim.add_body(block(2, side), rock(), 2.5e-4)
    saved = sim.save_checkpoint(tmp_path / "intact.npz")
    assert len(sim.fragment_table()["fragment"]) == 1 and sim.damage.max() == 0
    sim.precrack((side, 0), (1, 0))
    assert len(sim.fragment_table()["fragment"]) == 2 and sim.damage.max() > 0
    sim.load_checkpoint(saved)
    assert len(sim.fragment_table()["fragment"]) == 1 and sim.damage.max() == 0
    assert not sim.damage.flags.writeable  # kept: a caller cannot change it


@pytest.mark.parametrize("dimension", [2, 3])
def test_an_intact_assembly_is_one_fragment_per_particle_with_no_breakage(dimension: int) -> None:
    sim = gr.Simulation(dimension)
    for k in range(3):
        centre = (3e-3 * k, 0, 0)[:dimension]
        shape = gr.Disc(centre, 1e-3) if dimension == 2 else gr.Sphere(centre, 1e-3)
        sim.add_body(shape, rock(), 2.5e-4 if dimension == 2 else 4e-4)
    table = sim.fragment_table()
    assert list(table["particle"]) == [0, 1, 2] and not table["debris"].any()
    sizes = table["diameter"]
    assert fragments.hardin_breakage(table, table) == 0.0
    assert fragments.einav_breakage(table, table, dimension, smallest=1e-5) == 0.0
    assert fragments.t10(table, sizes) == 0.0
    summary = fragments.summary(table, 0.0)
    assert summary == {
        "fragments": 3,
        "debris_nodes": 0,
        "debris_mass": 0.0,
        "particles_split": 0,
        "mean_damage": 0.0,
    }


def synthetic(pieces: list[tuple[int, float, float]]) -> fragments.Table:
    """A fragment table of (particle, diameter [m], mass [kg]) rows."""
    particle, diameter, mass = (np.array(c) for c in zip(*pieces, strict=True))
    return {"particle": particle.astype(np.int64), "diameter": diameter, "mass": mass}


def test_breakage_indices_of_a_grading_shift_match_hand_computation() -> None:
    """Two 1 mm grains of 1 kg; one breaks into 0.5 kg of 0.5 mm and 0.5 kg of 0.05 mm.

    Hardin (cut-off 0.074 mm): Bp0 = log10(1 / 0.074), Bp = (0.5 log10(0.5 / 0.074) + 0 +
    log10(1 / 0.074)) / 2, Br = (Bp0 - Bp) / Bp0 = 0.31656. Einav over [0.01, 1] mm (3D,
    alpha 2.5): F0 has no area, F has (0.25 ln 2 + 0.25 ln 20), the ultimate grading
    (1 - 0.01^0.5) / 0.5 = 1.8, B = 0.51234. t10: 0.5 kg of 2 kg no larger than 0.1 mm."""
    initial = synthetic([(0, 1e-3, 1.0), (1, 1e-3, 1.0)])
    current = synthetic([(0, 0.5e-3, 0.5), (0, 0.05e-3, 0.5), (1, 1e-3, 1.0)])
    bp0 = math.log10(1 / 0.074)
    bp = (0.5 * math.log10(0.5 / 0.074) + math.log10(1 / 0.074)) / 2
    assert fragments.hardin_breakage(initial, current) == pytest.approx((bp0 - bp) / bp0, 1e-12)
    assert (bp0 - bp) / bp0 == pytest.approx(0.31656, abs=1e-5)
    b = (0.25 * math.log(2) + 0.25 * math.log(20)) / 1.8
    assert fragments.einav_breakage(initial, current, 3, smallest=1e-5) == pytest.approx(b, 1e-12)
    assert b == pytest.approx(0.51234, abs=1e-5)
    assert fragments.t10(current, [1e-3, 1e-3]) == 0.25
    sizes, passing = fragments.grading_curve(current)
    np.testing.assert_allclose(sizes, [0.05e-3, 0.5e-3, 1e-3])
    np.testing.assert_allclose(passing, [0.25, 0.5, 1.0])


def test_bad_index_arguments_are_input_errors() -> None:
    table = synthetic([(0, 1e-3, 1.0)])
    with pytest.raises(gr.InputError, match="cut-off"):
        fragments.hardin_breakage(synthetic([(0, 1e-5, 1.0)]), table)
    with pytest.raises(gr.InputError, match="smallest < largest"):
        fragments.einav_breakage(table, table, 3, smallest=2e-3)
    with pytest.raises(gr.InputError, match="fractal dimension"):
        fragments.einav_breakage(table, table, 3, smallest=1e-5, alpha=3.0)


def test_a_run_writes_fragment_ids_tables_and_history_columns(tmp_path: Path) -> None:
    """Each frame carries Fragment_ID, frames/fragments_NNNNNN.csv holds the table (read back
    equal), and history.csv the fragment count, debris, broken particles and mean damage."""
    side = 2e-3
    sim = gr.Simulation(2)
    sim.add_body(block(2, side), rock(), 2.5e-4)
    sim.add_body(gr.Disc((6e-3, 0), 1e-3), rock(), 2.5e-4)
    sim.precrack((side, 0), (1, 0))
    sim.output(tmp_path, every=5)
    sim.run(10)
    table = sim.fragment_table()
    read = fragments.read_table(tmp_path / "frames" / "fragments_000002.csv")
    assert set(read) == set(fragments.COLUMNS)
    for name in fragments.COLUMNS:
        np.testing.assert_array_equal(read[name], table[name])
    _, fields = read_vtu_point_data(tmp_path / "frames" / "frame_000002.vtu")
    labels = fields["Fragment_ID"]
    assert sorted(set(labels.tolist())) == sorted(table["fragment"].tolist())
    with (tmp_path / "history.csv").open() as handle:
        last = list(csv.DictReader(handle))[-1]
    assert (last["fragments"], last["debris_nodes"], last["particles_split"]) == ("3", "0", "1")
    assert float(last["debris_mass"]) == 0.0 and 0 < float(last["mean_damage"]) < 0.2


def test_a_file_that_is_not_a_fragment_table_is_refused(tmp_path: Path) -> None:
    bad = tmp_path / "x.csv"
    bad.write_text("a,b\n1,2\n")
    with pytest.raises(gr.InputError, match="line 2: expected 13 columns"):
        fragments.read_table(bad)
    with pytest.raises(gr.InputError, match=r"fragment table file .* does not exist"):
        fragments.read_table(tmp_path / "missing.csv")
