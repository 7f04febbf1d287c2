"""The distributed run the rank benchmarks time (stop_checks.py, checkpoint_pieces.py): the 3D
pile of `granulate bench --ranks` on the world communicator, one thread per rank, stepped; and
the mean seconds of an action every rank takes together."""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable

from mpi4py import MPI

from granulate import bench_ranks
from granulate.parallel import DistributedRun
from granulate.threads import set_num_threads


def stepped_pile(grains: int, steps: int, comm: MPI.Comm) -> DistributedRun:
    """pile3d of `grains` grains on the ranks of `comm`, one thread each, after `steps` steps
    (the grains start pressed: that warning is not printed)."""
    set_num_threads(1, adaptive=False)
    sim = bench_ranks.pile3d(grains)
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="contact.*bodies pressed")
        run = DistributedRun(sim, comm)
        run.run(steps)
    return run


def mean_seconds(action: Callable[[], object], calls: int, comm: MPI.Comm) -> float:
    """The mean wall-clock seconds of `calls` calls of `action`, every rank starting together
    and the last finishing (barriers)."""
    comm.Barrier()
    start = time.perf_counter()
    for _ in range(calls):
        action()
    comm.Barrier()
    return (time.perf_counter() - start) / calls
