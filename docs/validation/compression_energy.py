"""The energy balance of the compression example: its settled pile compressed again, with a
history row every few steps, so that the top wall's work W = int F dy is exact to the sampling;
printed against the change of the total energy E (kinetic + strain + gravity + contact springs,
history.csv's total_energy) and the kinetic energy K, and the change of E - W at every row where
bonds broke. With restitution 1 nothing but broken bonds dissipates, so E - E_0 = W until the
first bond breaks, and a break may only release energy.

Run: python examples/compression_2d/compression_2d.py --out out/compression (settles the pile,
17 minutes here), then python docs/validation/compression_energy.py out/compression
[--restitution 1] [--friction 0] [--travel 3.4e-3] [--model pmb --fracture-energy 2] (under a
minute).
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

import granulate as gr

sys.path.insert(0, str(Path(__file__).parents[2] / "examples" / "compression_2d"))
import compression_2d  # the example's packing, settling and compression stages

GRAINS = 120


def settled_pile(folder: Path, options: compression_2d.Options, model: str | None, gc: float):
    """The example's grains, placed where the last frame of `folder`/settle has them."""
    if model is not None:  # the example's material with another bond model and Gc
        example_material = compression_2d.material
        compression_2d.material = lambda options: gr.Material(
            **{
                **example_material(options).model_dump(exclude_unset=True),
                "model": model,
                "fracture_energy": gc,
            }
        )
    width = compression_2d.WIDTH * min(1.0, math.sqrt(GRAINS / 502))
    grains = compression_2d.packing(GRAINS, width, seed=1, options=options)
    settled = compression_2d.simulation(grains, width, options)
    bodies = settled.bodies[:]
    settled.positions[:] = gr.Results(folder / "settle").frame(-1).positions
    return grains, width, settled, bodies


def balance(history: dict) -> tuple[np.ndarray, np.ndarray]:
    """W (trapezoids of the wall's force over its travel) and E - E_0 per history row [J/m]."""
    travel = np.abs(np.asarray(history["top_displacement"]))
    force = np.asarray(history["top_fy"])
    work = np.concatenate([[0.0], np.cumsum(np.diff(travel) * 0.5 * (force[1:] + force[:-1]))])
    energy = np.asarray(history["total_energy"])
    return work, energy - energy[0]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", type=Path, help="the example's --out folder")
    parser.add_argument("--restitution", type=float, default=1.0)
    parser.add_argument("--friction", type=float, default=0.0, help="while compressed")
    parser.add_argument("--speed", type=float, default=0.6, help="[m/s]")
    parser.add_argument("--travel", type=float, default=3.4e-3, help="[m]")
    parser.add_argument("--model", choices=("lps", "pmb"), default=None)
    parser.add_argument("--fracture-energy", type=float, default=50.0, help="with --model [J/m^2]")
    parser.add_argument("--out", type=Path, default=Path("out/compression_energy"))
    args = parser.parse_args()
    options = compression_2d.Options(
        restitution=args.restitution, history_every=5, friction=args.friction
    )
    grains, width, settled, bodies = settled_pile(
        args.folder, options, args.model, args.fracture_energy
    )
    compression_2d.compress(
        grains, width, settled, bodies, args.speed, args.travel, args.out, True, options
    )
    history = gr.Results(args.out).history
    work, gained = balance(history)
    travel = 1e3 * np.abs(np.asarray(history["top_displacement"]))
    kinetic, broken = np.asarray(history["kinetic_energy"]), np.asarray(history["broken_bonds"])
    for k in np.linspace(0, len(work) - 1, 11).astype(int)[1:]:
        print(
            f"travel {travel[k]:.2f} mm: W {work[k]:.4e} J/m, E - E0 {gained[k]:.4e}, "
            f"(E - E0) / W {gained[k] / work[k]:.4f}, K / W {kinetic[k] / work[k]:.3f}, "
            f"{int(broken[k])} bonds broken"
        )
    jumps = np.diff(gained - work)[np.diff(broken) > 0]
    print(
        f"change of E - W at the {len(jumps)} rows with new breaks: sum {jumps.sum():+.4e} J/m, "
        f"largest rise {jumps.max() if len(jumps) else 0.0:+.4e}"
    )


if __name__ == "__main__":
    main()
