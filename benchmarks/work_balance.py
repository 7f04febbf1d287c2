"""Ranks balanced by their grains' work (granulate/parallel/work_load.py), by that work scaled by
measured time, and by nodes alone: the same run under each balance, in turn.

    mpiexec -n K python benchmarks/work_balance.py [--case bonds|contact|breaking] [--steps S]
                                                   [--rounds R] [--compare off,work,time]

Cases (granulate.bench_ranks' pile layout, 2D, on a floor):
- bonds: 200 grains at 16 nodes a radius; the left half's horizon is 4.5 mesh sizes, the
  right half's 3 (2.25 times fewer bonds a node);
- contact: 400 grains at 5 nodes a radius; the left half touching on its lattice, the right
  half's grains 1.5 times as far apart (no contact among them);
- breaking: 400 grains at 5 nodes a radius; the left half brittle and thrown at 8 m/s into
  each other (they shatter), the right half at rest.
Each round runs the case once under each balance of --compare (default off,work), in an order
turning from round to round, one thread a rank: off, gr.LoadBalance(threshold=inf), the ranks
cut by nodes at the start and never again; work, the default gr.LoadBalance(); time,
gr.LoadBalance(weight="time").
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


def breaking_case() -> gr.Simulation:
    """The pile of 400 grains at h = R/5, its left half brittle (fracture energy 0.5 J/m^2)
    and each grain thrown at 8 m/s in a random direction into its neighbours, as bench_ranks'
    shatter case: they crack and split from the first steps, at a cost their counts miss;
    the right half at rest."""
    brittle = bench_ranks.ROCK.model_copy(update={"fracture_energy": 0.5})
    throws = np.random.default_rng(7).uniform(0.0, 2 * np.pi, 400)

    def half(column: int) -> tuple[gr.Material, float]:
        return (brittle, 1.0) if column < 10 else (bench_ranks.ROCK, 1.0)

    def velocity(k: int, column: int) -> tuple[float, float]:
        speed = 8.0 if column < 10 else 0.0
        return speed * np.cos(throws[k]), speed * np.sin(throws[k])

    return _pile(400, half, RADIUS / 5, velocity)


def _pile(
    grains: int,
    half: Callable[[int], tuple[gr.Material, float]],
    h: float,
    velocity: Callable[[int, int], tuple[float, float]] = lambda k, column: (0.0, 0.0),
) -> gr.Simulation:
    """Grains of radius 0.99 R in rows of 20 on a hexagonal lattice 2 R apart, on a floor,
    meshed at `h`; half(column) gives a column's material and how much farther apart its
    grains are (the right half's, from x = 21 R on), velocity(k, column) grain k's."""
    sim = gr.Simulation(2, gravity=(0, -9.81, 0))
    sim.contact = gr.Contact(restitution=0.5, friction=0.5)
    spacing = 2.0 * RADIUS
    for k in range(grains):
        row, column = divmod(k, 20)
        material, spread = half(column)
        shift = 0.0 if column < 10 else 10.5 - 10 * spread  # the right half from x = 21 R on
        x = spacing * (shift + spread * (column + 0.5 * (row % 2)))
        y = spacing * np.sqrt(3) / 2 * row * spread
        disc = gr.Disc((x, y), 0.99 * RADIUS)
        sim.add_body(disc, material, h, velocity=velocity(k, column))
    sim.add_wall(gr.Wall(gr.Plane((0, -0.99 * RADIUS, 0), (0, 1, 0))), name="floor")
    return sim


CASES = {"bonds": bonds_case, "contact": contact_case, "breaking": breaking_case}


#: The balances compared: none (the cut by nodes of the start kept), by the counts, by time.
BALANCES = {
    "off": gr.LoadBalance(threshold=float("inf")),
    "work": gr.LoadBalance(),
    "time": gr.LoadBalance(weight="time"),
}


def one_run(case: str, steps: int, balance: str, comm: MPI.Comm) -> dict | None:
    """The case run `steps` steps after 20 untimed, under BALANCES[balance]."""
    sim = CASES[case]()
    sim.load_balance = BALANCES[balance]
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
    parser.add_argument(
        "--compare", default="off,work", help="balances run in turn: off, work, time"
    )
    arguments = parser.parse_args()
    compared = arguments.compare.split(",")
    if not set(compared) <= set(BALANCES):
        parser.error(f"--compare takes {', '.join(BALANCES)}, got {arguments.compare}")
    comm = MPI.COMM_WORLD
    gr.set_num_threads(1, adaptive=False)
    for k in range(arguments.rounds):
        for balance in compared[k % len(compared) :] + compared[: k % len(compared)]:
            result = one_run(arguments.case, arguments.steps, balance, comm)
            if result is None:
                continue
            steps = ", ".join(f"{row[0]:.2f}" for row in result["rows"])
            work = ", ".join(f"{row[1]:,.0f} {row[2]}" for row in result["rows"])
            print(
                f"round {k + 1} balance {balance:4}: {arguments.steps} steps in "
                f"{result['wall']:.2f} s; ranks' step seconds {steps}; work {work}; "
                f"rebalanced before steps {result['rebalances']}",
                flush=True,
            )


if __name__ == "__main__":
    main()
