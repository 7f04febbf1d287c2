"""Faults around the output directory: a full disk, --overwrite followed by an input error, two
runs into one folder, leftovers of interrupted writes, folders that cannot hold a run."""

from __future__ import annotations

import errno
import json
import os
import socket
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import meshio
import pytest

import granulate as gr
from granulate.cli import main
from granulate.io import vtu

BASE = Path(__file__).parent / "cases" / "base.yaml"


def listed_frames(directory: Path) -> list[str]:
    collection = ET.parse(directory / "simulation.pvd").getroot().find("Collection")
    return [d.get("file") for d in collection.findall("DataSet")]


def test_a_full_disk_is_one_message_and_run_json_says_failed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The fourth frame meets a full disk: exit 1, one line naming the file and the cause, no
    traceback; run.json says failed; the frames written before are intact and listed."""
    written = vtu.atomic_write
    calls = {"frames": 0}

    def filling(path, data) -> None:
        if Path(path).name.startswith("frame_"):
            calls["frames"] += 1
            if calls["frames"] == 4:
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
        written(path, data)

    monkeypatch.setattr(vtu, "atomic_write", filling)
    out = tmp_path / "run"
    assert main(["run", str(BASE), "--out", str(out), "--quiet"]) == 1
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and "Traceback" not in error
    assert "could not write" in error and "No space left on device" in error
    assert "frame_000003.vtu" in error
    summary = json.loads((out / "run.json").read_text())
    assert summary["status"].startswith("failed: ") and "No space left" in summary["status"]
    frames = listed_frames(out)
    assert frames == [f"frames/frame_{k:06d}.vtu" for k in range(3)]
    for frame in frames:
        assert len(meshio.read(out / frame).points) > 0
    assert not (out / ".granulate.lock").exists()


def test_overwrite_followed_by_an_input_error_keeps_the_old_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """--overwrite deleted the old frames at once, so an error found after (here --steps 0)
    left a PVD listing frames that no longer existed. The old run is now replaced only when the
    new one starts writing, with the pieces of a distributed run's checkpoint."""
    out = tmp_path / "run"
    assert main(["run", str(BASE), "--out", str(out), "--quiet"]) == 0
    before = {p.name: p.read_bytes() for p in (out / "frames").iterdir()}
    pvd = (out / "simulation.pvd").read_bytes()
    assert (
        main(["run", str(BASE), "--out", str(out), "--quiet", "--overwrite", "--steps", "0"]) == 2
    )
    assert "--steps must be positive" in capsys.readouterr().err
    assert {p.name: p.read_bytes() for p in (out / "frames").iterdir()} == before
    assert (out / "simulation.pvd").read_bytes() == pvd
    stale = out / "checkpoint.npz.pieces" / "100-0a1b2c3d"  # a distributed run's checkpoint
    stale.mkdir(parents=True)
    assert (
        main(["run", str(BASE), "--out", str(out), "--quiet", "--overwrite", "--steps", "30"]) == 0
    )
    assert len(listed_frames(out)) < len(before) // 2  # replaced by the shorter run
    assert not (out / "checkpoint.npz.pieces").exists()


def plate(out: Path, **output) -> gr.Simulation:
    sim = gr.Simulation(2)
    material = gr.Material(density=2500, youngs_modulus=7e10, poisson_ratio=0.22, fracture=False)
    sim.add_body(gr.Rectangle((0, 0), (0.01, 0.005)), material, 0.5e-3)
    sim.output(out, every=10, **output)
    return sim


def test_a_second_run_into_a_locked_folder_is_refused(tmp_path: Path) -> None:
    """Two runs into one folder interleaved their rows and frames and both exited 0. A run
    holds .granulate.lock while it writes; another live process's lock refuses the run, a lock
    left by a process that is gone is taken over, and the lock goes when the run ends."""
    out = tmp_path / "run"
    sim = plate(out)
    lock = out / ".granulate.lock"
    out.mkdir()
    other = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(30)"])
    try:
        lock.write_text(json.dumps({"pid": other.pid, "host": socket.gethostname()}))
        with pytest.raises(gr.InputError, match="another run is writing into"):
            sim.run(20)
        assert not (out / "simulation.pvd").exists()
    finally:
        other.kill()
        other.wait()
    sim.run(20)  # the holder is gone: its lock is stale
    assert not lock.exists() and len(listed_frames(out)) == 3


