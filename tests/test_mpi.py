"""Distributed runs against the serial run, bit for bit, on 2 and 3 MPI ranks (3 ranks
oversubscribe 2 cores: correctness, not speed). Each case runs tests/mpi_check.py under the
mpiexec of the MPI installed with mpi4py (`pip install ".[test]"` brings both from PyPI)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

CHECK = Path(__file__).with_name("mpi_check.py")


def mpiexec() -> str:
    """The mpiexec beside this Python (the mpich wheel's), else the one on PATH."""
    beside = Path(sys.executable).with_name("mpiexec")
    found = str(beside) if beside.exists() else shutil.which("mpiexec")
    if found is None:
        raise RuntimeError('no mpiexec: install the test extras, pip install ".[test]"')
    return found


def run_ranks(ranks: int, *arguments: str) -> subprocess.CompletedProcess[str]:
    """mpi_check.py on `ranks` ranks; a hang fails the test after 5 minutes."""
    environment = {**os.environ, "OMP_NUM_THREADS": "1"}
    command = [mpiexec(), "-n", str(ranks), sys.executable, str(CHECK), *arguments]
    return subprocess.run(command, capture_output=True, text=True, timeout=300, env=environment)


@pytest.mark.parametrize(
    ("ranks", "dimension", "steps"), [(2, 2, 200), (3, 2, 200), (2, 3, 60), (3, 3, 60)]
)
def test_a_distributed_run_is_the_serial_run_bit_for_bit(
    ranks: int, dimension: int, steps: int
) -> None:
    done = run_ranks(ranks, str(dimension), str(steps))
    assert done.returncode == 0, done.stdout + done.stderr
    assert f"ranks {ranks}, {dimension}D" in done.stdout
    assert "'positions': 0.0, 'velocities': 0.0, 'forces': 0.0" in done.stdout


def test_grains_moving_past_the_ghost_margin_stop_every_rank_with_the_reason() -> None:
    done = run_ranks(3, "2", "50", "1e-6")  # the grains are thrown at up to 0.5 m/s
    assert done.returncode == 0, done.stdout + done.stderr
    assert "more than half the ghost margin" in done.stdout


def test_a_blow_up_on_one_rank_ends_every_rank_without_a_hang() -> None:
    done = run_ranks(3, "2", "20", "fail")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "rank 2 failed" in done.stdout and "InstabilityError" in done.stdout
