"""Example 4: a concave particle (PeriDEM's drum2d: a hexagon pinched to a neck) and a disc fall
onto a floor and bounce, as in PeriDEM's two-particle-with-wall case.

    python examples/disc_and_concave_particle_on_floor_2d.py           # ~20 s
    python examples/disc_and_concave_particle_on_floor_2d.py --smoke   # seconds

Steps: (1) material; (2) a Drum2D and a disc above a floor, the disc thrown
sideways; (3) gravity, contact with restitution 0.7 and friction 0.3; (4) run 60 ms with
output (history.csv has the floor's force); (5) report the highest rebound of each particle.
"""

from __future__ import annotations

import argparse

import granulate as gr


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="coarse mesh, short run")
    parser.add_argument("--out", default="out/drum_and_disc", help="output directory")
    parser.add_argument("--overwrite", action="store_true", help="replace an earlier run in --out")
    args = parser.parse_args(argv)

    rubber = gr.Material(density=1200, youngs_modulus=5e6, poisson_ratio=0.3, fracture=False)
    h = 0.25e-3 if args.smoke else 0.1e-3
    sim = gr.Simulation(dimension=2, gravity=(0, -9.81))
    sim.contact = gr.Contact(restitution=0.7, friction=0.3)
    concave = sim.add_body(gr.Drum2D((0.0, 3e-3), 2e-3, 0.8e-3), rubber, h, name="drum")
    disc = sim.add_body(gr.Disc((4e-3, 6e-3), 1e-3), rubber, h, velocity=(-0.1, 0), name="disc")
    sim.add_wall(gr.Plane((0, 0), (0, 1)), name="floor")
    end = 5e-3 if args.smoke else 60e-3
    sim.output(args.out, every=max(1, int(end / sim.dt) // 30), overwrite=args.overwrite)
    heights = {b.name: [] for b in (concave, disc)}
    while sim.time < end:
        sim.run(200)
        for b in (concave, disc):
            heights[b.name].append(float(sim.positions[b.nodes, 1].min()))
    summary = {
        "nodes": sim.node_count,
        "steps": sim.step,
        **{
            f"max_rebound_{name}": max(values[len(values) // 3 :])
            for name, values in heights.items()
        },
    }
    print(
        f"{sim.node_count} nodes, {sim.step} steps; highest rebound after landing: "
        f"drum {1e3 * summary['max_rebound_drum']:.2f} mm, "
        f"disc {1e3 * summary['max_rebound_disc']:.2f} mm; "
        f"output in {args.out}"
    )
    return summary


if __name__ == "__main__":
    main()
