"""Cost per node-step against the number of particles (BENCHMARKS.md case `scaling`).

    python benchmarks/scaling.py                  # 100, 400, 1600, 6400 particles
    python benchmarks/scaling.py --counts 100 10000 --json

N discs of 1 mm radius (h = 0.25 mm, 52 nodes each, one shared reference shape) on a square
grid with 0.1 mm gaps in a box, every other row thrown down at 0.3 m/s onto the row below,
under gravity, with contact (restitution 0.5, friction 0.5). After 200 steps that bring them into
contact, 200 steps are timed. A linear method keeps
the cost per node-step flat; the table gives it relative to the smallest case.
"""

from __future__ import annotations

import argparse
import json
import math
import time

import granulate as gr


def case(count: int, threads: int) -> dict[str, object]:
    gr.set_num_threads(threads)
    rock = gr.Material(density=2000, youngs_modulus=1e7, poisson_ratio=0.25, fracture_energy=10.0)
    disc = gr.ReferenceShape.from_shape(gr.Disc((0, 0), 1e-3), 0.25e-3)
    side = math.ceil(math.sqrt(count))
    pitch = 2.1e-3
    sim = gr.Simulation(2, gravity=(0, -9.81))
    sim.contact = gr.Contact(restitution=0.5, friction=0.5)
    for k in range(count):
        row = k // side
        sim.add_particle(
            disc,
            rock,
            position=(pitch * (k % side + 1), pitch * (row + 1)),
            rotation=0.1 * k,
            velocity=(0.0, -0.3 * (row % 2)),  # every other row catches up with the one below
        )
    sim.add_wall(gr.BoxContainer((0, 0), (pitch * (side + 1), pitch * (side + 30))), name="box")
    sim.run(200)
    live = sim.core.phase_times  # a live view: copy the numbers before timing
    before = (live.peridynamics, live.contact, live.integration)
    start = time.perf_counter()
    steps = 200
    sim.run(steps)
    seconds = time.perf_counter() - start
    phases = sim.core.phase_times
    return {
        "case": "scaling",
        "particles": count,
        "nodes": sim.node_count,
        "bonds": sim.bond_count,
        "steps": steps,
        "threads": threads,
        "seconds": seconds,
        "node_steps_per_s": sim.node_count * steps / seconds,
        "ns_per_node_step": 1e9 * seconds / (sim.node_count * steps),
        "contacts": sim.core.contact_statistics.node_contacts,
        "list_rebuilds": sim.core.contact_statistics.rebuilds,
        "phases": {
            "peridynamics": phases.peridynamics - before[0],
            "contact": phases.contact - before[1],
            "integration": phases.integration - before[2],
        },
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--counts", type=int, nargs="+", default=[100, 400, 1600, 6400])
    parser.add_argument("--threads", type=int, default=gr.get_num_threads())
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    first = None
    for count in args.counts:
        result = case(count, args.threads)
        first = first or result["ns_per_node_step"]
        if args.json:
            print(json.dumps(result), flush=True)
        else:
            phases = result["phases"]
            cost = result["ns_per_node_step"]
            print(
                f"{count:>6} particles {result['nodes']:>8} nodes  {cost:7.1f} ns/node-step "
                f"(x{cost / first:.2f})  contact {phases['contact']:.2f} s "
                f"of {result['seconds']:.2f} s  {result['contacts']} contacts  "
                f"{result['list_rebuilds']} rebuilds",
                flush=True,
            )


if __name__ == "__main__":
    main()
