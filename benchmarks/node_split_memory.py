"""Each rank's peak memory in a run of one body cut at node level: `granulate bench --ranks`'
notched block (53,400 nodes), 20 steps with an output step every 10 (history.csv and a frame
of every node), run(gather=False) as `granulate run` runs, and a checkpoint at the end.

    OMP_NUM_THREADS=1 mpiexec -n 2 python benchmarks/node_split_memory.py OUT

Rank 0 prints each rank's peak resident memory (ru_maxrss) [MB].
"""

from __future__ import annotations

import resource
import sys

from mpi4py import MPI

from granulate.bench_ranks import block

comm = MPI.COMM_WORLD
sim = block(comm=comm)
sim.output(sys.argv[1], every=10, overwrite=True)
sim.run(20, gather=False)
sim.save_checkpoint(sys.argv[1] + "/checkpoint.npz")
rss = comm.gather(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss // 1024, root=0)
if comm.rank == 0:
    print("max RSS MB per rank", rss)
