"""A small 3D compression: spheres packed in a box, pressed by a top plate.

    python examples/compression_3d/compression_3d.py           # 24 spheres, R/h = 4
    python examples/compression_3d/compression_3d.py --smoke   # 8 spheres, R/h = 2.5

Steps: (1) the PeriDEM paper's grain material (K = 21.6 MPa, G = 13 MPa, 50 J/m^2, 1200
kg/m^3; horizon 3 h); (2) spheres of radius 0.9-1.1 mm with conforming (shell) nodes; (3)
pack them on the face-centred cubic sites of a box (no two touch); (4) the box: floor and four
side walls, fixed, and a top plate 0.05 mm above the highest sphere's surface, moved down
at 0.5 m/s (its area is the box's, so history.csv has its stress top_stress [Pa]); (5) no
gravity (the grains start apart on their lattice sites; examples/compression_2d settles a
pile first), contact with restitution 0.5, friction 0.3 and a contact spring 100 times the
default (at 10 times, nodes overlapped by half their contact radius as the grains broke);
(6) run, writing history.csv, frames/ (Damage, Fragment_ID; contacts.pvd for force chains)
and compression.png: the plate's stress and the mean coordination number against its travel.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

import granulate as gr
from granulate.plots import two_scales

SPEED = 0.5  # the top plate's [m/s]
GAP = 0.05e-3  # between the plate and the highest sphere's surface at the start [m]


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="8 coarse spheres, short travel")
    parser.add_argument("--out", default="out/compression_3d", help="output directory")
    parser.add_argument("--overwrite", action="store_true", help="replace an earlier run in --out")
    parser.add_argument("--travel", type=float, default=3.5e-3, help="plate travel [m]")
    args = parser.parse_args(argv)

    # (1), (2) Material and grain.
    paper = gr.Material(
        density=1200, bulk_modulus=2.16e7, shear_modulus=1.296e7, fracture_energy=50
    )
    h = 1e-3 / (2.5 if args.smoke else 4)
    sphere = gr.Grain(
        gr.Sphere((0, 0, 0), 1e-3),
        paper,
        h,
        gr.Uniform(0.9e-3, 1.1e-3),
        discretization="conforming",
    )
    # (3) Pack on FCC sites.
    count, side, height = (8, 6.6e-3, 4.6e-3) if args.smoke else (24, 8.8e-3, 6.6e-3)
    box = gr.Box((0, 0, 0), (side, height, side))
    packing = gr.pack(box, [sphere], count, method="lattice", seed=1)
    print(packing.summary())

    sim = gr.Simulation(dimension=3)
    sim.contact = gr.Contact(restitution=0.5, friction=0.3, stiffness_factor=100)
    sim.add_packing(packing)
    # (4) The box and the plate.
    walls = (
        gr.Plane((0, 0, 0), (0, 1, 0)),
        gr.Plane((0, 0, 0), (1, 0, 0)),
        gr.Plane((side, 0, 0), (-1, 0, 0)),
        gr.Plane((0, 0, 0), (0, 0, 1)),
        gr.Plane((0, 0, side), (0, 0, -1)),
    )
    sim.add_wall(gr.Wall(walls), name="box")
    top = float(np.max(packing.positions[:, 1] + packing.radii)) + GAP  # above the surfaces
    plate = gr.Wall(
        (gr.Plane((0, top, 0), (0, -1, 0)),),
        motion=gr.Translation((0, -1, 0), gr.Linear(SPEED)),
        area=side * side,
    )
    sim.add_wall(plate, name="top")
    travel = 0.3e-3 if args.smoke else args.travel
    steps = math.ceil(travel / SPEED / sim.dt)
    print(f"{sim.node_count} nodes, {sim.bond_count} bonds, dt {sim.dt:.3g} s, {steps} steps")

    # (6) Run.
    sim.output(args.out, every=max(1, steps // 50), overwrite=args.overwrite)
    sim.run(steps)
    summary, history = sim.summary(), gr.Results(args.out).history
    figure = plot_compression(history, Path(args.out) / "compression.png")
    stress = history["top_stress"]
    print(
        f"{summary['steps']} steps in {summary['wall_seconds']:.1f} s; stress "
        f"{1e-3 * stress[-1]:.3g} kPa after {1e3 * history['top_displacement'][-1]:.2f} mm, "
        f"coordination {history['coordination'][-1]:.2f}, broken bonds {sim.broken_bonds()}; "
        f"{figure}"
    )
    return {
        "nodes": sim.node_count,
        "steps": summary["steps"],
        "final_stress": float(stress[-1]),
        "peak_stress": float(np.max(stress)),
        "coordination": float(history["coordination"][-1]),
        "broken_bonds": sim.broken_bonds(),
    }


def plot_compression(history: dict[str, np.ndarray], path: Path) -> Path:
    """The top plate's stress and the mean coordination against its travel, from history.csv."""
    labels = ("plate travel [mm]", "plate stress [kPa]", "mean coordination")
    travel = 1e3 * history["top_displacement"]
    stress = 1e-3 * history["top_stress"]
    return two_scales(path, travel, stress, history["coordination"], labels)


if __name__ == "__main__":
    main()
