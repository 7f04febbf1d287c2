"""What each rank of a distributed run holds (issue 17): its memory after the set-up every rank
makes (the whole Assembly: every grain's nodes), and after its part is built and stepped.

    mpiexec -n K python benchmarks/rank_memory.py [--grains G] [--steps S]

The case is `granulate bench --ranks`' pile3d (G grains in 10 x 10 columns on a floor, each
meshed where it stands at a quarter of its radius, one thread per rank), or with --placed the
same columns of grains placed from two reference shapes (a sphere and a cube, scaled), as
packings place them. Rank 0 prints per rank: its resident
memory [MB] (VmRSS) after the set-up and after `steps` steps of DistributedRun (the peak,
VmHWM, beside it), its part's core memory (Simulation.core.memory_bytes: bonds and the rest),
and the node arrays the whole set-up holds on every rank (the Assembly's positions and volumes
of the grains meshed where they stand, 32 bytes a node; placed grains hold none). Run it with
1 rank too: the serial run holds the same set-up.
"""

from __future__ import annotations

import argparse
import warnings

from mpi4py import MPI
from process_memory import status_mb

from granulate import bench_ranks
from granulate.parallel import DistributedRun
from granulate.threads import set_num_threads


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--grains", type=int, default=1000)
    parser.add_argument("--steps", type=int, default=5)
    parser.add_argument("--placed", action="store_true", help="grains placed from two shapes")
    arguments = parser.parse_args()
    set_num_threads(1, adaptive=False)
    comm = MPI.COMM_WORLD
    sim = bench_ranks.pile3d(arguments.grains, placed=arguments.placed)
    assembly = sim._assembly
    whole = sum(nodes.nbytes for nodes in assembly.stored_arrays())
    set_up, _ = status_mb("VmRSS", "VmHWM")
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="contact.*bodies pressed")
        run = DistributedRun(sim, comm)
        run.run(arguments.steps)
    stepped, peak = status_mb("VmRSS", "VmHWM")
    bonds, rest = run.local.core.memory_bytes()
    row = (run.owned_node_count, set_up, stepped, peak, bonds / 2**20, rest / 2**20, whole / 2**20)
    rows = comm.gather(row, root=0)
    if rows is None:
        return
    print(
        f"pile3d{' (placed)' if arguments.placed else ''}: {arguments.grains} grains, "
        f"{sim.node_count:,} nodes, {comm.Get_size()} ranks, "
        f"{arguments.steps} steps\n"
        "| rank | own nodes | set up MB | stepped MB | peak MB | part: bonds MB | part: rest MB "
        "| set-up's stored node arrays MB |\n|---:|---:|---:|---:|---:|---:|---:|---:|"
    )
    for rank, (own, up, now, high, b, r, w) in enumerate(rows):
        print(
            f"| {rank} | {own:,} | {up:.0f} | {now:.0f} | {high:.0f} | {b:.1f} | {r:.1f} "
            f"| {w:.1f} |"
        )


if __name__ == "__main__":
    main()
