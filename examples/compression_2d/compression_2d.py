"""The PeriDEM paper's compression test as a user sets it up natively: 366 discs and
136 hexagons (radius uniform in [0.9, 1.1] mm, random orientations) are packed on lattice
sites at the bottom of a 68 mm wide container, settle under gravity until they are at rest, and
are then compressed by a top wall placed on the settled pile and moved down at 0.06 m/s (Jha et
al., JMPS 2021, section 5 and Fig. 3a). history.csv of the second stage has the top wall's
stress ``top_stress`` [Pa] (its force over the container's width) against its travel
``top_displacement``.

    python examples/compression_2d/compression_2d.py --smoke     # 40 grains, 0.2 mm: seconds
    python examples/compression_2d/compression_2d.py             # 120 grains, 3.4 mm, 0.6 m/s
    python examples/compression_2d/compression_2d.py --grains 502 --speed 0.06  # the paper's
    python examples/compression_2d/compression_2d.py --peridem-constants  # PeriDEM's 2D LPS
    python examples/compression_2d/compression_2d.py --stiffness-factor 10  # a stiffer contact
    python examples/compression_2d/compression_2d.py --friction 0.5  # frictional compression

Steps: (1) the material (LPS, linear influence, horizon 0.6 mm); (2) two grains, discs with
conforming (ring) nodes and hexagons on a lattice, both of mesh size 0.2 mm at radius 1 mm;
(3) pack them on the hexagonal lattice sites of the container's bottom (no initial contact;
they fall at most a gap); (4) settle: gravity, contact with restitution 0.95 and no friction,
background damping, until the kinetic energy is below a millionth of the grains' weight times
a millimetre; (5) compress: the same grains at their settled positions, a top wall placed just
above the highest node, moved down; the wall stress against its travel is the load curve.
``--peridem-constants`` uses PeriDEM's 2D peridynamics instead of granulate's: the 3D LPS
constants and critical stretch in 2D (``Simulation(plane="peridem")``) and bonds that also
break in compression (``Material(break_in_compression=True)``), as the paper's runs did;
``--stiffness-factor`` multiplies the contact spring (``Contact(stiffness_factor=...)``).
``--friction`` gives the grains friction in stage 2 (they settle frictionless, as the paper's):
frictionless grains under the surface law slide past each other when a force chain gives way,
and the pile keeps a third of the wall's work as motion (docs/validation/README.md).
Stage 2 starts from the settled positions as PeriDEM's run2 restarts from its output_400
(the settling's contact history is not carried over: at rest, without friction, there is
none that matters).
"""

from __future__ import annotations

import argparse
import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

import granulate as gr

WIDTH, HEIGHT = 68e-3, 41e-3  # inner size of the container [m]
RADIUS = 1.1e-3  # the largest grain radius [m]
GAP = 0.05e-3  # the top wall starts this far above the highest node [m]


@dataclass(frozen=True)
class Options:
    """peridem: PeriDEM's 2D peridynamics (3D LPS constants, bonds breaking in compression);
    stiffness_factor: of the contact spring; pair_law: Contact(pair_law=...); restitution:
    Contact(restitution=...); history_every: steps between history rows of the compression
    (None: the frames' interval); friction: Contact(friction=...) of the compression (the
    settling is frictionless)."""

    peridem: bool = False
    stiffness_factor: float = 1.0
    pair_law: str = "surface"
    restitution: float = 0.95
    history_every: int | None = None
    friction: float = 0.0


def material(options: Options = Options()) -> gr.Material:
    """K, G [Pa], Gc [J/m^2], rho [kg/m^3] of the paper; horizon 0.6 mm for every grain;
    with options.peridem, bonds break in compression too."""
    return gr.Material(
        density=1200,
        bulk_modulus=2.16e7,
        shear_modulus=1.296e7,
        fracture_energy=50,
        horizon=0.6e-3,
        break_in_compression=options.peridem,
    )


