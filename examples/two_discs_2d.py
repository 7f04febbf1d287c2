"""Example 3: two discs of different sizes and materials collide head-on, once without damping
(restitution 1) and once with restitution 0.5; prints the measured coefficients.

    python examples/two_discs_2d.py            # R/h = 10, ~10 s
    python examples/two_discs_2d.py --smoke    # coarse (seconds)
    python examples/two_discs_2d.py --out DIR  # output folders DIR/e1.0 and DIR/e0.5

Steps: (1) two materials; (2) a soft 1 mm disc and a stiffer 0.6 mm disc approaching at
0.2 m/s; (3) contact with the requested restitution; (4) run until they separate; (5) measure
e = -(relative normal speed after) / (before).
"""

from __future__ import annotations

import argparse

import numpy as np

import granulate as gr


def collide(restitution: float, h: float, out: str, overwrite: bool) -> tuple[float, int, int]:
    polymer = gr.Material(density=1200, bulk_modulus=2.16e7, shear_modulus=1.296e7, fracture=False)
    ceramic = gr.Material(density=3000, bulk_modulus=5e8, shear_modulus=3e8, fracture=False)
    sim = gr.Simulation(dimension=2)
    sim.contact = gr.Contact(restitution=restitution)
    big = sim.add_body(gr.Disc((0, 0), 1e-3), polymer, h, velocity=(0.1, 0), name="big")
    small = sim.add_body(
        gr.Disc((1.6e-3 + 2 * h, 0), 0.6e-3), ceramic, h, velocity=(-0.1, 0), name="small"
    )
    sim.output(out, every=200, overwrite=overwrite)

    def relative_velocity() -> float:
        v = [
            np.average(sim.velocities[b.nodes, 0], weights=sim.volumes[b.nodes])
            for b in (big, small)
        ]
        return v[0] - v[1]

    before = relative_velocity()
    touched = False
    while True:
        sim.run(50)
        touching = sim.core.contact_statistics.node_contacts > 0
        touched = touched or touching
        if touched and not touching:
            break
    sim.run(200)
    return -relative_velocity() / before, sim.node_count, sim.step


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="coarse mesh")
    parser.add_argument("--out", default="out/two_discs", help="output directory")
    parser.add_argument("--overwrite", action="store_true", help="replace earlier runs in --out")
    args = parser.parse_args(argv)
    h = 0.25e-3 if args.smoke else 0.1e-3
    summary: dict[str, float] = {}
    for requested in (1.0, 0.5):
        measured, nodes, steps = collide(requested, h, f"{args.out}/e{requested}", args.overwrite)
        summary.update({f"e_{requested}": measured, "nodes": nodes, "steps": steps})
        print(
            f"requested restitution {requested}: measured {measured:.3f} "
            f"({nodes} nodes, {steps} steps)"
        )
    return summary


if __name__ == "__main__":
    main()
