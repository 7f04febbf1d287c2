"""Example 7: a mixed-shape charge (discs, triangles, hexagons and PeriDEM drums) tumbling in a
rotating mill drum with inner lifters, as in an attrition test.

    python examples/mixed_drum_2d.py              # 0.15 s of rotation, about 1.5 minutes
    python examples/mixed_drum_2d.py --time 3     # about five turns (half an hour)
    python examples/mixed_drum_2d.py --smoke      # seconds

Steps: (1) a brittle material; (2) four grains, sizes uniform in [1.5, 2.5] mm; (3) pack 50 of
them (equal volume fractions) inside the drum; (4) the drum: a circular container and six
lifter bars, one rigid wall turning at 12 rad/s (65 % of the critical speed); (5) gravity,
contact with restitution 0.5 and friction 0.5; (6) run; history.csv has the drum's torque
(drum_tz) and the broken bonds, frames/ the damage for ParaView.
"""

from __future__ import annotations

import argparse

import numpy as np

import granulate as gr

DRUM_RADIUS = 30e-3  # [m]


def lifters(count: int, height: float, width: float) -> list[gr.walls.Surface]:
    """Rectangular bars on the inside of the drum, evenly spaced."""
    bars = []
    for k in range(count):
        a = 2 * np.pi * k / count
        radial, tangent = np.array([np.cos(a), np.sin(a)]), np.array([-np.sin(a), np.cos(a)])
        inner, outer = DRUM_RADIUS - height, DRUM_RADIUS + 1e-3
        corners = [
            inner * radial - 0.5 * width * tangent,
            outer * radial - 0.5 * width * tangent,
            outer * radial + 0.5 * width * tangent,
            inner * radial + 0.5 * width * tangent,
        ]
        bars.append(gr.walls.obstacle(gr.Polygon(tuple(map(tuple, corners)))))
    return bars


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="20 coarse grains, short run")
    parser.add_argument("--out", default="out/mixed_drum", help="output directory")
    parser.add_argument("--overwrite", action="store_true", help="replace an earlier run in --out")
    parser.add_argument("--time", type=float, default=0.15, help="simulated time [s]")
    args = parser.parse_args(argv)

    # (1) Material (SI units).
    ore = gr.Material(density=2700, youngs_modulus=2e8, poisson_ratio=0.25, fracture_energy=5.0)
    # (2) Grains at reference radius 2 mm.
    h = 0.6e-3 if args.smoke else 0.35e-3
    sizes = gr.Uniform(1.5e-3, 2.5e-3)
    shapes = [
        gr.Disc((0, 0), 2e-3),
        gr.RegularPolygon((0, 0), 2e-3, 3),
        gr.RegularPolygon((0, 0), 2e-3, 6),
        gr.Drum2D((0, 0), 2e-3, 0.8e-3),
    ]
    grains = [gr.Grain(shape, ore, h, sizes) for shape in shapes]

    # (3) Packing inside the lifters' tips; the grains fall to the bottom at the start.
    charge = gr.Disc((0, 0), DRUM_RADIUS - 6e-3)
    count = 20 if args.smoke else 50
    packing = gr.pack(charge, grains, count, by="volume", seed=2, gap=0.2e-3)
    print(packing.summary())

    sim = gr.Simulation(dimension=2, gravity=(0, -9.81))
    sim.contact = gr.Contact(restitution=0.5, friction=0.5)
    sim.add_packing(packing)

    # (4) The drum: container and lifters turning together.
    drum = gr.Wall(
        (gr.walls.container(gr.Disc((0, 0), DRUM_RADIUS)), *lifters(6, 5e-3, 3e-3)),
        motion=gr.Rotation.steady(12.0, center=(0, 0)),
    )
    sim.add_wall(drum, name="drum")
    end = 5e-3 if args.smoke else args.time
    print(f"{sim.node_count} nodes, {sim.bond_count} bonds, dt {sim.dt:.3g} s")

    # (6) Run.
    sim.output(args.out, every=max(1, int(end / sim.dt) // 40), overwrite=args.overwrite)
    sim.run(until=end)
    summary = sim.summary()
    fragments = len(sim.fragments(min_nodes=3))
    print(
        f"{summary['steps']} steps in {summary['wall_seconds']:.1f} s; drum torque "
        f"{sim.wall_reactions()['drum'][5]:.4g} N m/m; broken bonds {sim.broken_bonds()}, "
        f"{fragments} pieces of 3 or more nodes from {len(packing)} grains; output in {args.out}"
    )
    return {
        "nodes": summary["nodes"],
        "steps": summary["steps"],
        "particles": len(packing),
        "broken_bonds": sim.broken_bonds(),
        "pieces": fragments,
    }


if __name__ == "__main__":
    main()
