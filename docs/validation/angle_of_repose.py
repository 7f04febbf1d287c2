"""A column of discs collapses against a wall into a half-heap whose slope rises with the friction
coefficient mu: the angle of repose of a 2D assembly (issue 13: "a pile's angle of repose rises
with mu").

Set-up: polydisperse conforming discs (radius 0.8-1.2 mm, R/h = 3 at 1 mm), packed on a
hexagonal lattice into a column W wide and 3 W high against a vertical wall, on a rough floor
(saw teeth: on a flat floor round grains roll away); gravity 100 m/s^2 (the collapse is 3.2
times faster than under 9.81, and the grains' strain under the column's weight stays below
1e-3; at 400 m/s^2 the contact layer is too soft for the impacts and the heap comes out
different), background damping 5 /s (its time constant, 0.2 s, is long against the collapse).
Released at rest, the column slumps and stops. The angle is the slope of the free surface: a
straight line fitted through the tops of the grains that form its upper envelope (the highest
grain in each slice one mean diameter wide), from the wall to the toe, the thin tail of grains
that ran out included.

There is no closed-form reference: the claim checked is the trend (frictionless discs run out
furthest, friction keeps a steeper heap, rolling resistance a steeper one still), and the
angles are reported. A collapsed column settles flatter than a heap poured slowly (the grains
flow and stop together), so these angles are lower than the angles of repose of poured piles
of the same grains.

Run: python docs/validation/angle_of_repose.py; prints the table (two packings per case) and
writes docs/validation/angle_of_repose.png (11 minutes on one thread of a shared 2-core
machine). --smoke: the small column, table only.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass

import numpy as np
from oblique_impact import save

import granulate as gr

GRAIN = gr.Material(density=2000, youngs_modulus=1e7, poisson_ratio=0.25, fracture=False)
RADIUS = 1e-3  # the reference disc; the grains are scaled from it
NODES_ACROSS_RADIUS = 3
GRAVITY = 100.0


@dataclass(frozen=True)
class Heap:
    """The settled deposit: the angle of its free surface [degrees], its height at the wall and
    its runout along the floor [m], and the grains' tops forming its upper envelope [m]."""

    angle: float
    height: float
    runout: float
    envelope: np.ndarray  # (k, 2): x and y of the envelope's grain tops


def collapse(
    friction: float,
    *,
    width: float = 8e-3,
    rolling_friction: float = 0.0,
    until: float = 0.12,
    seed: int = 1,
) -> tuple[Heap, gr.Simulation]:
    """Collapses a column `width` wide and 3 `width` high (see the module docstring) and
    returns the heap it leaves after `until` seconds."""
    grain = gr.Grain(
        gr.Disc((0, 0), RADIUS),
        GRAIN,
        mesh_size=RADIUS / NODES_ACROSS_RADIUS,
        sizes=gr.Uniform(0.8 * RADIUS, 1.2 * RADIUS),
        discretization="conforming",
    )
    column = gr.Rectangle((0, 0), (width, 3 * width))
    packing = gr.pack(column, [grain], _column_count(width), method="lattice", seed=seed)
    sim = gr.Simulation(2, gravity=(0, -GRAVITY), viscous_damping=5.0)
    sim.contact = gr.Contact(restitution=0.3, friction=friction, rolling_friction=rolling_friction)
    sim.add_packing(packing)
    sim.add_wall(rough_floor(10 * width), name="floor")
    sim.add_wall(gr.Plane((0, 0), (1, 0)), name="wall")
    sim.run(until=until)
    return measure(sim), sim


def rough_floor(length: float) -> gr.PolygonObstacle:
    """A floor of saw teeth 0.3 RADIUS high at a pitch of RADIUS, their tips at y = 0: round
    grains stop on it as they do on a floor of glued grains (on a flat floor they roll away)."""
    pitch, depth = RADIUS, 0.3 * RADIUS
    teeth = int(np.ceil(length / pitch))
    top = [(k * pitch / 2, 0.0 if k % 2 == 0 else -depth) for k in range(2 * teeth + 1)]
    return gr.PolygonObstacle([*top, (teeth * pitch, -2 * depth), (0.0, -2 * depth)])


