"""Example 1: a notched glass plate (2D, plane stress), clamped on the left and pulled on the
right until a crack runs from the notch across the plate.

    python examples/pull_rectangle_2d.py                 # 44,700 nodes, ~15 s on 2 cores
    python examples/pull_rectangle_2d.py --smoke         # coarse and short (seconds)
    python examples/pull_rectangle_2d.py --out results   # output folder (default out/pull_2d)

Steps: (1) material from E, nu, Gc; (2) a 100 mm dog-bone plate (20 mm gauge, 40 mm grips,
smooth shoulders) minus a 4 mm notch, on a lattice; (3) clamp the left grip, pull the right one
with a velocity ramped up over 40 us; (4) run with VTU/PVD output (open
out/pull_2d/simulation.pvd in ParaView, colour by Damage); (5) count the pieces. The crack
starts at the notch and splits the plate in two; nothing else cracks (the run reports the
damaged nodes near the grips: none). A plain rectangle pulled with a 10 us ramp, as this
example once was, also cracked at the corners of the grips: the sudden pull sends a stress
wave that breaks the plate where the rigid grips concentrate stress before the notch crack
has run.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import granulate as gr

# What the full run must show (checked by tests/test_examples.py --full).
EXPECTED_PIECES = 2


def dog_bone(
    length: float, height: float, grip: float, shoulder: float
) -> list[tuple[float, float]]:
    """Outline of a plate whose grips (``grip`` long, twice ``height`` tall) join the gauge
    section (``height`` tall, between y = 0 and height) through shoulders ``shoulder`` long
    shaped as half a cosine wave (no kink at either end), counter-clockwise from the lower left."""
    t = np.linspace(0.0, 1.0, 33)
    rise = 0.25 * height * (1 + np.cos(np.pi * t))  # from height / 2 down to 0
    bottom = [(0.0, -0.5 * height)]
    bottom += [(grip + shoulder * u, -r) for u, r in zip(t, rise, strict=True)]
    bottom += [(length - grip - shoulder * u, -r) for u, r in zip(t[::-1], rise[::-1], strict=True)]
    bottom += [(length, -0.5 * height)]
    top = [(x, height - y) for x, y in reversed(bottom)]
    return bottom + top


def damaged_near_ends(sim: gr.Simulation, reach: float) -> int:
    """Nodes with damage above 0.3 within `reach` of either end of the plate (the grips and
    their shoulders)."""
    x = sim.reference_positions[:, 0]
    near = (x < x.min() + reach) | (x > x.max() - reach)
    return int(np.count_nonzero(sim.damage[near] > 0.3))


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="coarse mesh, few steps")
    parser.add_argument("--out", default="out/pull_2d", help="output directory")
    parser.add_argument("--overwrite", action="store_true", help="replace an earlier run in --out")
    parser.add_argument("--end-time", type=float, default=80e-6, help="simulated time [s]")
    args = parser.parse_args(argv)

    # (1) Soda-lime glass: E = 70 GPa, nu = 0.22, Gc = 8 J/m^2.
    glass = gr.Material(density=2500, youngs_modulus=70e9, poisson_ratio=0.22, fracture_energy=8.0)
    # (2) Geometry: a dog-bone plate, with grips twice as tall as the 20 mm gauge section and
    # smooth (cosine) shoulders between them, and a notch in the middle of the gauge's top edge.
    # The grips carry half the gauge's stress and the shoulders concentrate little, so the
    # crack starts at the notch only (a plain rectangle also cracked at the grips' corners).
    length, height = 0.1, 0.02
    grip, shoulder = 0.01, 0.02  # lengths of each grip and each shoulder [m]
    h = 1e-3 if args.smoke else 0.25e-3
    notch = gr.Rectangle(
        (0.5 * length - 0.5e-3 - h, height - 4e-3), (0.5 * length + 0.5e-3 + h, height + h)
    )
    plate = gr.Difference(gr.Polygon(dog_bone(length, height, grip, shoulder)), notch)
    sim = gr.Simulation(dimension=2, plane="stress")
    sim.add_body(plate, glass, mesh_size=h, name="plate")
    # (3) Loading: left 3 mm clamped, right 3 mm pulled at 1 m/s (ramped up over 40 us).
    sim.fix(sim.select(gr.Rectangle((-1, -1), (3e-3, 1))))
    sim.prescribe_velocity(
        sim.select(gr.Rectangle((length - 3e-3, -1), (1, 1))), (1.0, 0.0), ramp_time=40e-6
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
        "damaged_at_grips": damaged_near_ends(sim, grip + shoulder),
    }
    print(
        f"{summary['nodes']} nodes, {summary['steps']} steps in {seconds:.1f} s; "
        f"{summary['broken_bonds']} bonds broken; "
        f"{len(pieces)} piece(s), {summary['damaged_at_grips']} damaged nodes near the grips; "
        f"output in {args.out}"
    )
    return summary


if __name__ == "__main__":
    main()
