"""Example 6: the PeriDEM paper's compression test, set up from scratch: 366 discs and 136
hexagons (radius uniform in [0.9, 1.1] mm, random orientations) packed in a 68 mm x 41 mm
container whose top wall moves down at 0.06 m/s (Jha et al., JMPS 2021, section 5).

    python examples/compression_2d.py                  # 5,000 steps (0.5 ms), about a minute
    python examples/compression_2d.py --steps 600000   # the paper's whole run (60 ms)
    python examples/compression_2d.py --smoke          # a 60-particle version, seconds

Steps: (1) the material (LPS, linear influence, horizon 0.6 mm); (2) two grains, discs with
conforming (ring) nodes and hexagons on a lattice, both of mesh size 0.2 mm at radius 1 mm;
(3) pack them on lattice sites in the container (no initial contact); (4) walls: a fixed floor
and sides, a top plate pushed down by a velocity; (5) gravity, contact with restitution 0.95 and
no friction, dt = 1e-7 s; (6) run with output; history.csv has the top wall's force
(top_fy) against its displacement (top_displacement).

PeriDEM meshes these grains with gmsh (123 and 91 nodes, about 63,000 nodes in all); the
ring and lattice discretizations at h = 0.2 mm give about 40,000.
"""

from __future__ import annotations

import argparse

import granulate as gr

WIDTH, HEIGHT = 68e-3, 41e-3  # inner size of the container [m]


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="60 particles, 200 steps")
    parser.add_argument("--steps", type=int, default=5000, help="time steps (dt = 1e-7 s)")
    parser.add_argument("--out", default="out/compression", help="output directory")
    parser.add_argument("--overwrite", action="store_true", help="replace an earlier run in --out")
    parser.add_argument("--seed", type=int, default=1, help="seed of the packing")
    args = parser.parse_args(argv)

    # (1) Material: K, G [Pa], Gc [J/m^2], rho [kg/m^3]; horizon 0.6 mm for every grain.
    material = gr.Material(
        density=1200,
        bulk_modulus=2.16e7,
        shear_modulus=1.296e7,
        fracture_energy=50,
        horizon=0.6e-3,
    )
    # (2) Grains: reference radius 1 mm, mesh size 0.2 mm there (it scales with the grain).
    sizes = gr.Uniform(0.9e-3, 1.1e-3)
    disc = gr.Grain(
        gr.Disc((0, 0), 1e-3), material, 0.2e-3, sizes, 366, discretization="conforming"
    )
    hexagon = gr.Grain(gr.RegularPolygon((0, 0), 1e-3, 6), material, 0.2e-3, sizes, 136)

    # (3) Packing: smoke runs fill a quarter-height box with 60 grains.
    height = HEIGHT / 4 if args.smoke else HEIGHT
    count = 60 if args.smoke else 502
    container = gr.Rectangle((0, 0), (WIDTH / (2 if args.smoke else 1), height))
    packing = gr.pack(container, [disc, hexagon], count, method="lattice", seed=args.seed)
    print(packing.summary())

    sim = gr.Simulation(dimension=2, gravity=(0, -10), dt=1e-7)
    sim.contact = gr.Contact(restitution=0.95, friction=0.0)
    sim.add_packing(packing)

    # (4) Walls: floor and sides fixed; the top plate moves down at 0.06 m/s.
    right = container.upper[0]
    sim.add_wall(
        gr.Wall(
            (
                gr.Plane((0, 0), (0, 1)),
                gr.Plane((0, 0), (1, 0)),
                gr.Plane((right, 0), (-1, 0)),
            )
        ),
        name="container",
    )
    sim.add_wall(
        gr.Wall(
            (gr.Plane((0, height), (0, -1)),),
            motion=gr.Translation((0, -1), gr.Linear(0.06)),
        ),
        name="top",
    )
    print(
        f"{sim.node_count} nodes, {sim.bond_count} bonds, dt {sim.dt:.3g} s "
        f"(stable estimate {sim.stable_dt:.3g} s)"
    )

    # (6) Run.
    steps = 200 if args.smoke else args.steps
    sim.output(args.out, every=max(1, steps // 20), overwrite=args.overwrite)
    sim.run(steps)
    summary = sim.summary()
    rate = summary["nodes"] * summary["steps"] / max(summary["wall_seconds"], 1e-9)
    top = sim.wall_reactions()["top"]
    print(
        f"{summary['steps']} steps in {summary['wall_seconds']:.1f} s "
        f"({rate / 1e6:.2f} M node-steps/s); top wall force {top[1]:.4g} N/m, "
        f"broken bonds {sim.broken_bonds()}, packing fraction {packing.packing_fraction:.3f}; "
        f"output in {args.out}"
    )
    return {
        "nodes": summary["nodes"],
        "steps": summary["steps"],
        "particles": len(packing),
        "packing_fraction": packing.packing_fraction,
        "node_steps_per_s": rate,
    }


if __name__ == "__main__":
    main()
