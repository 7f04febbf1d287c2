"""PeriDEM decks as input: broken and mutated decks give one clear message, keys the example
decks do not use, PeriDEM's constants and friction, the older deck format, restarts from
PeriDEM's output and resumes, where a deck writes (runs against PeriDEM's results:
test_peridem.py)."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import meshio
import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import granulate as gr
from granulate import peridem
from granulate.case import load_case
from granulate.cli import main
from granulate.errors import InputError
from granulate.io.vtu import read_vtu_point_data, write_vtu
from peridem_decks import (
    DECKS,
    broken_deck,
    history,
    reference,
    run_deck,
)


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (
            lambda t: t.replace("Final_Time", "Final_Tme"),
            "unknown key 'Final_Tme'; did you mean 'Final_Time'",
        ),
        (lambda t: t.replace("mesh_cir_1_0.msh", "missing.msh"), "missing.msh"),
        (lambda t: t.replace("Type: PDState", "Type: RNPBond", 1), "'RNPBond' is not supported"),
        (lambda t: t + "Restart:\n  File: a.vtu\n  Step: 10\n", "restart file"),
        (lambda t: t + "Restart:\n  File: a.vtu\n", "Restart: give File"),
        (lambda t: t.replace("Particle_List: [1]", "Particle_List: [7]"), "IC.Constant_Velocity"),
        (
            # one problem, told as it is: not wrapped as 'an unexpected kind', and without the
            # particles the broken zone would have had reported missing as well
            lambda t: t.replace("mesh_cir_1_0.msh", "input_0.yaml"),
            "1 problem(s) in the PeriDEM deck:\n  - Mesh.Zone_1.File: cannot read mesh file",
        ),
        (lambda t: t.replace("Particle_List: [0]", "Particle_List: [5]"), "0 .. 1"),
        (lambda t: t.replace("  Zone_12:\n", "  Zone_21:\n"), "Contact.Zone_12: missing"),
        (lambda t: t.replace("- Theta", "- Thetta"), "unknown tags ['Thetta']"),
        (lambda t: t.replace("Time_Steps: 200000", "Time_Steps: -3"), "Time_Steps"),
        (lambda t: t.replace("Density: 1.200000e+03", "Density: -5", 1), "Density"),
    ],
)
def test_broken_decks_get_one_clear_message(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], edit, message: str
) -> None:
    deck = broken_deck(tmp_path, "twop_circ", edit)
    assert main(["check", str(deck)]) == 2
    err = capsys.readouterr().err
    assert message in err, err
    assert "Traceback" not in err


def test_compat_switch_is_for_decks_only(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    case = Path(__file__).parent / "cases" / "base.yaml"
    assert main(["check", str(case), "--peridem-compat"]) == 2
    assert "applies to decks" in capsys.readouterr().err


def test_peridem_constants_in_2d() -> None:
    """plane 'peridem': the 3D critical stretch s0 = sqrt(Gc / ((3G + (3/4)^4 (K - 5G/3)) delta))
    and the 3D LPS state: an isotropic stretch eps of an interior node gives theta = 3 eps and
    W = K theta^2 / 2 = 4.5 K eps^2 (the 2D plane-strain W is 2 (K + G/3) eps^2)."""
    K, G, Gc, delta = 2.16e5, 1.296e5, 500.0, 1.5e-3
    material = gr.Material(
        density=1200, bulk_modulus=K, shear_modulus=G, fracture_energy=Gc, horizon=delta
    )
    s0 = material.critical_stretch(5e-4, 2, "peridem")
    assert s0 == pytest.approx(
        math.sqrt(Gc / ((3 * G + 0.75**4 * (K - 5 * G / 3)) * delta)), rel=1e-12
    )
    eps = 1e-4
    energies = {}
    for plane in ("peridem", "strain"):
        sim = gr.Simulation(2, plane)
        body = sim.add_body(gr.Rectangle((0, 0), (10e-3, 10e-3)), material, 5e-4)
        sim.contact = None
        sim.positions[:] = sim.positions * (1 + eps)
        centre = int(np.argmin(np.hypot(*(sim.positions[:, :2] - 5e-3 * (1 + eps)).T)))
        sim.run(0)
        energies[plane] = sim.core.strain_energy_density()[centre]
        assert body.node_count == 400
    assert energies["peridem"] == pytest.approx(4.5 * K * eps**2, rel=0.03)
    assert energies["strain"] == pytest.approx(2 * (K + G / 3) * eps**2, rel=0.03)


def test_peridem_friction_speeds_sliding_up() -> None:
    """friction_law 'peridem' reproduces PeriDEM's sign: a block sliding on a floor accelerates
    at +mu g instead of decelerating (within 10 %)."""
    rubber = gr.Material(density=1000, youngs_modulus=5e6, poisson_ratio=0.25, fracture=False)
    mu, g, h = 0.4, 9.81, 1e-3
    sim = gr.Simulation(2, gravity=(0, -g))
    sim.contact = gr.Contact(restitution=0.3, friction=mu, friction_law="peridem")
    block = sim.add_body(gr.Rectangle((0, 0.5 * h), (10 * h, 5.5 * h)), rubber, h)
    sim.add_wall(gr.Plane((0, 0), (0, 1)), name="floor")
    sim.run(until=0.02)
    sim.velocities[:, 0] = 0.3
    masses = sim.volumes * rubber.density
    speed = lambda: float(masses @ sim.velocities[:, 0] / masses.sum())  # noqa: E731
    before, start = speed(), sim.time
    sim.run(until=start + 0.02)
    acceleration = (speed() - before) / (sim.time - start)
    assert acceleration == pytest.approx(mu * g, rel=0.10)
    with pytest.raises(InputError, match="friction_law"):
        gr.Contact(friction_law="backwards")
    assert block.node_count == 50


def test_grid_discretization_is_peridems_uniform_mesh() -> None:
    nodes, volumes = gr.shapes.grid(gr.Rectangle((0, 0), (0.01, 0.01)), 5e-4)
    assert len(nodes) == 441
    assert volumes.sum() == pytest.approx(1e-4, rel=1e-12)
    assert volumes.min() == pytest.approx(0.25 * 5e-4**2) and volumes.max() == pytest.approx(
        5e-4**2
    )
    nodes3, volumes3 = gr.shapes.grid(gr.Box((0, 0, 0), (1, 2, 3)), 0.5)
    assert len(nodes3) == 3 * 5 * 7 and volumes3.sum() == pytest.approx(6.0, rel=1e-12)
    with pytest.raises(InputError, match="Rectangle and Box"):
        gr.shapes.grid(gr.Disc((0, 0), 1), 0.1)


def test_smallest_spacing_is_the_closest_pair() -> None:
    rng = np.random.default_rng(3)
    points = rng.uniform(size=(300, 3))
    brute = min(
        np.linalg.norm(points[i] - points[j]) for i in range(300) for j in range(i + 1, 300)
    )
    assert peridem.smallest_spacing(points) == pytest.approx(brute, rel=1e-12)


def _leaves(data, path=()):
    if isinstance(data, dict):
        for key, value in data.items():
            yield from _leaves(value, (*path, key))
    elif isinstance(data, list):
        for k, value in enumerate(data):
            yield from _leaves(value, (*path, k))
    yield path


junk = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-5, 5),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=5),
    st.lists(st.integers(-2, 20), max_size=3),
    st.dictionaries(st.sampled_from(["Type", "Parameters", "File"]), st.integers(), max_size=2),
)


@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(data=st.data())
def test_mutated_decks_give_input_errors_only(tmp_path: Path, data) -> None:
    """Any value of a deck replaced by junk: the deck loads, or InputError; nothing else."""
    deck = yaml.safe_load((DECKS / "twop_circ" / "input_0.yaml").read_text())
    paths = [p for p in _leaves(deck) if p]
    for _ in range(data.draw(st.integers(1, 3))):
        where = data.draw(st.sampled_from(paths))
        target = deck
        try:
            for key in where[:-1]:
                target = target[key]
            target[where[-1]] = data.draw(junk)
        except (KeyError, IndexError, TypeError):
            continue
    folder = tmp_path / "deck"
    shutil.copytree(DECKS / "twop_circ", folder, dirs_exist_ok=True)
    (folder / "input_0.yaml").write_text(yaml.safe_dump(deck))
    try:
        load_case(folder / "input_0.yaml")
    except InputError:
        pass


def test_keys_the_example_decks_do_not_use(tmp_path: Path) -> None:
    """loc_rad placements, KIc, Horizon_Mesh_Ratio, PMBBond, force sets, exclusion lists,
    quadratic and sin displacements, Output_Criteria and Compressive_Test are translated."""

    def edit(text: str) -> str:
        deck = yaml.safe_load(text)
        deck["Particle_Generation"]["File_Data_Type"] = "loc_rad"
        deck["Model"]["Seed"] = 7
        zone2 = deck["Material"]["Zone_2"]
        zone2.pop("Gc")
        zone2.pop("Horizon")
        zone2.update({"Type": "PMBBond", "KIc": 1.0e5, "Horizon_Mesh_Ratio": 4.0})
        deck["Force_BC"]["Sets"] = 1
        deck["Force_BC"]["Set_1"] = {
            "Particle_List": [0, 1],
            "Particle_Exclude_List": [0],
            "Direction": [2],
            "Time_Function": {"Type": "sin", "Parameters": [5.0, 100.0]},
            "Spatial_Function": {"Type": "constant"},
        }
        deck["Displacement_BC"]["Sets"] = 2
        deck["Displacement_BC"]["Set_2"] = {
            "Region": {"Geometry": {"Type": "circle", "Parameters": [2e-4, 1e-3, 1e-3, 0.0]}},
            "Direction": [1],
            "Time_Function": {"Type": "quadratic", "Parameters": [1e-3, 2e-2]},
        }
        deck["Output"]["Output_Criteria"] = {"Type": "max_node_dist", "Parameters": [0.1]}
        deck["Particle"]["Compressive_Test"] = {"Particle_Id": 1, "Particle_Force_Direction": 2}
        return yaml.safe_dump(deck)

    deck = broken_deck(tmp_path, "twop_circ", edit)
    translation = peridem.translate(deck)
    case = translation.case
    # loc_rad: random orientations from the deck's seed; a two-particle test turns disc i by i pi.
    assert [p["rotation"] for p in case["particles"]] == pytest.approx([0.0, math.pi])
    zone2 = case["materials"]["zone_2"]
    assert zone2["model"] == "pmb" and zone2["horizon_factor"] == 4.0
    e = 9 * 2.16e7 * 1.296e7 / (3 * 2.16e7 + 1.296e7)
    assert zone2["fracture_energy"] == pytest.approx(1.0e10 / e, rel=1e-12)
    force = next(load for load in case["loading"] if load["type"] == "force_density")
    assert force["nodes"] == {"body": ["p0", "p1"], "exclude": ["p0"]}
    assert force["vector"] == [0.0, 1.0]
    assert force["function"] == {"type": "sine", "amplitude": 5.0, "frequency": 50.0}
    quadratic = next(load for load in case["loading"] if load["type"] == "displacement")
    assert quadratic["nodes"]["region"] == {"type": "disc", "center": [1e-3, 1e-3], "radius": 2e-4}
    assert quadratic["function"] == {"type": "quadratic", "a": 1e-3, "b": 2e-2}
    assert quadratic["components"] == "x"
    assert case["stop"]["node_distance"] == 0.1
    assert case["output"]["track"] == ["p0", "p1"]
    # A particle placed from the CSV: its area is not known to the translator, and it says so.
    assert case["output"]["track_areas"] == {}
    assert any("p1 is placed from the particle file" in note for note in translation.notes)
    assert any("loc_rad" in note for note in translation.notes)
    assert main(["run", str(deck), "--out", str(tmp_path / "out"), "--quiet", "--steps", "20"]) == 0


def test_node_distance_stops_a_run() -> None:
    sim = gr.Simulation(2)
    sim.add_body(
        gr.Disc((0, 0), 1e-3),
        gr.Material(
            density=1000, youngs_modulus=1e6, poisson_ratio=0.25, fracture=False, horizon_factor=3
        ),
        2.5e-4,
        velocity=(10.0, 0),
    )
    reason = sim.run(10_000, stop=[gr.stopping.NodeDistance(2e-3)], check_every=10)
    assert reason is not None and "from the origin" in reason
    assert np.max(np.hypot(sim.positions[:, 0], sim.positions[:, 1])) > 2e-3
    with pytest.raises(InputError, match="positive distance"):
        gr.stopping.NodeDistance(-1.0)


def test_restart_from_peridems_output(tmp_path: Path) -> None:
    """Restart {File, Step}: twop_circ continued from PeriDEM's own frame at step 60,000 starts
    from its displacements (the top disc's mean uy equals PeriDEM's to 1e-12 m) at t = 0.018 s."""
    deck = broken_deck(
        tmp_path,
        "twop_circ",
        lambda t: t + "Restart:\n  File: peridem_output/output_0_12.vtu\n  Step: 60000\n",
    )
    out = tmp_path / "out"
    assert main(["run", str(deck), "--out", str(out), "--quiet", "--steps", "5000"]) == 0
    rows = history(out)
    top = reference("twop_circ")
    top = top[(top[:, 3] == 1) & (top[:, 1] == 60_000)][0]
    assert rows[0]["step"] == 60_000 and rows[0]["time"] == pytest.approx(0.018, rel=1e-12)
    assert rows[0]["p1_uy"] == pytest.approx(top[9], abs=1e-12)
    assert rows[-1]["step"] == 65_000
    with pytest.raises(InputError, match="holds 246 nodes"):
        broken = broken_deck(
            tmp_path / "other",
            "compression_small_set",
            lambda t: (
                t + "Restart:\n  File: ../../twop_circ/peridem_output/output_0_12.vtu\n  Step: 5\n"
            ),
        )
        load_case(broken).build(outputs=False)


def test_vtu_reader_reads_what_the_writer_writes(tmp_path: Path) -> None:
    rng = np.random.default_rng(4)
    points = rng.uniform(size=(70_000, 3))  # several zlib blocks
    fields = {
        "Displacement": rng.standard_normal((70_000, 3)),
        "Particle_ID": np.arange(70_000, dtype=np.uint32) // 7,
        "Fixity": np.zeros(70_000, np.uint8),
    }
    write_vtu(tmp_path / "f.vtu", points, fields)
    read_points, data = read_vtu_point_data(tmp_path / "f.vtu")
    np.testing.assert_array_equal(read_points, points)
    for name, values in fields.items():
        np.testing.assert_array_equal(data[name], values)
    (tmp_path / "bad.vtu").write_bytes(b"<VTKFile><Unstructured")
    with pytest.raises(InputError, match="not a VTU file"):
        read_vtu_point_data(tmp_path / "bad.vtu")


def test_resume_across_an_impact_on_a_held_disc_is_bitwise(tmp_path: Path) -> None:
    """The held lower disc of twop_circ counts as a wall in the dashpot; a run resumed before
    the impact (step 10,000 of 20,000) writes the same history as an uninterrupted one."""
    whole = run_deck("twop_circ", tmp_path / "whole", 20_000)
    split = run_deck("twop_circ", tmp_path / "split", 10_000)
    assert (
        main(
            [
                "run",
                str(DECKS / "twop_circ" / "input_0.yaml"),
                "--out",
                str(split),
                "--quiet",
                "--resume",
                "--steps",
                "10000",
            ]
        )
        == 0
    )
    assert (whole / "history.csv").read_bytes() == (split / "history.csv").read_bytes()
    uy = {int(r["step"]): r["p1_uy"] for r in history(whole)}
    fell, after = uy[10_000] - uy[15_000], uy[15_000] - uy[20_000]
    assert after < 0.1 * fell  # the falling disc struck the held one after the resume


def test_resuming_a_restarted_deck_starts_from_the_restart_positions(tmp_path: Path) -> None:
    """A deck whose reference grains overlap (the top disc of twop_circ 1.2 mm into the lower
    one) is refused, and runs when it restarts from a frame that lifts them apart; resumed from
    its checkpoint it runs on (--resume judged the reference positions and refused it:
    n500_circ_hex's stage 2) and writes the same history as an uninterrupted run."""
    with pytest.warns(gr.GranulateWarning, match="exceeds the stable"):  # PeriDEM's own dt
        apart = load_case(DECKS / "twop_circ" / "input_0.yaml").build(outputs=False)
    top = apart.bodies[1].nodes
    deck = broken_deck(tmp_path, "twop_circ", lambda text: text)
    locations = deck.parent / "particle_locations_0.csv"
    locations.write_text(locations.read_text().replace("0.003600", "0.001800"))
    with pytest.raises(InputError, match="p0 and p1 overlap at the start"):
        load_case(deck).build(outputs=False)
    displacement = np.zeros((apart.node_count, 3))
    displacement[top, 1] = 1.8e-3  # back to twop_circ's positions, centres 2.6 mm apart
    velocity = np.zeros((apart.node_count, 3))
    velocity[top, 1] = -0.1
    write_vtu(
        deck.parent / "lifted.vtu",
        apart.reference_positions,
        {"Displacement": displacement, "Velocity": velocity},
    )
    deck.write_text(deck.read_text() + "Restart:\n  File: lifted.vtu\n  Step: 0\n")
    whole = run_deck("twop_circ", tmp_path / "whole", 10_000, deck=deck)
    split = run_deck("twop_circ", tmp_path / "split", 5_000, deck=deck)
    run_deck("twop_circ", split, 5_000, "--resume", deck=deck)
    assert (whole / "history.csv").read_bytes() == (split / "history.csv").read_bytes()
    assert history(whole)[-1]["step"] == 10_000


def test_a_deck_writes_its_output_in_the_working_directory(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """PeriDEM's Output.Path (../out/, relative to the deck) sent a run's output next to the deck
    folder; it goes to out/<deck folder> in the working directory, and the run says so."""
    deck = broken_deck(tmp_path / "decks", "twop_circ", lambda text: text)
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    assert main(["run", str(deck), "--steps", "5"]) == 0
    printed = capsys.readouterr().out
    assert "output in out/twop_circ" in printed and "Output.Path '../out/'" in printed
    assert (work / "out" / "twop_circ" / "history.csv").is_file()
    assert not (tmp_path / "decks" / "out").exists()
    target = tmp_path / "cases" / "twop.yaml"
    target.parent.mkdir()
    assert main(["convert", str(deck), "-o", str(target)]) == 0
    case = yaml.safe_load(target.read_text())
    assert case["output"]["directory"] == "out/twop_circ"
    meshes = [grain["mesh"]["file"] for grain in case["grains"].values()]
    assert meshes and all((target.parent / m).is_file() for m in meshes)


def older_format(text: str, time_steps: int | None = None) -> str:
    """compression_small_set written in PeriDEM's older deck format (its paper's decks): the two
    wall zones under Zone (Is_Wall, Type, Parameters) with a Wall block, the displacement sets
    by Wall_List, the loaded wall by Compressive_Test.Wall_Id, and the Contact_Data tag."""
    data = yaml.safe_load(text)
    walls = {}
    for zone in ("Zone_9", "Zone_10"):
        particle = data["Particle"].pop(zone)
        data["Zone"][zone] = {k: particle[k] for k in ("Is_Wall", "Type", "Parameters")}
        walls[zone] = {
            "Type": "flexible",
            "All_Dofs_Constrained": particle["All_Dofs_Constrained"],
            "Mesh": True,
        }
    data["Wall"] = walls
    data["Particle"]["Compressive_Test"] = {"Wall_Id": 1, "Wall_Force_Direction": 2}
    for s, wall in (("Set_1", 0), ("Set_2", 1)):
        del data["Displacement_BC"][s]["Particle_List"]
        data["Displacement_BC"][s]["Wall_List"] = [wall]
    data["Output"]["Tags"] = [*data["Output"].get("Tags", ["Displacement"]), "Contact_Data"]
    if time_steps is not None:
        data["Model"]["Time_Steps"] = time_steps
    return yaml.safe_dump(data)


def test_decks_in_peridems_older_format_translate_as_the_current_ones(tmp_path: Path) -> None:
    """PeriDEM's paper decks (decks/n500_circ_hex) use an older format: wall zones under Zone
    with a Wall block, Wall_List, Compressive_Test.Wall_Id. compression_small_set rewritten in
    it translates to the same case as the original (walls 0 and 1 are its particles 15 and 16),
    except the notes; its Time_Steps: 1 slip (fewer steps than one output interval) runs to
    Final_Time at granulate's own time step, and says so. Its Compressive_Test (the original
    has none) adds the loaded wall's area, the moving container's width (history.csv's
    p16_stress)."""
    new = peridem.translate(DECKS / "compression_small_set" / "input_0.yaml")
    older = broken_deck(tmp_path / "a", "compression_small_set", older_format)
    old = peridem.translate(older)
    areas = old.case["output"].pop("track_areas")
    assert new.case["output"].pop("track_areas") == {}
    assert old.case == new.case
    moving = meshio.read(DECKS / "compression_small_set" / "mesh_moving_container_0.msh").points
    assert areas == {"p16": pytest.approx(np.ptp(moving[:, 0]), rel=1e-12)}
    assert any("p16_stress" in note for note in old.notes)
    out = tmp_path / "out"
    assert main(["run", str(older), "--out", str(out), "--quiet", "--steps", "400"]) == 0
    rows = history(out)
    assert all(r["p16_stress"] == math.hypot(r["p16_fx"], r["p16_fy"]) / areas["p16"] for r in rows)
    assert any("Contact_Data" in note for note in old.notes)
    slip = broken_deck(tmp_path / "b", "compression_small_set", lambda t: older_format(t, 1))
    translated = peridem.translate(slip)
    assert translated.case["time"] == {"end": new.case["time"]["dt"] * new.case["time"]["steps"]}
    assert any("Time_Steps: 1 is fewer than Output.Output_Interval" in n for n in translated.notes)
    wrong = broken_deck(
        tmp_path / "c",
        "compression_small_set",
        lambda t: older_format(t).replace("Wall_List:\n    - 1", "Wall_List:\n    - 2"),
    )
    with pytest.raises(
        InputError, match=r"\[2\] names walls that do not exist \(walls are numbered 0 .. 1"
    ):
        peridem.translate(wrong)


def test_a_compressive_test_direction_outside_the_dimension_is_refused(tmp_path: Path) -> None:
    def direction_3(text: str) -> str:
        return older_format(text).replace("Wall_Force_Direction: 2", "Wall_Force_Direction: 3")

    deck = broken_deck(tmp_path, "compression_small_set", direction_3)
    with pytest.raises(InputError, match="Wall_Force_Direction: a direction 1 to 2, got 3"):
        peridem.translate(deck)


def test_a_wall_block_beside_particle_entries_is_ignored_as_peridem_does(tmp_path: Path) -> None:
    """Today's format describes walls under Particle; a Wall block there is one PeriDEM does
    not read, so it changes nothing (only the older format, where the wall zone has no
    Particle entry, reads it)."""

    def with_wall_block(text: str) -> str:
        data = yaml.safe_load(text)
        data["Wall"] = {"Zone_9": {"Type": "flexible", "All_Dofs_Constrained": True, "Mesh": True}}
        return yaml.safe_dump(data)

    new = peridem.translate(DECKS / "compression_small_set" / "input_0.yaml")
    deck = broken_deck(tmp_path, "compression_small_set", with_wall_block)
    translated = peridem.translate(deck)
    assert translated.case == new.case
    assert "Wall: not read (PeriDEM does not use it to run either)" in translated.notes
