"""Time to generate packings and to turn them into particles.

    python benchmarks/packing.py                 # 10,000 grains, 2D and 3D, both methods
    python benchmarks/packing.py --count 2000 --json

2D: discs and hexagons, radius uniform in [0.9, 1.1] mm, in a square sized for 45 % of the
area in bounding discs. 3D: spheres in a cube sized for 30 % of the volume in bounding spheres.
Prints the seconds for pack() and for Simulation.add_packing() (which places a shared reference
shape per grain) and the packing fraction reached.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

import granulate as gr


def run(dimension: int, method: str, count: int) -> dict[str, object]:
    rock = gr.Material(density=2000, youngs_modulus=1e7, poisson_ratio=0.25, fracture_energy=10.0)
    sizes = gr.Uniform(0.9e-3, 1.1e-3)
    if dimension == 2:
        grains = [
            gr.Grain(gr.Disc((0, 0), 1e-3), rock, 0.25e-3, sizes, 3),
            gr.Grain(gr.RegularPolygon((0, 0), 1e-3, 6), rock, 0.25e-3, sizes, 1),
        ]
        side = np.sqrt(count * np.pi * 1e-6 / 0.45)
        container: gr.Shape = gr.Rectangle((0, 0), (side, side))
    else:
        grains = [gr.Grain(gr.Sphere((0, 0, 0), 1e-3), rock, 0.4e-3, sizes)]
        side = (count * 4 / 3 * np.pi * 1e-9 / 0.30) ** (1 / 3)
        container = gr.Box((0, 0, 0), (side, side, side))
    start = time.perf_counter()
    packing = gr.pack(container, grains, count, method=method, seed=1)
    packed = time.perf_counter() - start
    sim = gr.Simulation(dimension)
    start = time.perf_counter()
    sim.add_packing(packing)
    placed = time.perf_counter() - start
    return {
        "case": f"pack{dimension}d_{method}",
        "particles": count,
        "pack_seconds": round(packed, 3),
        "add_seconds": round(placed, 3),
        "packing_fraction": round(packing.packing_fraction, 4),
        "nodes": sim.node_count,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=10_000)
    parser.add_argument("--json", action="store_true", help="one JSON object per line")
    args = parser.parse_args()
    if not args.json:
        print(
            f"{'case':<20} {'particles':>9} {'pack s':>8} {'add s':>8} {'fraction':>9} {'nodes':>9}"
        )
    for dimension in (2, 3):
        for method in ("random", "lattice"):
            row = run(dimension, method, args.count)
            if args.json:
                print(json.dumps(row))
            else:
                print(
                    f"{row['case']:<20} {row['particles']:>9} {row['pack_seconds']:>8} "
                    f"{row['add_seconds']:>8} {row['packing_fraction']:>9} {row['nodes']:>9}"
                )


if __name__ == "__main__":
    main()
