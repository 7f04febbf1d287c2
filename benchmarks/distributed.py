"""Per-rank speed and communication share of a distributed run (granulate.parallel).

    mpiexec -n K python benchmarks/distributed.py [--case pile|drum|pile3d] [--grains N]
                                                  [--steps S] [--collect-every N]

pile (default 400 grains): compression-like, at rest: discs and hexagons of radius 0.98-1 mm
(R/h = 5) on a hexagonal lattice 2 mm apart, touching their neighbours, under gravity on a
floor between two side walls.
drum (default 300 grains): drum-like, flowing: the same grains on a hexagonal lattice inside a
drum turning at 20 rad/s, each thrown at 2 m/s in a random direction, so that the ranks
migrate grains every few dozen steps.
pile3d (default 1,000 grains): the pile in 3D: spheres and cubes of radius 0.98-1 mm (R/h = 4)
on a cubic lattice 2 mm apart, 10 x 10 columns, on a floor.

Rank 0 prints a table: per rank the grains and nodes it owns at the end, the ghost nodes it
holds besides, its owned node-steps per second, and the shares of its wall-clock time spent in
the ghost exchange, in the partition check (a reduction), in migrations and, with
--collect-every N, in gathering the whole state into rank 0's simulation every N steps (as a run
with outputs or stop criteria every N steps does, DistributedRun.collect; nothing is written);
then the migrations and grains handed over. On fewer cores than ranks (oversubscribed) the shares
include waiting for the other ranks and are an upper bound.
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


def drum(grains: int) -> gr.Simulation:
    """`grains` grains on a hexagonal lattice inside a turning drum, thrown at 2 m/s."""
    rng = np.random.default_rng(5)
    spacing = 2.0 * RADIUS
    size = int(np.ceil(np.sqrt(grains / 0.9 * 2 / np.sqrt(3)))) + 2
    sites = [
        (
            spacing * (column + 0.5 * (row % 2) - size / 2),
            spacing * np.sqrt(3) / 2 * (row - size / 2),
        )
        for row in range(size)
        for column in range(size)
    ]
    sites.sort(key=lambda site: (np.hypot(*site), site))
    sim = gr.Simulation(2, gravity=(0, -9.81, 0))
    sim.contact = gr.Contact(restitution=0.5, friction=0.5)
    for k, centre in enumerate(sites[:grains]):
        radius = RADIUS * rng.uniform(0.98, 1.0)
        shape = (
            gr.RegularPolygon(centre, radius, 6, angle=0.3 * k)
            if k % 3 == 0
            else gr.Disc(centre, radius)
        )
        angle = rng.uniform(0, 2 * np.pi)
        velocity = (2.0 * np.cos(angle), 2.0 * np.sin(angle))
        sim.add_body(shape, ROCK, RADIUS / 5, velocity=velocity)
    reach = max(np.hypot(*site) for site in sites[:grains]) + 2 * RADIUS
    rotation = gr.Rotation.steady(20.0)
    sim.add_wall(gr.Wall(gr.CircleContainer((0, 0), reach), motion=rotation), name="drum")
    return sim


def pile3d(grains: int) -> gr.Simulation:
    """`grains` grains in 10 x 10 columns on a cubic lattice, on a floor."""
    rng = np.random.default_rng(3)
    sim = gr.Simulation(3, gravity=(0, -9.81, 0))
    sim.contact = gr.Contact(restitution=0.5, friction=0.5)
    for k in range(grains):
        layer, rest = divmod(k, 100)
        row, column = divmod(rest, 10)
        centre = (2 * RADIUS * column, 2 * RADIUS * layer, 2 * RADIUS * row)
        radius = RADIUS * rng.uniform(0.98, 1.0)
        if k % 3 == 0:
            half = 0.8 * radius
            shape = gr.Box(tuple(c - half for c in centre), tuple(c + half for c in centre))
        else:
            shape = gr.Sphere(centre, radius)
        sim.add_body(shape, ROCK, RADIUS / 4)
    sim.add_wall(gr.Wall(gr.Plane((0, -0.99 * RADIUS, 0), (0, 1, 0))), name="floor")
    return sim


CASES = {"pile": (pile, 400), "drum": (drum, 300), "pile3d": (pile3d, 1000)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--case", choices=sorted(CASES), default="pile")
    parser.add_argument("--grains", type=int, default=None)
    parser.add_argument("--steps", type=int, default=300)
    parser.add_argument("--collect-every", type=int, default=0, help="steps (0: never)")
    arguments = parser.parse_args()
    make, default_grains = CASES[arguments.case]
    grains = arguments.grains or default_grains
    comm = MPI.COMM_WORLD
    warnings.filterwarnings("ignore", message="contact.*bodies pressed")  # placed pressed
    run = DistributedRun(make(grains), comm)
    run.run(20)  # lists built, caches warm
    every = arguments.collect_every or arguments.steps
    if arguments.collect_every:
        run.collect()  # rank 0 builds the whole simulation once
    run.seconds = dict.fromkeys(run.seconds, 0.0)
    migrations, handed = run.migrations, run.handed_over
    comm.Barrier()  # every rank's clock starts together
    start = time.perf_counter()
    for done in range(0, arguments.steps, every):
        run.run(min(every, arguments.steps - done))
        if arguments.collect_every:
            run.collect()
    wall = time.perf_counter() - start
    owned = len(run.partition.grains_of(comm.Get_rank()))
    row = (owned, run.owned_node_count, run.ghost_node_count, wall, run.seconds)
    rows = comm.gather(row, root=0)
    if comm.Get_rank() != 0:
        return
    print(f"{arguments.case}: {grains} grains, {arguments.steps} steps, {comm.Get_size()} ranks")
    print(
        "| rank | grains | nodes | ghost nodes | node-steps/s | exchange % | check % | migrate % "
        "| collect % |"
    )
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for rank, (owned, nodes, ghosts, seconds, parts) in enumerate(rows):
        speed = nodes * arguments.steps / seconds
        shares = " | ".join(
            f"{100 * parts[name] / seconds:.1f}"
            for name in ("exchange", "check", "migrate", "collect")
        )
        print(f"| {rank} | {owned} | {nodes:,} | {ghosts:,} | {speed / 1e6:.2f} M | {shares} |")
    print(
        f"{run.migrations - migrations} migrations, {run.handed_over - handed} grains handed "
        f"over in the timed steps"
    )


if __name__ == "__main__":
    main()
