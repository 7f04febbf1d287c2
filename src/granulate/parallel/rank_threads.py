"""Each rank's share of its machine's cores, as its OpenMP thread count by default.

Every rank of a distributed run runs its own OpenMP threads. Left at OpenMP's default (every CPU
the process may use), K ranks on one machine start K times as many threads as it has cores, and
threads spinning at their barriers while another rank holds their core slow a run down by up to
three orders of magnitude (the drum of tests/mpi_stop_check.py, 600 steps of a bare
DistributedRun on 2 ranks of 2 cores: 59-62 s with 2 threads each, 0.07-0.08 s with 1). So,
unless the user set a thread count (OMP_NUM_THREADS, granulate.set_num_threads, ``granulate
--threads``: granulate.threads), a rank uses at most its share: the CPUs it may use over the
ranks on its machine (MPI.COMM_TYPE_SHARED), at least 1. Simulation.run's thread tuner then
adapts below that.
"""

from __future__ import annotations

from typing import Any

from granulate import _core, threads


def share_of_cores(comm: Any) -> int:
    """Every rank of `comm` together: cap this rank's threads at its share of its machine's
    CPUs unless the user set a thread count; the count it now uses."""
    from mpi4py import MPI

    machine = comm.Split_type(MPI.COMM_TYPE_SHARED)
    share = max(1, threads.available_cpus() // machine.Get_size())
    machine.Free()
    if threads.is_adaptive() and threads.get_num_threads() > share:
        _core.set_num_threads(share)
    return threads.get_num_threads()