def packing(count: int, width: float, seed: int, options: Options = Options()) -> gr.Packing:
    """`count` grains (the paper's 73 % discs) on lattice sites filling the bottom rows of a
    container `width` wide."""
    sizes = gr.Uniform(0.9e-3, 1.1e-3)
    discs = round(count * 366 / 502)
    rock = material(options)
    disc = gr.Grain(gr.Disc((0, 0), 1e-3), rock, 0.2e-3, sizes, discs, discretization="conforming")
    hexagon = gr.Grain(gr.RegularPolygon((0, 0), 1e-3, 6), rock, 0.2e-3, sizes, count - discs)
    spacing = 2 * RADIUS * 1.05  # the lattice's spacing with pack's gap, about
    across = int(width // spacing)
    rows = math.ceil(count / (across - 0.5))
    height = (rows - 1) * spacing * math.sqrt(3) / 2 + 2 * spacing
    return gr.pack(
        gr.Rectangle((0, 0), (width, height)), [disc, hexagon], count, method="lattice", seed=seed
    )


def simulation(grains: gr.Packing, width: float, options: Options = Options()) -> gr.Simulation:
    """The grains in the container (floor and sides), frictionless contact, gravity."""
    plane = "peridem" if options.peridem else "strain"
    sim = gr.Simulation(dimension=2, gravity=(0, -10), plane=plane)
    sim.contact = gr.Contact(
        restitution=options.restitution,
        friction=0.0,
        stiffness_factor=options.stiffness_factor,
        pair_law=options.pair_law,
    )
    sim.add_packing(grains)
    sides = (gr.Plane((0, 0), (0, 1)), gr.Plane((0, 0), (1, 0)), gr.Plane((width, 0), (-1, 0)))
    sim.add_wall(gr.Wall(sides), name="container")
    return sim


def settle(
    grains: gr.Packing,
    width: float,
    until: float,
    out: Path,
    overwrite: bool,
    options: Options = Options(),
) -> tuple[gr.Simulation, list[gr.Body]]:
    """Stage 1: the grains fall onto each other and come to rest (background damping 50 /s),
    or `until` [s] has passed; returns the simulation and the grains' bodies."""
    sim = simulation(grains, width, options)
    bodies = sim.bodies[:]
    sim.viscous_damping = 50.0
    weight = float(sim.volumes.sum()) * 1200 * 10
    at_rest = gr.stopping.KineticEnergyBelow(1e-6 * weight * 1e-3, after=0.01)
    sim.output(out, every=5000, overwrite=overwrite)
    reason = sim.run(until=until, stop=[at_rest])
    print(f"settling: {reason or f'stopped at t = {until} s, not yet at rest'}")
    return sim, bodies


def compress(
    grains: gr.Packing,
    width: float,
    settled: gr.Simulation,
    bodies: list[gr.Body],
    speed: float,
    travel: float,
    out: Path,
    overwrite: bool,
    options: Options = Options(),
) -> gr.Simulation:
    """Stage 2: the settled grains under a top wall placed GAP above them, moved down at `speed`
    until it has travelled `travel`; its stress is recorded over the container's width."""
    sim = simulation(settled.placements_now(bodies, grains), width, options)  # where they rest
    sim.contact = dataclasses.replace(sim.contact, friction=options.friction)
    top = float(settled.positions[:, 1].max()) + GAP
    plate = gr.Wall(
        (gr.Plane((0, top), (0, -1)),),
        motion=gr.Translation((0, -1), gr.Linear(speed)),
        area=width,
    )
    sim.add_wall(plate, name="top")
    steps = math.ceil(travel / speed / sim.dt)
    sim.output(
        out, every=max(1, steps // 40), history_every=options.history_every, overwrite=overwrite
    )
    sim.run(steps)
    return sim


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--smoke", action="store_true", help="40 grains settled 5 ms, 0.2 mm of travel"
    )
    parser.add_argument("--grains", type=int, default=120, help="grains (the paper: 502)")
    parser.add_argument(
        "--speed", type=float, default=0.6, help="top wall speed [m/s] (the paper: 0.06)"
    )
    parser.add_argument("--travel", type=float, default=3.4e-3, help="top wall travel [m]")
    parser.add_argument("--out", default="out/compression", help="output directory")
    parser.add_argument("--overwrite", action="store_true", help="replace an earlier run in --out")
    parser.add_argument("--seed", type=int, default=1, help="seed of the packing")
    parser.add_argument(
        "--peridem-constants",
        action="store_true",
        help="PeriDEM's 2D peridynamics: 3D LPS constants, bonds break in compression too",
    )
    parser.add_argument(
        "--stiffness-factor", type=float, default=1.0, help="of the contact spring (default 1)"
    )
    parser.add_argument(
        "--pair-law",
        choices=("surface", "granulate"),
        default="surface",
        help="contact law: surface (the default) or granulate (the node spheres, which made the "
        "committed figures)",
    )
    parser.add_argument(
        "--friction", type=float, default=0.0, help="grains' friction while compressed (default 0)"
    )
    args = parser.parse_args(argv)
    count, travel, until = (40, 0.2e-3, 5e-3) if args.smoke else (args.grains, args.travel, 1.0)
    width = WIDTH * min(1.0, math.sqrt(count / 502))  # the paper's proportions
    out = Path(args.out)

    options = Options(
        args.peridem_constants, args.stiffness_factor, args.pair_law, friction=args.friction
    )
    grains = packing(count, width, args.seed, options)
    print(grains.summary())
    settled, bodies = settle(grains, width, until, out / "settle", args.overwrite, options)
    print(f"settled at t = {settled.time:.4g} s, {settled.node_count} nodes, dt {settled.dt:.3g} s")
    sim = compress(
        grains,
        width,
        settled,
        bodies,
        args.speed,
        travel,
        out / "compress",
        args.overwrite,
        options,
    )
    history = gr.Results(out / "compress").history
    stress = history["top_stress"]
    summary = sim.summary()
    print(
        f"compressed {1e3 * travel:.2f} mm in {summary['steps']} steps "
        f"({summary['wall_seconds']:.1f} s): top wall stress {1e-3 * stress[-1]:.3g} kPa at the "
        f"end, {1e-3 * np.max(stress):.3g} kPa at most, broken bonds {sim.broken_bonds()}; "
        f"output in {out}"
    )
    return {
        "nodes": summary["nodes"],
        "steps": summary["steps"] + settled.summary()["steps"],
        "particles": count,
        "final_stress": float(stress[-1]),
    }


if __name__ == "__main__":
    main()
