"""Example 1: a notched glass plate (2D, plane stress), clamped on the left and pulled on the
right until a crack runs from the notch across the plate.

    python examples/pull_rectangle_2d.py                 # 32,000 nodes, ~15 s on 2 cores
    python examples/pull_rectangle_2d.py --smoke         # coarse and short (seconds)
    python examples/pull_rectangle_2d.py --out results   # output folder (default out/pull_2d)

Steps: (1) material from E, nu, Gc; (2) a 100 mm x 20 mm plate minus a 4 mm notch, on a
lattice; (3) clamp the left edge, pull the right edge with a smoothly ramped velocity; (4) run
with VTU/PVD output (open out/pull_2d/simulation.pvd in ParaView, colour by Damage);
(5) count the pieces. The crack starts at the notch, branches as it speeds up and splits the
plate in two; shorter cracks start at the corners of the rigid grips, where stress concentrates.
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
    parser.add_argument("--out", default="out/pull_2d", help="output directory")
    parser.add_argument("--overwrite", action="store_true", help="replace an earlier run in --out")
    parser.add_argument("--end-time", type=float, default=80e-6, help="simulated time [s]")
    args = parser.parse_args(argv)

    # (1) Soda-lime glass: E = 70 GPa, nu = 0.22, Gc = 8 J/m^2.
    glass = gr.Material(density=2500, youngs_modulus=70e9, poisson_ratio=0.22, fracture_energy=8.0)
    # (2) Geometry: plate with a notch in the middle of its top edge.
    length, height = 0.1, 0.02
    h = 1e-3 if args.smoke else 0.25e-3
    notch = gr.Rectangle(
        (0.5 * length - 0.5e-3 - h, height - 4e-3), (0.5 * length + 0.5e-3 + h, height + h)
    )
    plate = gr.Difference(gr.Rectangle((0, 0), (length, height)), notch)
    sim = gr.Simulation(dimension=2, plane="stress")
    sim.add_body(plate, glass, mesh_size=h, name="plate")
    # (3) Loading: left 3 mm clamped, right 3 mm pulled at 1 m/s (ramped over 10 us).
    sim.fix(sim.select(gr.Rectangle((-1, -1), (3e-3, 1))))
    sim.prescribe_velocity(
        sim.select(gr.Rectangle((length - 3e-3, -1), (1, 1))), (1.0, 0.0), ramp_time=10e-6
    )
    # (4) Run.
    end_time = 2e-6 if args.smoke else args.end_time
    steps = int(np.ceil(end_time / sim.dt))
    sim.output(args.out, every=max(1, steps // 20), overwrite=args.overwrite)
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
        f"{summary['nodes']} nodes, {summary['steps']} steps in {seconds:.1f} s; "
        f"{summary['broken_bonds']} bonds broken; "
        f"{len(pieces)} piece(s); output in {args.out}"
    )
    return summary


if __name__ == "__main__":
    main()
