"""Ranks balanced by their grains' work (granulate/parallel/work_load.py) against ranks balanced
by nodes alone: the same run with the balance checks on and off, alternating.

    mpiexec -n K python benchmarks/work_balance.py [--case bonds|contact] [--steps S]
                                                   [--rounds R]

Cases (granulate.bench_ranks' pile layout, 2D, at rest on a floor between two walls):
- bonds: 200 grains at 16 nodes a radius; the left half's horizon is 4.5 mesh sizes, the
  right half's 3 (2.25 times fewer bonds a node);
- contact: 400 grains at 5 nodes a radius; the left half touching on its lattice, the right
  half's grains 1.5 times as far apart (no contact among them).
Each round runs the case once with the balance off (gr.LoadBalance(threshold=inf): the ranks cut
by nodes at the start and never again) and once on, the order alternating, one thread a rank.
Rank 0 prints per run the wall seconds of the steps, each rank's step seconds (its own work,
without the exchange and checks), each rank's work (DistributedRun.owned_work) at the end with its
nodes, intact bond copies and contact list entries, and the steps the ranks rebalanced before
(0: the start's check, before the timed steps).
"""

from __future__ import annotations

import argparse
import time
import warnings
from collections.abc import Callable

import numpy as np
from mpi4py import MPI

import granulate as gr
from granulate import bench_ranks
from granulate.parallel import DistributedRun

RADIUS = bench_ranks.RADIUS


def bonds_case() -> gr.Simulation:
    """The pile of 200 grains at h = R/16, its left half of horizon 4.5 h, its right 3 h."""
    h = RADIUS / 16
    rock = bench_ranks.ROCK
    wide, narrow = (rock.model_copy(update={"horizon": k * h}) for k in (4.5, 3.0))
    return _pile(200, lambda column: (wide if column < 10 else narrow, 1.0), h)


def contact_case() -> gr.Simulation:
    """The pile of 400 grains at h = R/5, its right half spread 1.5 times as far apart."""
    return _pile(400, lambda column: (bench_ranks.ROCK, 1.0 if column < 10 else 1.5), RADIUS / 5)


def _pile(grains: int, half: Callable[[int], tuple[gr.Material, float]], h: float) -> gr.Simulation:
    """Grains of radius 0.99 R in rows of 20 on a hexagonal lattice 2 R apart, on a floor,
    meshed at `h`; half(column) gives a column's material and how much farther apart its
    grains are (the right half's, from x = 21 R on)."""
    sim = gr.Simulation(2, gravity=(0, -9.81, 0))
    sim.contact = gr.Contact(restitution=0.5, friction=0.5)
    spacing = 2.0 * RADIUS
    for k in range(grains):
        row, column = divmod(k, 20)
        material, spread = half(column)
        shift = 0.0 if column < 10 else 10.5 - 10 * spread  # the right half from x = 21 R on
        x = spacing * (shift + spread * (column + 0.5 * (row % 2)))
        y = spacing * np.sqrt(3) / 2 * row * spread
        sim.add_body(gr.Disc((x, y), 0.99 * RADIUS), material, h)
    sim.add_wall(gr.Wall(gr.Plane((0, -0.99 * RADIUS, 0), (0, 1, 0))), name="floor")
    return sim


CASES = {"bonds": bonds_case, "contact": contact_case}


def one_run(case: str, steps: int, balance: bool, comm: MPI.Comm) -> dict | None:
    """The case run `steps` steps after 20 untimed, with the balance checks on or off."""
    sim = CASES[case]()
    sim.load_balance = gr.LoadBalance(threshold=1.1 if balance else float("inf"))
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="contact.*bodies pressed")
        run = DistributedRun(sim, comm)
        run.run(20)
    run.seconds = dict.fromkeys(run.seconds, 0.0)
    comm.Barrier()
    start = time.perf_counter()
    run.run(steps)
    comm.Barrier()
    wall = time.perf_counter() - start
    core, own = run.local.core, run.owned_nodes
    counts = (
        len(own),
        int(np.asarray(core.intact_bond_copies(own)).sum()),
        int(np.asarray(core.contact_list_entries(own)).sum()),
    )
    work = run.owned_work()
    rows = comm.gather((run.seconds["steps"], work, counts), root=0)
    if rows is None:
        return None
    return {"wall": wall, "rows": rows, "rebalances": run.rebalance_steps, "balance": balance}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--case", choices=list(CASES), default="bonds")
    parser.add_argument("--steps", type=int, default=300)
    parser.add_argument("--rounds", type=int, default=2)
    arguments = parser.parse_args()
    comm = MPI.COMM_WORLD
    gr.set_num_threads(1, adaptive=False)
    for k in range(arguments.rounds):
        for balance in (k % 2 == 0, k % 2 == 1):
            result = one_run(arguments.case, arguments.steps, balance, comm)
            if result is None:
                continue
            steps = ", ".join(f"{row[0]:.2f}" for row in result["rows"])
            work = ", ".join(f"{row[1]:,.0f} {row[2]}" for row in result["rows"])
            print(
                f"round {k + 1} balance {'on ' if balance else 'off'}: {arguments.steps} steps in "
                f"{result['wall']:.2f} s; ranks' step seconds {steps}; work {work}; "
                f"rebalanced before steps {result['rebalances']}",
                flush=True,
            )


if __name__ == "__main__":
    main()
