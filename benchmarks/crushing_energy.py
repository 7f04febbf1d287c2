"""Energy of shattering grains under each contact law: the ``crushing`` bench set-up run longer.

Six brittle discs (R = 1 mm, h = 0.05 mm) hit a floor and break; every ``--every`` steps this
prints the kinetic and strain energy [J/m], the fastest node [m/s], broken bonds and pieces. A
contact law that pushes crack faces or fragments apart would show the energy rising or nodes
flying faster than the impact; the figures in docs/parameters.md ("Contact law") come from

    python benchmarks/crushing_energy.py --law surface --speed 10
    python benchmarks/crushing_energy.py --law granulate --speed 10
"""

from __future__ import annotations

import argparse

import numpy as np

import granulate as gr


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--law", choices=("surface", "granulate"), default="surface")
    parser.add_argument("--speed", type=float, default=10.0, help="impact speed [m/s]")
    parser.add_argument("--steps", type=int, default=12000)
    parser.add_argument("--every", type=int, default=1000)
    args = parser.parse_args()
    material = gr.Material(
        density=2000, youngs_modulus=1e9, poisson_ratio=0.25, fracture_energy=2.0, horizon_factor=3
    )
    sim = gr.Simulation(2, gravity=(0, -9.81))
    sim.contact = gr.Contact(restitution=0.5, pair_law=args.law)
    for k in range(6):
        sim.add_body(
            gr.Disc((k * 2.2e-3, 1.2e-3), 1e-3), material, 0.5e-4, velocity=(0, -args.speed)
        )
    sim.add_wall(gr.Plane((0, 0), (0, 1)), name="floor")
    start = sim.kinetic_energy()
    print(f"{args.law}, {args.speed} m/s: kinetic energy at the start {start:.4e} J/m")
    for done in range(args.every, args.steps + 1, args.every):
        sim.run(steps=args.every, progress=False)
        kinetic, strain = sim.kinetic_energy(), sim.strain_energy()
        fastest = float(np.linalg.norm(sim.velocities, axis=1).max())
        print(
            f"step {done}: kinetic {kinetic:.4e} strain {strain:.4e} sum {kinetic + strain:.4e} "
            f"J/m, fastest node {fastest:.2f} m/s, broken bonds {sim.broken_bonds()}, "
            f"pieces {len(sim.fragments(min_nodes=1))}",
            flush=True,
        )


if __name__ == "__main__":
    main()
