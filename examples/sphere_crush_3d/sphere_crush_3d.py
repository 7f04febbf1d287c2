"""A brittle sphere crushed between two plates: the load-displacement curve and the fragments.

    python examples/sphere_crush_3d/sphere_crush_3d.py            # R/h = 12: about a minute
    python examples/sphere_crush_3d/sphere_crush_3d.py --nodes-per-radius 6   # coarser: 4 s
    python examples/sphere_crush_3d/sphere_crush_3d.py --smoke    # R/h = 3, seconds

Steps: (1) a brittle stone (LPS, E = 10 GPa, fracture energy 10 J/m^2); (2) a 1 mm sphere with
conforming (shell) nodes resting on a fixed floor; (3) a top plate placed half a mesh size
above it and moved down at 1 m/s (1/2000 of the stone's wave speed, whose waves cross the
sphere in a microsecond) for 0.2 mm; (4) contact with restitution 0.5, friction 0.5 and a
contact spring 100 times the default, so that the stone's own elasticity and not the contact
layer takes the load (docs/parameters.md); (5) run, writing history.csv (the plate's force
top_fy [N] and travel top_displacement [m], broken bonds, fragments), frames/ (Damage,
Fragment_ID) and crush.png: the plate's force against its travel, with the broken bonds.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

import granulate as gr
from granulate.plots import two_scales

RADIUS = 1e-3  # [m]
SPEED = 1.0  # the top plate's [m/s]


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="a coarse sphere, short travel")
    parser.add_argument("--out", default="out/sphere_crush", help="output directory")
    parser.add_argument("--overwrite", action="store_true", help="replace an earlier run in --out")
    parser.add_argument("--travel", type=float, default=0.2e-3, help="plate travel [m]")
    parser.add_argument(
        "--nodes-per-radius", type=float, default=12, help="R/h of the sphere (smoke: 3)"
    )
    args = parser.parse_args(argv)

    # (1) Material (SI units).
    stone = gr.Material(density=2500, youngs_modulus=10e9, poisson_ratio=0.25, fracture_energy=10.0)
    # (2) The sphere on the floor.
    h = RADIUS / (3 if args.smoke else args.nodes_per_radius)
    sim = gr.Simulation(3)
    sim.contact = gr.Contact(restitution=0.5, friction=0.5, stiffness_factor=100)
    sim.add_body(gr.Sphere((0, RADIUS, 0), RADIUS), stone, h, discretization="conforming")
    sim.add_wall(gr.Plane((0, 0, 0), (0, 1, 0)), name="floor")
    # (3) The top plate, half a mesh size above the sphere's surface (its contact layer).
    top = 2 * RADIUS + 0.5 * h
    plate = gr.Wall(
        (gr.Plane((0, top, 0), (0, -1, 0)),), motion=gr.Translation((0, -1, 0), gr.Linear(SPEED))
    )
    sim.add_wall(plate, name="top")
    travel = 0.3e-3 if args.smoke else args.travel
    steps = math.ceil(travel / SPEED / sim.dt)
    print(f"{sim.node_count} nodes, {sim.bond_count} bonds, dt {sim.dt:.3g} s, {steps} steps")

    # (5) Run.
    sim.output(args.out, every=max(1, steps // 60), overwrite=args.overwrite)
    sim.run(steps)
    summary, history = sim.summary(), gr.Results(args.out).history
    force, travelled = history["top_fy"], history["top_displacement"]
    peak = int(np.argmax(force))
    pieces = sim.fragments(min_nodes=10)
    figure = plot_crush(history, Path(args.out) / "crush.png")
    print(
        f"{summary['steps']} steps in {summary['wall_seconds']:.1f} s; peak force "
        f"{force[peak]:.4g} N at {1e6 * travelled[peak]:.1f} um; broken bonds "
        f"{sim.broken_bonds()}; {len(pieces)} piece(s) of 10+ nodes; {figure}"
    )
    return {
        "nodes": sim.node_count,
        "steps": summary["steps"],
        "peak_force": float(force[peak]),
        "peak_travel": float(travelled[peak]),
        "broken_bonds": sim.broken_bonds(),
        "pieces": len(pieces),
    }


def plot_crush(history: dict[str, np.ndarray], path: Path) -> Path:
    """The top plate's force against its travel, and the broken bonds, from history.csv."""
    labels = ("plate travel [um]", "plate force [N]", "broken bonds")
    travel = 1e6 * history["top_displacement"]
    return two_scales(path, travel, history["top_fy"], history["broken_bonds"], labels)


if __name__ == "__main__":
    main()
