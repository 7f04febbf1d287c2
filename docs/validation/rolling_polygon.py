"""Why a resolved disc rolling on a wall loses speed on the node spheres: it rolls as the
polygon of its surface points (ARCHITECTURE.md, "The surface law").

A conforming disc of radius R at R/h nodes per radius (soft material of the friction tests, 1
mm, g = 9.81) lands on a floor for 3 ms, is set sliding at v0 = 0.1 m/s without spin (friction
0.3), and is followed for 30 ms. On the node spheres (the default law) the wall sees each
surface node through its own small contact sphere, so under a stiff contact (the default kn
leaves an overlap of about 4e-8 m under the disc's weight) the disc's centre drops by the
polygon's sagitta h^2 / (8 R) between two nodes and lands on the next one with an impact. A
rigid polygon of vertex angle alpha = h / R and inertia 3/2 m R^2 about a vertex keeps (1/2 +
cos alpha) / (3/2) ~ 1 - alpha^2 / 3 of its speed per vertex: a drag that grows with v^2 and
falls with h. With a damping contact (e = 0.1) that loss shows as a steady slowing; with an
elastic one (e = 1) the landings pump the disc into hops instead. Under the surface law (--law
surface) the wall sees the disc, a round particle, through its points' osculating spheres,
which agree on its circle: it rolls steadily and its centre stays at its resting height.

Prints, per 3 ms window after the launch: the fraction of samples (every 10 steps) in which the
disc flies (its vertical velocity changed by exactly -g dt), its centre's lowest and highest
position against its resting height in units of h, and its mean speed over v0.

Run: python docs/validation/rolling_polygon.py [--nodes 10] [--restitution 0.1]
[--stiffness-factor 1] [--law granulate|surface] (R/h = 10: about 6 s; 20: about 50 s).
"""

from __future__ import annotations

import argparse

import numpy as np
from oblique_impact import rigid_motion

import granulate as gr

SOFT = gr.Material(density=1200, bulk_modulus=2.16e7, shear_modulus=1.296e7, fracture=False)
RADIUS, SPEED, GRAVITY = 1e-3, 0.1, 9.81


def rolling_disc(
    nodes: int, restitution: float, stiffness_factor: float, law: str, duration: float = 0.03
) -> np.ndarray:
    """Rows of (time after launch [s], flying 0/1, centre height over rest [h], v / v0), over
    `duration` seconds from the launch."""
    h = RADIUS / nodes
    sim = gr.Simulation(2, gravity=(0, -GRAVITY))
    sim.contact = gr.Contact(
        restitution=restitution, friction=0.3, pair_law=law, stiffness_factor=stiffness_factor
    )
    disc = sim.add_body(gr.Disc((0, RADIUS), RADIUS), SOFT, h, discretization="conforming")
    sim.add_wall(gr.Plane((0, 0), (0, 1)), name="floor")
    sim.run(until=0.003)
    rest = rigid_motion(sim, disc)[0][1]
    sim.velocities[:, 0] += SPEED
    launch, before, then = sim.time, rigid_motion(sim, disc)[1][1], sim.time
    rows = []
    while sim.time < launch + duration:
        sim.run(10)
        centre, velocity, _ = rigid_motion(sim, disc)
        flying = abs(velocity[1] - before + GRAVITY * (sim.time - then)) < 1e-9
        rows.append((sim.time - launch, flying, (centre[1] - rest) / h, velocity[0] / SPEED))
        before, then = velocity[1], sim.time
    return np.array(rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--nodes", type=int, default=10, help="nodes per radius R/h")
    parser.add_argument("--restitution", type=float, default=0.1)
    parser.add_argument("--stiffness-factor", type=float, default=1.0)
    parser.add_argument("--law", default="granulate", choices=["granulate", "surface"])
    args = parser.parse_args()
    rows = rolling_disc(args.nodes, args.restitution, args.stiffness_factor, args.law)
    alpha = 1 / args.nodes
    print(
        f"R/h = {args.nodes}, e = {args.restitution}, stiffness_factor = {args.stiffness_factor}, "
        f"{args.law} law; sagitta h / (8 R/h) = {alpha / 8:.4f} h, rigid polygon's loss "
        f"alpha^2 / 3 = {alpha**2 / 3:.2e} of the speed per node passed"
    )
    print(" window [ms]  flying  centre min / max [h]  v / v0")
    for start in np.arange(0, 0.03, 0.003):
        window = (rows[:, 0] >= start) & (rows[:, 0] < start + 0.003)
        flying, height, speed = rows[window, 1], rows[window, 2], rows[window, 3]
        print(
            f"  {start * 1e3:4.0f}-{(start + 0.003) * 1e3:2.0f}     {flying.mean():4.2f}"
            f"    {height.min():+.4f} / {height.max():+.4f}      {speed.mean():.4f}"
        )


if __name__ == "__main__":
    main()
