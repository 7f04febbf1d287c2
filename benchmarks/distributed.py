"""Per-rank speed and communication share of a distributed run (granulate.parallel).

    mpiexec -n K python benchmarks/distributed.py [--grains 400] [--steps 300]

A compression-like pile: discs and hexagons of radius 0.98-1 mm (R/h = 5) on a hexagonal
lattice 2 mm apart, touching their neighbours, under gravity on a floor between two
side walls, at rest. Each rank prints, on rank 0's table: the grains and nodes it owns, the
ghost nodes it holds besides, its owned node-steps per second, and the shares of its wall-clock
time spent in the ghost exchange and in the partition check (a reduction). On fewer cores than
ranks (oversubscribed) the shares include waiting for the other ranks and are an upper bound.
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np
from mpi4py import MPI

import granulate as gr
from granulate.parallel import DistributedRun

RADIUS = 1e-3
ROCK = gr.Material(
    density=1200, bulk_modulus=2.16e7, shear_modulus=1.296e7, fracture_energy=50, horizon=0.6e-3
)


def pile(grains: int) -> gr.Simulation:
    """`grains` grains in rows of 20 on a hexagonal lattice, in a box open at the top."""
    rng = np.random.default_rng(3)
    spacing, columns = 2.0 * RADIUS, 20
    sim = gr.Simulation(2, gravity=(0, -9.81, 0))
    sim.contact = gr.Contact(restitution=0.5, friction=0.5)
    for k in range(grains):
        row, column = divmod(k, columns)
        centre = (spacing * (column + 0.5 * (row % 2)), spacing * np.sqrt(3) / 2 * row)
        radius = RADIUS * rng.uniform(0.98, 1.0)
        shape = (
            gr.RegularPolygon(centre, radius, 6, angle=0.3 * k)
            if k % 3 == 0
            else gr.Disc(centre, radius)
        )
        sim.add_body(shape, ROCK, RADIUS / 5)
    width = spacing * (columns + 0.5)
    sim.add_wall(gr.Wall(gr.Plane((0, -0.99 * RADIUS, 0), (0, 1, 0))), name="floor")
    sim.add_wall(gr.Wall(gr.Plane((-0.99 * RADIUS, 0, 0), (1, 0, 0))), name="left")
    sim.add_wall(gr.Wall(gr.Plane((width - RADIUS, 0, 0), (-1, 0, 0))), name="right")
    return sim


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--grains", type=int, default=400)
    parser.add_argument("--steps", type=int, default=300)
    arguments = parser.parse_args()
    comm = MPI.COMM_WORLD
    warnings.filterwarnings("ignore", message="contact.*bodies pressed")  # placed pressed
    run = DistributedRun(pile(arguments.grains), comm)
    run.run(20)  # lists built, caches warm
    run.seconds = dict.fromkeys(run.seconds, 0.0)
    start = time.perf_counter()
    run.run(arguments.steps)
    wall = time.perf_counter() - start
    owned = len(run.partition.grains_of(comm.Get_rank()))
    row = (owned, run.owned_node_count, run.ghost_node_count, wall, run.seconds)
    rows = comm.gather(row, root=0)
    if comm.Get_rank() != 0:
        return
    print(f"{arguments.grains} grains, {arguments.steps} steps, {comm.Get_size()} ranks")
    print("| rank | grains | nodes | ghost nodes | node-steps/s | exchange % | check % |")
    print("|---:|---:|---:|---:|---:|---:|---:|")
    for rank, (grains, nodes, ghosts, seconds, parts) in enumerate(rows):
        speed = nodes * arguments.steps / seconds
        print(
            f"| {rank} | {grains} | {nodes:,} | {ghosts:,} | {speed / 1e6:.2f} M | "
            f"{100 * parts['exchange'] / seconds:.1f} | {100 * parts['check'] / seconds:.1f} |"
        )


if __name__ == "__main__":
    main()