def test_a_serial_run_on_one_of_several_ranks_is_told_to_give_its_simulation_a_comm(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`mpiexec -n 2 granulate run example.py` of a script whose Simulation has no comm ran the
    whole script on each rank, and the second rank was refused the folder the first was writing
    with no word of MPI. Started as rank 1 of 2 (the launcher's variables), the refusal says so
    and what to do."""
    out = tmp_path / "run"
    sim = plate(out)
    out.mkdir()
    (out / ".granulate.lock").write_text(
        json.dumps({"pid": os.getpid(), "host": socket.gethostname()})
    )
    monkeypatch.setenv("PMI_SIZE", "2")
    monkeypatch.setenv("PMI_RANK", "1")
    with pytest.raises(gr.InputError) as refused:
        sim.run(20)
    assert str(refused.value).startswith(f"another run is writing into {out}")
    assert "rank 1 of 2 MPI ranks" in str(refused.value)
    assert "gr.Simulation(..., comm=MPI.COMM_WORLD)" in str(refused.value)


def test_frames_without_a_pvd_are_a_run_too(tmp_path: Path) -> None:
    out = tmp_path / "run"
    (out / "frames").mkdir(parents=True)
    (out / "frames" / "frame_000000.vtu").write_text("<VTKFile/>")
    with pytest.raises(gr.InputError, match="already holds a run"):
        plate(out)


def test_resuming_removes_the_temporaries_of_interrupted_writes(tmp_path: Path) -> None:
    out = tmp_path / "run"
    plate(out).run(20)
    leftovers = [out / ".checkpoint.npz.x1y2.tmp", out / "frames" / ".frame_000009.vtu.ab.tmp"]
    for leftover in leftovers:
        leftover.write_bytes(b"partial")
    plate(out, resume=True)
    assert not any(leftover.exists() for leftover in leftovers)
    assert (out / "simulation.pvd").exists()


@pytest.mark.parametrize("kind", ["file", "under a file"])
def test_folders_that_cannot_hold_a_run_are_refused_by_check_and_run(
    tmp_path: Path, kind: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """check said valid and run gave a NotADirectoryError traceback."""
    blocker = tmp_path / "blocker"
    blocker.write_text("a file")
    target = blocker if kind == "file" else blocker / "out"
    case = tmp_path / "case.yaml"
    case.write_text(
        BASE.read_text().replace(
            "output: {every: 20}", f"output: {{directory: {target}, every: 20}}"
        )
    )
    assert main(["check", str(case)]) == 2
    assert main(["run", str(case), "--quiet"]) == 2
    errors = capsys.readouterr().err
    assert errors.count(f"output directory {target}") == 2 and "Traceback" not in errors


@pytest.mark.parametrize(
    ("directory", "message"),
    [
        ("nul\0name", "holds a NUL character"),
        ("x" * 300, "longer than 255 bytes"),
        ("/dev/null/out", "is under the file /dev/null"),
        ("/proc/granulate_out", "cannot be made"),
    ],
)
def test_output_paths_the_system_rejects_are_input_errors(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, directory: str, message: str
) -> None:
    """They gave ValueError, OSError or NotADirectoryError tracebacks."""
    monkeypatch.chdir(tmp_path)
    with pytest.raises(gr.InputError, match=message):
        plate(Path(directory)).run(5)


def test_an_output_interval_that_would_fill_the_disk_is_refused(tmp_path: Path) -> None:
    """Frames every 10 steps of a 10^12-step run (about 5 PB): refused before anything is
    written, with the size and the free space."""
    sim = plate(tmp_path / "run")
    with pytest.raises(gr.InputError, match="would write 100,000,000,001 frames"):
        sim.run(10**12)
    assert not (tmp_path / "run" / "simulation.pvd").exists()


def test_checkpoints_every_step_of_a_huge_run_are_refused(tmp_path: Path) -> None:
    """A checkpoint every step of a 10^12-step run would make the run mostly writing."""
    sim = plate(tmp_path / "run")
    sim.checkpoint_every(1)
    with pytest.raises(gr.InputError, match="checkpoints every 1 steps would write"):
        sim.run(10**12)
    sim.checkpoint_every(100)
    sim.run(200)  # an ordinary interval runs
    assert (tmp_path / "run" / "checkpoint.npz").exists()
