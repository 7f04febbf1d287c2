"""What a distributed run's checkpoint costs each rank: the seconds to save it and to load it
again, how much each rank's peak resident memory rose in each (VmHWM), and the
files written; and whether rank 0 built the whole model for it. Since session 51 each rank
writes its own grains' piece (granulate/parallel/checkpoint_pieces.py); before, rank 0 took
every grain's state into its whole simulation and wrote one file. Run it from two installs,
alternating, for an A/B.

    OMP_NUM_THREADS=1 mpiexec -n 2 python benchmarks/checkpoint_pieces.py [--grains 1000]
        [--steps 5]

The case is the 3D pile of `granulate bench --ranks` (1,000 grains: 258,624 nodes).
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path

from mpi4py import MPI
from pile_ranks import mean_seconds, stepped_pile
from process_memory import status_mb


def timed(comm: MPI.Comm, action: Callable[[], object]) -> tuple[float, float]:
    """Seconds `action()` took, every rank starting together, and how much it raised this
    process's peak resident memory (VmHWM) [MB]."""
    before = status_mb("VmHWM")[0]
    seconds = mean_seconds(action, 1, comm)
    return seconds, status_mb("VmHWM")[0] - before


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--grains", type=int, default=1000)
    parser.add_argument("--steps", type=int, default=5)
    options = parser.parse_args()
    comm = MPI.COMM_WORLD
    run = stepped_pile(options.grains, options.steps, comm)
    sim = run._sim
    folder = Path(comm.bcast(tempfile.mkdtemp() if comm.Get_rank() == 0 else None, root=0))
    path = folder / "checkpoint.npz"
    saved = timed(comm, lambda: run.save_checkpoint(path))
    loaded = timed(comm, lambda: run.load_checkpoint(path))
    rows = comm.gather((saved, loaded), root=0)
    if rows is None:
        return
    files = sorted(p for p in folder.rglob("*") if p.is_file())
    sizes = ", ".join(f"{p.relative_to(folder)} {p.stat().st_size / 2**20:.1f} MB" for p in files)
    print(f"{sim.node_count:,} nodes; rank 0 built the whole model: {sim._core is not None}")
    print(f"files: {sizes}")
    for rank, ((save_s, save_mb), (load_s, load_mb)) in enumerate(rows):
        print(
            f"rank {rank}: save {save_s:.2f} s, peak +{save_mb:.0f} MB; "
            f"load {load_s:.2f} s, peak +{load_mb:.0f} MB"
        )
    shutil.rmtree(folder)


if __name__ == "__main__":
    main()
