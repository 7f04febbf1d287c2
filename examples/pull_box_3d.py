"""Example 2: a notched glass bar (3D), clamped at one end and pulled at the other until it
breaks at the notch.

    python examples/pull_box_3d.py                 # 31,000 nodes, ~25 s on 2 cores
    python examples/pull_box_3d.py --smoke         # coarse and short (seconds)
    python examples/pull_box_3d.py --out results   # output folder (default out/pull_3d)

Steps: (1) material; (2) a 40 x 10 x 10 mm bar minus a notch across its top face, on a cubic
lattice; (3) clamp x < 2 mm, pull x > 38 mm at 1 m/s (ramped); (4) run with VTU/PVD output
(open out/pull_3d/simulation.pvd in ParaView, colour by Damage); (5) count the pieces.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import granulate as gr

# What the full run must show (checked by tests/test_examples.py --full).
EXPECTED_PIECES = 2


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="coarse mesh, few steps")
    parser.add_argument("--out", default="out/pull_3d", help="output directory")
    parser.add_argument("--overwrite", action="store_true", help="replace an earlier run in --out")
    args = parser.parse_args(argv)

    # (1) Soda-lime glass.
    glass = gr.Material(density=2500, youngs_modulus=70e9, poisson_ratio=0.22, fracture_energy=8.0)
    # (2) Bar with a 3 mm deep notch across the top face at mid-length.
    length, side = 0.04, 0.01
    h = 1e-3 if args.smoke else 0.5e-3
    notch = gr.Box((0.5 * length - 0.5e-3 - h, -1, side - 3e-3), (0.5 * length + 0.5e-3 + h, 1, 1))
    bar = gr.Difference(gr.Box((0, 0, 0), (length, side, side)), notch)
    sim = gr.Simulation(dimension=3)
    sim.add_body(bar, glass, mesh_size=h, name="bar")
    # (3) Clamp one end, pull the other.
    sim.fix(sim.select(gr.Box((-1, -1, -1), (2e-3, 1, 1))))
    sim.prescribe_velocity(
        sim.select(gr.Box((length - 2e-3, -1, -1), (1, 1, 1))), (1.0, 0, 0), ramp_time=3e-6
    )
    # (4) Run.
    end_time = 1e-6 if args.smoke else 55e-6
    steps = int(np.ceil(end_time / sim.dt))
    sim.output(args.out, every=max(1, steps // 15), overwrite=args.overwrite)
    start = time.perf_counter()
    sim.run(until=end_time)
    seconds = time.perf_counter() - start
    # (5) Pieces of at least 1 % of the nodes held together by intact bonds.
    pieces = sim.fragments(min_nodes=sim.node_count // 100)
    summary = {
        "nodes": sim.node_count,
        "bonds": sim.bond_count,
        "steps": sim.step,
        "seconds": seconds,
        "broken_bonds": sim.broken_bonds(),
        "pieces": len(pieces),
    }
    print(
        f"{summary['nodes']} nodes, {summary['bonds']} bonds, {summary['steps']} steps in "
        f"{seconds:.1f} s; {summary['broken_bonds']} bonds broken; "
        f"{len(pieces)} piece(s); output in {args.out}"
    )
    return summary


if __name__ == "__main__":
    main()
