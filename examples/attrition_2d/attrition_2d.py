"""Attrition in a mill: a mixed charge (discs, triangles, hexagons and PeriDEM drums, small and
large, the large ones tougher) tumbling in a rotating drum with inner lifters.

    python examples/attrition_2d/attrition_2d.py                     # 0.15 s, about 2 minutes
    python examples/attrition_2d/attrition_2d.py --axis-offset 8e-3  # the drum turns off its centre
    python examples/attrition_2d/attrition_2d.py --time 3            # about five turns
    python examples/attrition_2d/attrition_2d.py --smoke             # seconds

Steps: (1) two brittle materials, the large grains' twice as tough; (2) four shapes in two size
ranges (1.2-1.6 mm and 2.0-2.5 mm); (3) pack 50 of them (equal volume fractions) inside the
drum; (4) the drum: a circular container and six lifter bars, one rigid wall turning at 12
rad/s (65 % of the critical speed) about its centre or about an axis --axis-offset [m] from it;
(5) gravity, contact with restitution 0.5 and friction 0.5; (6) run, writing history.csv (the
drum's torque drum_tz, broken bonds, fragments, mean damage), frames/ for ParaView (Damage and
Fragment fields) and attrition.png: mean damage and fragment count against time.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import granulate as gr
from granulate.plots import two_scales

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
    parser.add_argument("--out", default="out/attrition", help="output directory")
    parser.add_argument("--overwrite", action="store_true", help="replace an earlier run in --out")
    parser.add_argument("--time", type=float, default=0.4, help="simulated time [s]")
    parser.add_argument(
        "--axis-offset",
        type=float,
        default=0.0,
        help="distance of the drum's axis from its centre [m]",
    )
    parser.add_argument(
        "--pair-law",
        choices=("surface", "granulate"),
        default="surface",
        help="contact law: surface (the default) or granulate (the node spheres, which made "
        "attrition_six_turns.png)",
    )
    args = parser.parse_args(argv)

    # (1) Materials (SI units): the large grains need twice the energy to crack.
    ore = gr.Material(density=2700, youngs_modulus=2e8, poisson_ratio=0.25, fracture_energy=0.3)
    tough_ore = gr.Material(
        density=2700, youngs_modulus=2e8, poisson_ratio=0.25, fracture_energy=0.6
    )
    # (2) Four shapes at reference radius 2 mm, in two size ranges (mesh sizes scale with them).
    h = 0.6e-3 if args.smoke else 0.35e-3
    shapes = [
        gr.Disc((0, 0), 2e-3),
        gr.RegularPolygon((0, 0), 2e-3, 3),
        gr.RegularPolygon((0, 0), 2e-3, 6),
        gr.Drum2D((0, 0), 2e-3, 0.8e-3),
    ]
    small, large = gr.Uniform(1.2e-3, 1.6e-3), gr.Uniform(2.0e-3, 2.5e-3)
    grains = [gr.Grain(shape, ore, h, small) for shape in shapes]
    grains += [gr.Grain(shape, tough_ore, h, large) for shape in shapes]

    # (3) Packing inside the lifters' tips; the grains fall to the bottom at the start.
    charge = gr.Disc((0, 0), DRUM_RADIUS - 6e-3)
    count = 20 if args.smoke else 50
    packing = gr.pack(charge, grains, count, by="volume", seed=2, gap=0.2e-3)
    print(packing.summary())

    sim = gr.Simulation(dimension=2, gravity=(0, -9.81))
    sim.contact = gr.Contact(restitution=0.5, friction=0.5, pair_law=args.pair_law)
    sim.add_packing(packing)

    # (4) The drum: container and lifters turning together.
    drum = gr.Wall(
        (gr.walls.container(gr.Disc((0, 0), DRUM_RADIUS)), *lifters(6, 5e-3, 3e-3)),
        motion=gr.Rotation.steady(12.0, center=(args.axis_offset, 0)),
    )
    sim.add_wall(drum, name="drum")
    end = 5e-3 if args.smoke else args.time
    print(f"{sim.node_count} nodes, {sim.bond_count} bonds, dt {sim.dt:.3g} s")

    # (6) Run.
    sim.output(args.out, every=max(1, int(end / sim.dt) // 40), overwrite=args.overwrite)
    sim.run(until=end)
    summary = sim.summary()
    fragments = len(sim.fragments(min_nodes=3))
    history = gr.Results(args.out).history
    figure = plot_attrition(history, Path(args.out) / "attrition.png")
    print(
        f"{summary['steps']} steps in {summary['wall_seconds']:.1f} s; drum torque "
        f"{sim.wall_reactions()['drum'][5]:.4g} N m/m; broken bonds {sim.broken_bonds()}, "
        f"{fragments} pieces of 3 or more nodes from {len(packing)} grains, mean damage "
        f"{history['mean_damage'][-1]:.4f}; {figure}"
    )
    return {
        "nodes": summary["nodes"],
        "steps": summary["steps"],
        "particles": len(packing),
        "broken_bonds": sim.broken_bonds(),
        "pieces": fragments,
        "mean_damage": float(history["mean_damage"][-1]),
    }


def plot_attrition(history: dict[str, np.ndarray], path: Path) -> Path:
    """Mean damage (volume-weighted) and the number of pieces against time, from history.csv."""
    labels = ("time [ms]", "mean damage", "pieces (a whole grain is one)")
    time = 1e3 * history["time"]
    return two_scales(
        path, time, history["mean_damage"], history["fragments"], labels, right_steps=True
    )


if __name__ == "__main__":
    main()
