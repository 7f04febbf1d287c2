"""YAML case files and the command line: example cases check and run; broken cases exit 2 with
a message naming the problem; fuzzed cases never raise anything but InputError; resume through
the CLI continues bit for bit; plots and renders are written; the schema reference."""

from __future__ import annotations

import filecmp
import json
import re
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import granulate as gr
from granulate import case as case_files
from granulate.cli import main
from granulate.errors import InputError

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE_CASES = sorted((ROOT / "examples" / "cases").glob("*.yaml"))
BROKEN = sorted((Path(__file__).parent / "cases" / "broken").glob("*.yaml"))
BASE = Path(__file__).parent / "cases" / "base.yaml"


def test_there_are_example_cases_and_a_broken_corpus() -> None:
    assert len(EXAMPLE_CASES) >= 3
    assert len(BROKEN) >= 30


@pytest.mark.parametrize("path", EXAMPLE_CASES, ids=lambda p: p.stem)
def test_example_cases_pass_check(path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    assert "valid" in out and "nodes" in out and "estimated time" in out


@pytest.mark.parametrize("path", EXAMPLE_CASES, ids=lambda p: p.stem)
def test_example_cases_run_briefly(path: Path, tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--steps", "30", "--quiet"]) == 0
    assert (out / "simulation.pvd").exists() and (out / "history.csv").exists()
    assert (out / "checkpoint.npz").exists()
    assert list((out / "frames").glob("particles_*.csv"))


def test_base_case_is_valid(tmp_path: Path) -> None:
    assert main(["check", str(BASE)]) == 0


@pytest.mark.parametrize("path", BROKEN, ids=lambda p: p.stem)
def test_broken_cases_exit_2_naming_the_problem(
    path: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    expected = re.match(r"# expect: (.*)", path.read_text()).group(1)  # type: ignore[union-attr]
    code = main(["check", str(path)])
    error = capsys.readouterr().err
    assert code == 2, error
    assert error.startswith("granulate: error: ") and "Traceback" not in error
    assert expected in error, error


def test_a_case_sets_when_the_ranks_balance_their_work() -> None:
    """load_balance reaches the simulation (a distributed run reads it: test_mpi.py); left
    out, the default: every 100 steps, past 1.1 times the mean; .inf is YAML's infinity. It
    is left out of the case's fingerprint, so a checkpoint resumes under other settings."""
    text = BASE.read_text()
    assert case_files.parse_case(text, BASE).build().load_balance == gr.LoadBalance()
    given = text + "load_balance: {every: 0, threshold: .inf, weight: time}\n"
    built = case_files.parse_case(given, BASE).build()
    assert built.load_balance == gr.LoadBalance(every=0, threshold=float("inf"), weight="time")
    # Its speed, not its results: the fingerprint a checkpoint is resumed by is the same.
    assert built.case_fingerprint == case_files.parse_case(text, BASE).fingerprint


def test_base_case_through_run_plot_and_render(tmp_path: Path) -> None:
    out = tmp_path / "run"
    assert main(["run", str(BASE), "--out", str(out), "--quiet"]) == 0
    assert main(["run", str(BASE), "--out", str(out), "--quiet"]) == 2  # never overwritten
    assert main(["plot", str(out)]) == 0
    for name in ("energies.png", "broken_bonds.png", "wall_box.png", "grading.png", "breakage.png"):
        assert (out / name).stat().st_size > 1000
    assert main(["render", str(out), "--gif"]) == 0
    assert (out / "renders" / "run.gif").stat().st_size > 1000
    assert len(list((out / "renders").glob("frame_*.png"))) >= 5
    assert main(["render", str(out), "--frame", "999"]) == 2
    assert main(["plot", str(tmp_path / "nothing")]) == 2


def test_resume_through_the_cli_continues_bit_for_bit(tmp_path: Path) -> None:
    whole, split = tmp_path / "whole", tmp_path / "split"
    assert main(["run", str(BASE), "--out", str(whole), "--quiet"]) == 0
    assert main(["run", str(BASE), "--out", str(split), "--quiet", "--steps", "70"]) == 0
    assert main(["run", str(BASE), "--out", str(split), "--quiet", "--resume"]) == 0
    files = sorted(
        str(p.relative_to(whole))
        for p in whole.rglob("*")
        if p.is_file() and p.name not in ("run.json", "checkpoint.npz")
    )
    assert len(files) > 5
    for name in files:
        assert filecmp.cmp(whole / name, split / name, shallow=False), name


def test_resume_works_with_per_pair_contact(tmp_path: Path) -> None:
    """The fingerprint names materials by order, not identity: a case reloaded for --resume
    (new Material objects) with a per-pair contact law still matches its checkpoint."""
    case = tmp_path / "pairs.yaml"
    text = BASE.read_text().replace(
        "walls:",
        "contact_pairs:\n  - {materials: [rock, rock], contact: {restitution: 0.5}}\nwalls:",
    )
    case.write_text(text)
    whole, split = tmp_path / "whole", tmp_path / "split"
    assert main(["run", str(case), "--out", str(whole), "--quiet"]) == 0
    assert main(["run", str(case), "--out", str(split), "--quiet", "--steps", "70"]) == 0
    assert main(["run", str(case), "--out", str(split), "--quiet", "--resume"]) == 0
    assert filecmp.cmp(whole / "history.csv", split / "history.csv", shallow=False)


def test_resume_refuses_another_case(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "run"
    assert main(["run", str(BASE), "--out", str(out), "--quiet", "--steps", "40"]) == 0
    other = tmp_path / "other.yaml"
    other.write_text(BASE.read_text().replace("gravity: [0, -9.81]", "gravity: [0, -5]"))
    assert main(["run", str(other), "--out", str(out), "--quiet", "--resume"]) == 2
    assert "different set-up" in capsys.readouterr().err
    assert main(["run", str(BASE), "--out", str(tmp_path / "new"), "--resume", "--quiet"]) == 2


def test_schema_reference_and_json_schema(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["schema"]) == 0
    reference = capsys.readouterr().out
    for key in ("materials", "packings", "walls", "loading", "checkpoint", "stop", "[m]"):
        assert key in reference
    assert main(["schema", "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    assert "dimension" in document["properties"]
    committed = json.loads((ROOT / "docs" / "case.schema.json").read_text())
    assert committed == document, "regenerate docs/case.schema.json: granulate schema --json"


# ----------------------------------------------------------------------------- fuzzing
BASE_DATA = yaml.safe_load(BASE.read_text())
scalars = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-5, 5),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=8),
)
values = st.recursive(
    scalars,
    lambda inner: st.one_of(
        st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=8), inner, max_size=4)
    ),
    max_leaves=8,
)


def _paths(data: object, prefix: tuple = ()) -> list[tuple]:
    found = [prefix]
    if isinstance(data, dict):
        for key, value in data.items():
            found += _paths(value, (*prefix, key))
    elif isinstance(data, list):
        for index, value in enumerate(data):
            found += _paths(value, (*prefix, index))
    return found


PATHS = _paths(BASE_DATA)[1:]


@st.composite
def mutated_cases(draw: st.DrawFn) -> dict:
    data = json.loads(json.dumps(BASE_DATA))
    for _ in range(draw(st.integers(1, 3))):
        path = draw(st.sampled_from(PATHS))
        parent = data
        try:
            for part in path[:-1]:
                parent = parent[part]
        except (KeyError, IndexError, TypeError):
            continue
        action = draw(st.sampled_from(["number", "number", "replace", "delete", "rename"]))
        key = path[-1]
        if not isinstance(parent, dict | list):
            continue
        try:
            if action == "number":  # same type, other value: reaches the building stage
                old = parent[key]
                if isinstance(old, bool) or not isinstance(old, int | float):
                    continue
                # Scaled within a factor of 2, or made invalid: fuzzing the checks, not the
                # machine's memory (a valid case may be as large as the user wants).
                factor = draw(st.sampled_from([0, -1, 0.5, 2, float("nan"), float("inf")]))
                scaled = old * factor
                keep_int = isinstance(old, int) and np.isfinite(scaled)
                parent[key] = int(scaled) if keep_int else scaled
            elif action == "replace":
                parent[key] = draw(values)
            elif action == "delete" and isinstance(parent, dict):
                del parent[key]
            elif action == "rename" and isinstance(parent, dict):
                parent[draw(st.text(max_size=8))] = parent.pop(key)
        except (KeyError, IndexError, TypeError):  # an earlier mutation changed the structure
            continue
    return data


@settings(
    max_examples=150,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
@given(mutated_cases())
def test_fuzzed_cases_raise_input_error_or_build(data: dict) -> None:
    text = yaml.safe_dump(data)
    try:
        case = case_files.parse_case(text, BASE)
        case.build(outputs=False)
    except InputError:
        pass


@pytest.mark.parametrize("with_contact", [True, False])
def test_precracks_in_a_case_file_break_bonds(tmp_path: Path, with_contact: bool) -> None:
    """Any precracks entry stopped the run ("cannot change contact after the simulation has
    started"): precrack built the simulation before contact and walls were set. It is kept
    until the build now; here it cuts the first particle in two."""
    text = BASE.read_text() + (
        "precracks:\n  - {point: [0.005, 0.005], normal: [1, 0], "
        "region: {type: rectangle, lower: [0.004, 0.003], upper: [0.006, 0.007]}}\n"
    )
    if not with_contact:  # a body-only case: one plate, no grains, walls or packings
        text = (
            "dimension: 2\nmaterials:\n  rock: {density: 2600, youngs_modulus: 5.0e+7, "
            "poisson_ratio: 0.25, fracture_energy: 20}\nbodies:\n  - {name: plate, material: "
            "rock, mesh_size: 2.5e-4, shape: {type: rectangle, lower: [0, 0], upper: [0.01, "
            "0.01]}}\ntime: {end: 1.0e-5}\n"
            "precracks:\n  - {point: [0.005, 0.005], normal: [1, 0]}\n"
        )
    case = tmp_path / "cracked.yaml"
    case.write_text(text)
    assert main(["check", str(case)]) == 0
    out = tmp_path / "out"
    assert main(["run", str(case), "--out", str(out), "--quiet"]) == 0
    history = (out / "history.csv").read_text().splitlines()
    header = history[0].split(",")
    first = dict(zip(header, history[1].split(","), strict=True))
    assert int(first["broken_bonds"]) > 0


def test_a_packing_in_a_union_container_checks_and_runs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    case = tmp_path / "union.yaml"
    case.write_text(
        BASE.read_text()
        .replace(
            "packings:\n  - {container: {type: rectangle, lower: [0, 0], upper: [0.01, 0.004]}",
            "shapes:\n  bin: {type: union, shapes: [{type: rectangle, lower: [0, 0], upper: "
            "[0.01, 0.004]}, {type: rectangle, lower: [0.003, 0.004], upper: [0.007, 0.008]}]}\n"
            "packings:\n  - {container: bin",
        )
        .replace("particles:\n  - {grain: pebble, position: [0.005, 0.005]}\n", "")
    )
    assert "container: bin" in case.read_text()
    assert main(["check", str(case)]) == 0
    assert "packing fraction" in capsys.readouterr().out
    assert main(["run", str(case), "--out", str(tmp_path / "out"), "--quiet", "--steps", "5"]) == 0


def test_files_that_are_not_what_they_should_be_get_one_message(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A UTF-16 case file, a loop of symbolic links as a mesh, and a gmsh header declaring
    9e11 nodes (meshio would allocate them) are refused with one line each, no traceback."""
    utf16 = tmp_path / "utf16.yaml"
    utf16.write_bytes(BASE.read_text().encode("utf-16"))
    (tmp_path / "loop_a").symlink_to(tmp_path / "loop_b")
    (tmp_path / "loop_b").symlink_to(tmp_path / "loop_a")
    huge = tmp_path / "huge.msh"
    huge.write_text("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n900000000000\n1 0 0 0\n")
    mesh_case = BASE.read_text().replace(
        "    shape: {type: disc, radius: 1.0e-3}\n", "    mesh: {file: MESH}\n"
    )
    cases = {
        utf16: "is not UTF-8 text",
        tmp_path / "looped.yaml": "cannot be resolved",
        tmp_path / "huge.yaml": "900,000,000,000 nodes declared",
    }
    (tmp_path / "looped.yaml").write_text(mesh_case.replace("MESH", "loop_a"))
    (tmp_path / "huge.yaml").write_text(mesh_case.replace("MESH", "huge.msh"))
    for path, message in cases.items():
        assert main(["check", str(path)]) == 2
        error = capsys.readouterr().err
        assert message in error and error.count("\n") == 1 and "Traceback" not in error, error
