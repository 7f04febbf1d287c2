"""Example 5: a brittle sphere hits a wall at 25 m/s and cracks (3D).

    python examples/sphere_hits_wall_3d.py           # 19,000 nodes, ~15 s
    python examples/sphere_hits_wall_3d.py --smoke   # coarse and short (seconds)

Steps: (1) a brittle material (E = 20 GPa, Gc = 12 J/m^2); (2) a 5 mm sphere just above a
floor, moving down at 25 m/s; (3) contact with restitution 0.8; (4) run 40 us with output
(colour by Damage in ParaView: a crushed cone forms under the contact, with cracks running
from it); (5) report broken bonds and pieces.
"""

from __future__ import annotations

import argparse
import time

import granulate as gr

# What the full run must show (checked by tests/test_examples.py --full).
EXPECTED_PIECES = 1


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="coarse mesh, few steps")
    parser.add_argument("--out", default="out/sphere_wall", help="output directory")
    parser.add_argument("--overwrite", action="store_true", help="replace an earlier run in --out")
    args = parser.parse_args(argv)

    stone = gr.Material(density=2500, youngs_modulus=20e9, poisson_ratio=0.2, fracture_energy=12.0)
    radius = 5e-3
    h = 1e-3 if args.smoke else 0.3e-3
    sim = gr.Simulation(dimension=3)
    sim.contact = gr.Contact(restitution=0.8)
    sim.add_body(
        gr.Sphere((0, radius + h, 0), radius), stone, h, velocity=(0, -25.0, 0), name="sphere"
    )
    sim.add_wall(gr.Plane((0, 0, 0), (0, 1, 0)), name="floor")
    end = 0.5e-6 if args.smoke else 40e-6
    sim.output(args.out, every=max(1, int(end / sim.dt) // 12), overwrite=args.overwrite)
    start = time.perf_counter()
    sim.run(until=end)
    seconds = time.perf_counter() - start
    pieces = sim.fragments(min_nodes=50)
    summary = {
        "nodes": sim.node_count,
        "steps": sim.step,
        "seconds": seconds,
        "broken_bonds": sim.broken_bonds(),
        "pieces": len(pieces),
        "peak_floor_force": float(-sim.wall_reactions()["floor"][1]),
    }
    print(
        f"{sim.node_count} nodes, {sim.step} steps in {seconds:.1f} s; "
        f"{summary['broken_bonds']} bonds broken; "
        f"{len(pieces)} piece(s) of 50+ nodes; output in {args.out}"
    )
    return summary


if __name__ == "__main__":
    main()
