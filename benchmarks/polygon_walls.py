"""Grains settling on a polygon wall of many edges: the angle of repose's rough floor (saw teeth
0.3 grain radii high at a pitch of one radius, docs/validation/angle_of_repose.py): the
smoke test's column of discs collapsing onto it, timed per step once it has spread over the
floor (after `--settle` steps, 0.05 s), with the share the contact phase takes.

    python benchmarks/polygon_walls.py [--teeth 120] [--settle 20000] [--steps 4000]
        [--rounds 3]

Prints, per round, the steps per second and the contact phase's share of the step (the node
and wall contact searches and forces). One thread.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "docs" / "validation"))
import angle_of_repose

import granulate as gr


def settling_column(teeth: int) -> gr.Simulation:
    """The smoke test's column (6 mm wide, 12 grains) over a floor of `teeth` teeth."""
    width = 6e-3
    grain = gr.Grain(
        gr.Disc((0, 0), angle_of_repose.RADIUS),
        angle_of_repose.GRAIN,
        mesh_size=angle_of_repose.RADIUS / angle_of_repose.NODES_ACROSS_RADIUS,
        sizes=gr.Uniform(0.8 * angle_of_repose.RADIUS, 1.2 * angle_of_repose.RADIUS),
        discretization="conforming",
    )
    column = gr.Rectangle((0, 0), (width, 3 * width))
    packing = gr.pack(column, [grain], 12, method="lattice", seed=1)
    sim = gr.Simulation(2, gravity=(0, -angle_of_repose.GRAVITY), viscous_damping=5.0)
    sim.contact = gr.Contact(restitution=0.3, friction=0.5)
    sim.add_packing(packing)
    sim.add_wall(angle_of_repose.rough_floor(teeth * angle_of_repose.RADIUS), name="floor")
    sim.add_wall(gr.Plane((0, 0), (1, 0)), name="wall")
    return sim


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--teeth", type=int, default=120)
    parser.add_argument("--settle", type=int, default=20000)
    parser.add_argument("--steps", type=int, default=4000)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    gr.set_num_threads(1)
    for _ in range(args.rounds):
        sim = settling_column(args.teeth)
        sim.run(args.settle)  # the column spread over the floor
        before = sim.core.phase_times.contact
        start = time.perf_counter()
        sim.run(args.steps)
        seconds = time.perf_counter() - start
        contact = sim.core.phase_times.contact - before
        print(
            f"{args.teeth} teeth ({2 * args.teeth + 3} vertices), {sim.node_count} nodes: "
            f"{args.steps / seconds:,.0f} steps/s, contact {100 * contact / seconds:.0f} % of it"
        )


if __name__ == "__main__":
    main()
