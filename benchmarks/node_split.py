"""Per-rank speed and communication share of a body split at node level
(granulate.parallel.node_split): a notched LPS block of glass (60 x 30 x 30 nodes, 54,000;
horizon 3 mesh sizes) stretched along its length, its nodes dealt to the ranks by recursive
coordinate bisection.

    mpiexec -n K python benchmarks/node_split.py [--steps S] [--threads T] [--json]

Prints, per rank: its own and halo nodes, own node-steps/s over the timed steps, and the share
of those steps spent in the two exchanges (the halo's positions, then its dilatation sums;
waits for the other ranks included). The first step is not timed. One thread per rank unless
--threads. On 2 cores, K > 2 oversubscribes: correctness, not speed.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np
from mpi4py import MPI

import granulate as gr
from granulate.parallel.node_split import NodeSplitRun
from granulate.threads import set_num_threads

RATE = 60.0  # the strain rate [1/s]


def block() -> gr.Simulation:
    """The notched block, each node starting at v_x = RATE (x - c), its ends held at that speed."""
    glass = gr.Material(density=2500, youngs_modulus=70e9, poisson_ratio=0.22, fracture_energy=8.0)
    sim = gr.Simulation(dimension=3)
    notch = gr.Box((14.7e-3, 10e-3, -1), (15.3e-3, 1, 1))
    sim.add_body(
        gr.Difference(gr.Box((0, 0, 0), (0.03, 0.015, 0.015)), notch), glass, mesh_size=0.5e-3
    )
    sim.contact = None
    start = np.asarray(sim.reference_positions)
    centre = 0.5 * (start[:, 0].min() + start[:, 0].max())
    velocities = np.zeros_like(start)
    velocities[:, 0] = RATE * (start[:, 0] - centre)
    sim.start_from(start, velocities)
    for end in (gr.Box((-1, -1, -1), (1e-3, 1, 1)), gr.Box((29e-3, -1, -1), (1, 1, 1))):
        nodes = sim.select(end)
        sim.prescribe_velocity(nodes, (RATE * (start[nodes, 0].mean() - centre), 0.0, 0.0))
    return sim


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--steps", type=int, default=100)
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--json", action="store_true")
    arguments = parser.parse_args()
    set_num_threads(arguments.threads, adaptive=False)
    comm = MPI.COMM_WORLD
    run = NodeSplitRun(block(), comm)
    run.run(1)
    run.seconds = {"steps": 0.0, "exchange": 0.0}
    comm.Barrier()
    start = time.perf_counter()
    run.run(arguments.steps)
    seconds = time.perf_counter() - start
    row = {
        "rank": comm.Get_rank(),
        "own_nodes": len(run.own),
        "halo_nodes": run.halo_nodes,
        "node_steps_per_s": len(run.own) * arguments.steps / seconds,
        "exchange_share": run.seconds["exchange"] / seconds,
    }
    rows = comm.gather(row, root=0)
    broken = run.broken_bonds()
    if comm.Get_rank() != 0:
        return
    for r in rows:
        if arguments.json:
            print(json.dumps({**r, "ranks": comm.Get_size(), "bonds_broken": broken}))
        else:
            print(
                f"rank {r['rank']}: {r['own_nodes']} own and {r['halo_nodes']} halo nodes, "
                f"{r['node_steps_per_s'] / 1e6:.2f} M node-steps/s, "
                f"exchange {100 * r['exchange_share']:.1f} % of the steps"
            )
    print(
        f"{comm.Get_size()} ranks, {arguments.steps} steps, {broken} bonds broken; "
        f"{np.mean([r['node_steps_per_s'] for r in rows]) / 1e6:.2f} M node-steps/s per rank"
    )


if __name__ == "__main__":
    main()
