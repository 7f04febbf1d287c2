"""A body split at node level on the ranks of MPI.COMM_WORLD (granulate.parallel.node_split)
against the serial run on rank 0: prints the largest difference of every node's position,
velocity, force and dilatation, the bonds broken, and each rank's halo.

    mpiexec -n K python tests/mpi_split_check.py SHAPE MODEL STEPS

SHAPE and MODEL as tests/assemblies.py's `pulled` takes them (plate, strip or block; lps
or pmb)."""

from __future__ import annotations

import sys

import numpy as np
from mpi4py import MPI

from assemblies import pulled
from granulate.parallel.node_split import NodeSplitRun
from rank_zero import wait_asleep

FIELDS = ("positions", "velocities", "forces", "dilatation")


def main() -> int:
    shape, model, steps = sys.argv[1], sys.argv[2], int(sys.argv[3])
    comm = MPI.COMM_WORLD
    split = NodeSplitRun(pulled(shape, model), comm)
    split.run(steps)
    gathered = {field: split.gather(field) for field in FIELDS}
    halos = comm.gather((len(split.own), split.halo_nodes), root=0)
    broken = split.broken_bonds()
    exchange = comm.gather(split.seconds["exchange"] / sum(split.seconds.values()), root=0)
    if comm.Get_rank() != 0:
        return 0
    serial = pulled(shape, model)
    serial.core.run(steps)
    differences = {
        field: float(np.abs(gathered[field] - np.asarray(getattr(serial.core, field))).max())
        for field in FIELDS
    }
    print(f"ranks {comm.Get_size()}, {shape} {model}, {steps} steps: {differences}")
    print(f"bonds broken {broken} against {serial.core.broken_bonds()} serially")
    print(f"own and halo nodes per rank {halos}; exchange shares {[round(s, 3) for s in exchange]}")
    return 0


if __name__ == "__main__":
    code = main()
    wait_asleep(MPI.COMM_WORLD)  # while rank 0 runs serially and compares
    sys.exit(code)
