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

import numpy as np
from mpi4py import MPI

import granulate as gr
from granulate import bench_ranks
from granulate.parallel import DistributedRun
from granulate.threads import set_num_threads


def resident_mb() -> tuple[float, float]:
    """(VmRSS, VmHWM) of this process [MB], from /proc/self/status."""
    fields = {}
    with open("/proc/self/status") as status:
        for line in status:
            name, _, value = line.partition(":")
            fields[name] = value
    return tuple(float(fields[name].split()[0]) / 1024 for name in ("VmRSS", "VmHWM"))


def placed_pile3d(grains: int) -> gr.Simulation:
    """pile3d's columns with each grain placed from one of two reference shapes: a sphere of
    radius R and a cube of half-side 0.8 R, meshed at R/4 (bench_ranks' R), scaled to the
    grain's radius."""
    radius = bench_ranks.RADIUS
    rng = np.random.default_rng(3)
    sim = gr.Simulation(3, gravity=(0, -9.81, 0))
    sim.contact = gr.Contact(restitution=0.5, friction=0.5)
    half = 0.8 * radius
    shapes = (
        gr.ReferenceShape.from_shape(gr.Box((-half,) * 3, (half,) * 3), radius / 4),
        gr.ReferenceShape.from_shape(gr.Sphere((0, 0, 0), radius), radius / 4),
    )
    for k in range(grains):
        layer, rest = divmod(k, 100)
        row, column = divmod(rest, 10)
        centre = (2 * radius * column, 2 * radius * layer, 2 * radius * row)
        scale = rng.uniform(0.98, 1.0)
        shape = shapes[0] if k % 3 == 0 else shapes[1]
        sim.add_particle(shape, bench_ranks.ROCK, position=centre, scale=scale)
    sim.add_wall(gr.Wall(gr.Plane((0, -0.99 * radius, 0), (0, 1, 0))), name="floor")
    return sim


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--grains", type=int, default=1000)
    parser.add_argument("--steps", type=int, default=5)
    parser.add_argument("--placed", action="store_true", help="grains placed from two shapes")
    arguments = parser.parse_args()
    set_num_threads(1, adaptive=False)
    comm = MPI.COMM_WORLD
    make = placed_pile3d if arguments.placed else bench_ranks.pile3d
    sim = make(arguments.grains)
    assembly = sim._assembly
    whole = sum(nodes.nbytes for nodes in assembly.stored_arrays())
    set_up, _ = resident_mb()
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="contact.*bodies pressed")
        run = DistributedRun(sim, comm)
        run.run(arguments.steps)
    stepped, peak = resident_mb()
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
