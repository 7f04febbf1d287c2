"""The command line: info, running a script, exit codes and one-line errors."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from granulate.cli import main
from granulate.parallel.launch import launched_ranks


def granulate(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "granulate", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        check=False,
    )


def test_info() -> None:
    result = granulate("info")
    assert result.returncode == 0
    assert "granulate 0.1.0" in result.stdout and "threads:" in result.stdout


def test_run_script_and_input_error_exit_codes(tmp_path: Path) -> None:
    good = tmp_path / "good.py"
    good.write_text(
        "import granulate as gr\n"
        "m = gr.Material(density=1000, youngs_modulus=1e9, poisson_ratio=0.25, fracture=False)\n"
        "s = gr.Simulation(2)\n"
        "s.add_body(gr.Rectangle((0, 0), (0.01, 0.01)), m, 1e-3)\n"
        "s.run(10)\n"
        "print('done', s.step)\n"
    )
    result = granulate("--threads", "1", "run", str(good))
    assert result.returncode == 0 and "done 10" in result.stdout

    bad = tmp_path / "bad.py"
    bad.write_text(
        "import granulate as gr\n"
        "m = gr.Material(density=1000, youngs_modulus=1e9, poisson_ratio=0.25,\n"
        "                fracture=False, horizon=1e-4)\n"
        "s = gr.Simulation(2)\n"
        "s.add_body(gr.Rectangle((0, 0), (0.01, 0.01)), m, 1e-3)\n"
        "s.run(10)\n"
    )
    result = granulate("run", str(bad))
    assert result.returncode == 2
    assert result.stderr.strip().startswith("granulate: error:")
    assert "smaller than the mesh size" in result.stderr
    assert "Traceback" not in result.stderr


def test_blow_up_exits_1(tmp_path: Path) -> None:
    script = tmp_path / "unstable.py"
    script.write_text(
        "import warnings, granulate as gr\n"
        "warnings.simplefilter('ignore')\n"
        "m = gr.Material(density=1000, youngs_modulus=1e9, poisson_ratio=0.25, fracture=False)\n"
        "s = gr.Simulation(2)\n"
        "b = s.add_body(gr.Rectangle((0, 0), (0.01, 0.01)), m, 1e-3, velocity=(0, 1))\n"
        "s.dt = 5 * s.stable_dt  # the most a run accepts\n"
        "s.velocities[:5, 0] = 1.0\n"
        "s.run(1000)\n"
    )
    result = granulate("run", str(script))
    assert result.returncode == 1
    assert "unstable" in result.stderr and "Traceback" not in result.stderr


def test_missing_script_is_a_user_error() -> None:
    result = granulate("run", "does_not_exist.py")
    assert result.returncode == 2 and "does not exist" in result.stderr


def test_bench_quick_prints_the_documented_keys(tmp_path: Path) -> None:
    result = granulate(
        "--threads",
        "1",
        "bench",
        "--quick",
        "--json",
        "--case",
        "lps3d_lattice",
        "--case",
        "compression_small",
        "--case",
        "vtu_1m",
        "--out",
        str(tmp_path),
        cwd=Path(__file__).parents[1],
    )
    assert result.returncode == 0, result.stderr
    import json

    rows = [json.loads(line) for line in result.stdout.splitlines()]
    assert [r["case"] for r in rows] == ["lps3d_lattice", "compression_small", "vtu_1m"]
    keys = {
        "case",
        "nodes",
        "bonds",
        "particles",
        "steps",
        "threads",
        "seconds",
        "node_steps_per_s",
        "bond_evals_per_s",
        "peak_rss_mb",
        "phases",
    }
    for r in rows:
        assert keys <= set(r)
        assert r["threads"] == 1 and r["seconds"] > 0
    assert set(rows[0]["phases"]) == {
        "peridynamics",
        "contact_search",
        "contact_forces",
        "walls",
        "integration",
        "output",
    }
    # 16 bytes in the shared bond family, 1 bit of state (each node's bits on whole bytes).
    assert rows[0]["memory"]["bytes_per_bond"] == pytest.approx(16.125, abs=0.02)
    assert granulate("bench", "--case", "nonsense").returncode == 2


def test_a_long_set_up_is_announced_before_it_starts(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from granulate import cli
    from granulate.case import load_case

    text = (Path(__file__).parents[1] / "examples" / "cases" / "pile_2d.yaml").read_text()
    for count, said in ((30, False), (200_000, True)):
        case_file = tmp_path / f"pile_{count}.yaml"
        case_file.write_text(text.replace("count: 30,", f"count: {count},"))
        cli._announce_setup(load_case(case_file))  # loads the case only: nothing is placed
        out = capsys.readouterr().out
        assert ("packing 200,000 grains: set-up takes about 60 s" in out) is said, out


@pytest.mark.parametrize(
    "environ",
    [
        {"OMPI_COMM_WORLD_SIZE": "2", "OMPI_COMM_WORLD_RANK": "{rank}"},  # Open MPI
        {"PMI_SIZE": "2", "PMI_RANK": "{rank}"},  # MPICH, Intel MPI
        {"SLURM_STEP_NUM_TASKS": "2", "SLURM_PROCID": "{rank}"},  # srun
    ],
    ids=["openmpi", "hydra", "srun"],
)
def test_commands_started_as_several_mpi_ranks_say_what_is_wrong_once(
    environ: dict[str, str],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Under a launcher's K ranks, `granulate convert` (K copies would write one file) is
    refused, and `granulate run case.yaml` without mpi4py is told to install the mpi extra
    (tests/test_mpi_cli.py runs real ranks): rank 0 says so once, every rank exits 2, nothing is
    written. `granulate schema` prints once. A Python script (which may use mpi4py itself)
    still runs."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setitem(sys.modules, "mpi4py", None)  # import mpi4py fails
    case = Path(__file__).parent / "cases" / "base.yaml"
    for rank in (0, 1):
        for name, value in environ.items():
            monkeypatch.setenv(name, value.format(rank=rank))
        assert main(["convert", "input_0.yaml", "-o", "case.yaml"]) == 2
        assert main(["run", str(case)]) == 2
        printed = capsys.readouterr()
        assert main(["schema"]) == 0
        assert (capsys.readouterr().out != "") == (rank == 0)  # printed once, by rank 0
        if rank == 0:
            refused, missing = printed.err.splitlines()
            assert "'granulate convert' was started as 2 MPI processes" in refused
            assert "mpi4py is not installed: pip install 'granulate[mpi]'" in missing
        else:
            assert printed.err == "" and printed.out == ""
    assert sorted(tmp_path.iterdir()) == []
    script = tmp_path / "sweep.py"
    script.write_text("print('ran')\n")
    assert main(["run", str(script)]) == 0
    assert capsys.readouterr().out == "ran\n"


def test_a_batch_script_outside_srun_is_one_process() -> None:
    """Slurm sets SLURM_STEP_NUM_TASKS = 1 for the batch script itself."""
    slurm = {"SLURM_NTASKS": "8", "SLURM_STEP_NUM_TASKS": "1", "SLURM_PROCID": "0"}
    assert launched_ranks(slurm) == (1, 0)
    assert launched_ranks({}) == (1, 0)
    assert launched_ranks({"PMI_SIZE": "3", "PMI_RANK": "2"}) == (3, 2)
