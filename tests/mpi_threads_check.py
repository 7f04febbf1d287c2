"""Run under `mpiexec -n K python tests/mpi_threads_check.py` (tests/test_mpi.py does): each
rank of a DistributedRun of the drum (tests/assemblies.py) prints, through rank 0, the
thread count it uses (parallel/rank_threads.py) and the CPUs it may use."""

from __future__ import annotations

import sys
from pathlib import Path

from mpi4py import MPI

sys.path.insert(0, str(Path(__file__).parent))
import granulate as gr
from assemblies import tumbling_drum
from granulate.parallel import DistributedRun
from granulate.threads import available_cpus

comm = MPI.COMM_WORLD
run = DistributedRun(tumbling_drum(Path("unused"), outputs=False), comm)
run.run(10)
rows = comm.gather((gr.get_num_threads(), available_cpus()), root=0)
if comm.Get_rank() == 0:
    print(f"threads and CPUs per rank {rows}")