def _column_count(width: float) -> int:
    """Grains that fill the column's hexagonal lattice of the largest diameter."""
    diameter = 2.4 * RADIUS
    across = int(width // diameter)
    rows = int((3 * width - diameter) // (diameter * np.sqrt(3) / 2)) + 1
    return across * rows - rows // 2


def measure(sim: gr.Simulation) -> Heap:
    """The heap's free surface from its grains (see the module docstring)."""
    centres, sizes = [], []
    for body in sim.bodies:
        x = sim.positions[body.nodes, :2]
        centre = np.average(x, axis=0, weights=sim.volumes[body.nodes])
        centres.append(centre)
        sizes.append(np.max(np.linalg.norm(x - centre, axis=1)))
    centres, sizes = np.array(centres), np.array(sizes)
    tops = centres[:, 1] + sizes
    diameter = 2 * float(np.mean(sizes))
    slices = np.floor(centres[:, 0] / diameter).astype(int)
    envelope = []
    for s in np.unique(slices):  # the highest grain of each slice
        members = np.flatnonzero(slices == s)
        highest = members[np.argmax(tops[members])]
        envelope.append((centres[highest, 0], tops[highest]))
    envelope = np.array(envelope)
    slope, _ = np.polyfit(envelope[:, 0], envelope[:, 1], 1)
    return Heap(
        angle=float(np.degrees(np.arctan(-slope))),
        height=float(tops.max()),
        runout=float(centres[:, 0].max() + diameter / 2),
        envelope=envelope,
    )


CASES = [(0.0, 0.0), (0.2, 0.0), (0.5, 0.0), (0.5, 0.3)]  # (friction, rolling friction)
SEEDS = (1, 2)  # packings: one heap is a noisy measure, the figure's angles are their means


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--smoke", action="store_true", help="the 8 mm column (28 grains); prints, draws nothing"
    )
    args = parser.parse_args()
    width = 8e-3 if args.smoke else 16e-3
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9, 3.6))
    print("mu   mu_r  seed  grains  angle [deg]  height [mm]  runout [mm]")
    for friction, rolling in CASES:
        heaps = []
        for seed in SEEDS:
            heap, sim = collapse(
                friction, width=width, rolling_friction=rolling, until=0.14, seed=seed
            )
            heaps.append(heap)
            print(
                f"{friction:4.2f} {rolling:4.2f}  {seed:4d}  {len(sim.bodies):6d}"
                f"  {heap.angle:11.1f}  {heap.height * 1e3:11.2f}  {heap.runout * 1e3:11.2f}"
            )
        mean = float(np.mean([h.angle for h in heaps]))
        print(f"{friction:4.2f} {rolling:4.2f}  mean          {mean:11.1f}")
        x, y = heaps[0].envelope[:, 0] * 1e3, heaps[0].envelope[:, 1] * 1e3
        label = f"mu = {friction}" + (f", mu_r = {rolling}" if rolling else "")
        line = ax.plot(x, y, "o", ms=3, label=f"{label}: {mean:.1f} deg (mean of {len(SEEDS)})")[0]
        fit = np.polyfit(x, y, 1)
        ax.plot(x, np.polyval(fit, x), "-", color=line.get_color(), lw=1)
    ax.set_xlabel("distance from the wall [mm]")
    ax.set_ylabel("top of the heap [mm]")
    if args.smoke:
        return
    ax.legend(fontsize=8)
    title = (
        f"Column collapse, {width * 1e3:.0f} mm x {3 * width * 1e3:.0f} mm of discs (0.8-1.2 mm,"
        f" R/h = {NODES_ACROSS_RADIUS}): the heap's upper envelope (packing seed {SEEDS[0]})"
        " and the fitted slope"
    )
    save(fig, title, "angle_of_repose.png")


if __name__ == "__main__":
    main()
