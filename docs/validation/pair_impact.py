"""Two spinning bodies meeting head-on, the 2D (3D) analogues of Chung & Ooi (2011, Granular
Matter 13:643) test 7 (two identical spheres at a constant normal velocity and varying angular
velocities) and test 8 (two differently sized spheres), against the rigid-body impulse theory
with Coulomb friction.

Body 1 (radius R1, mass m1, inertia I1 = k m1 R1^2; disc k = 1/2, sphere k = 2/5) lies below
body 2 (R2, m2, I2) on the y axis. They approach at v_n (each at its share, so that their centre
of mass rests), with no tangential velocity, spinning about z at omega_1 and omega_2
(counterclockwise positive). Body 1's contact point slides past body 2's at

    u = (v_1 - omega_1 R1) - (v_2 + omega_2 R2)            (x components)

The normal impulse is J_n = (1 + e) m* v_n, m* = m1 m2 / (m1 + m2). A friction impulse J on
body 1 along x (-J on body 2) changes u by J B, B = (1 + 1/k) (1/m1 + 1/m2), and

    v_1' = v_1 + J / m1,   omega_1' = omega_1 - J R1 / I1,
    v_2' = v_2 - J / m2,   omega_2' = omega_2 - J R2 / I2.

While the contact point slides all through the impact (|u| > mu J_n B), J = -sign(u) mu J_n;
below, rigid bodies leave without slip, J = -u / B. Elastic contacts spring back instead (as in
tests 4 to 6, oblique_impact.py): the dashed line is the full reversal of u, J = -2 u / B,
capped by Coulomb's mu J_n.

Test 7: equal bodies spinning the same way, omega_1 = omega_2 = omega, so u = -2 omega R; by
symmetry v_1' = -v_2' and omega_1' = omega_2'. Test 8: a body of radius R spinning at omega hits
a body of radius 5 R at rest (same material, the same nodes per radius, so meshed 5 times
coarser); with a mass ratio of 25 (125 in 3D) the large body is nearly a wall (Chung & Ooi make
it 1000 times denser as well).

Run: python docs/validation/pair_impact.py [--dimension 2|3] [--test 7|8] [--smoke]; writes
docs/validation/pair_impact_test<7|8>_<d>d.png and prints the table. --friction MU (the table
only) and --nodes N (nodes per radius) vary the set-up; --pair-law granulate runs the node
spheres instead of the surface law (the figure's name ends in _granulate).
"""

from __future__ import annotations

import argparse

import numpy as np
from oblique_impact import (
    MU,
    RADIUS,
    RESTITUTION,
    SOFT,
    SPEED,
    rigid_motion,
    save_test_figure,
)

import granulate as gr

LARGE = 5.0  # test 8: radius of body 2 over that of body 1


def inertia_factor(dimension: int) -> float:
    """k in I = k m R^2: a disc 1/2, a sphere 2/5."""
    return 0.5 if dimension == 2 else 0.4


def run_until_apart(sim: gr.Simulation, bodies: list, radii: tuple[float, float]) -> None:
    """Run until the bodies have touched and their surfaces are apart by a tenth of body 1's
    radius, then 50 steps more. (Spinning grains can lose every node contact for a moment while
    they still press together, so a contact count alone does not say they have parted.)"""
    touched = False
    while True:
        sim.run(10)
        touched = touched or sim.core.contact_statistics.node_contacts > 0
        centres = [
            np.average(sim.positions[b.nodes], axis=0, weights=sim.volumes[b.nodes]) for b in bodies
        ]
        gap = np.linalg.norm(centres[1] - centres[0]) - sum(radii)
        if touched and gap > 0.1 * radii[0]:
            break
    sim.run(50)


def pair_impact(
    dimension: int,
    radii: tuple[float, float],
    spins: tuple[float, float],
    nodes_across_radius: int,
    friction: float = MU,
    pair_law: str = "surface",
) -> dict:
    """Bodies of `radii` spinning at omega R = `spins` meet at SPEED: their masses, friction,
    velocities and spins (omega R) before and after, and the normal restitution."""
    sim = gr.Simulation(dimension)
    sim.contact = gr.Contact(restitution=RESTITUTION, friction=friction, pair_law=pair_law)
    bodies, centres = [], []
    for side, radius in zip((-1, 1), radii, strict=True):
        h = radius / nodes_across_radius
        gap = 0.3 * radii[0] / nodes_across_radius
        centre = np.array([0.0, side * (radius + gap), 0.0])[:dimension]
        shape = gr.Disc(centre, radius) if dimension == 2 else gr.Sphere(centre, radius)
        bodies.append(sim.add_body(shape, SOFT, h, discretization="conforming"))
        centres.append(centre)
    masses = [float(np.sum(sim.volumes[b.nodes])) * SOFT.density for b in bodies]
    shares = (masses[1] / sum(masses), -masses[0] / sum(masses))
    for body, centre, radius, share, spin in zip(
        bodies, centres, radii, shares, spins, strict=True
    ):
        offset = sim.positions[body.nodes, :2] - centre[:2]  # rigid spin about z: omega x r
        sim.velocities[body.nodes, 0] = -spin / radius * offset[:, 1]
        sim.velocities[body.nodes, 1] = share * SPEED + spin / radius * offset[:, 0]
    run_until_apart(sim, bodies, radii)
    after = [rigid_motion(sim, b)[1:] for b in bodies]
    return {
        "masses": masses,
        "friction": friction,
        "radii": radii,
        "spins": spins,
        "e": (after[1][0][1] - after[0][0][1]) / SPEED,
        "v_t_after": [float(v[0]) for v, _ in after],
        "spin_after": [w[2] * r for (_, w), r in zip(after, radii, strict=True)],
    }


def pair_theory(dimension: int, row: dict, e: float, reversal: bool = False) -> dict:
    """The rigid-body rebound of `row`'s bodies (velocities along x, omega R) with Coulomb
    friction; with `reversal`, the elastic bound: u reversed, capped by Coulomb."""
    k = inertia_factor(dimension)
    m1, m2 = row["masses"]
    slip = -row["spins"][0] - row["spins"][1]  # u with v_1 = v_2 = 0
    normal = (1 + e) * m1 * m2 / (m1 + m2) * SPEED
    compliance = (1 + 1 / k) * (1 / m1 + 1 / m2)
    stick = (2.0 if reversal else 1.0) * abs(slip) / compliance
    impulse = -np.sign(slip) * min(stick, row["friction"] * normal)
    return {
        "v_t_after": [impulse / m1, -impulse / m2],
        "spin_after": [row["spins"][0] - impulse / (k * m1), row["spins"][1] - impulse / (k * m2)],
    }


def spin_pairs(test: int, rates: np.ndarray) -> list[tuple[float, float]]:
    """omega R of both bodies for each spin rate: both turning (test 7), the small one (test 8)."""
    return [(w, w if test == 7 else 0.0) for w in rates]


def table(
    dimension: int,
    test: int,
    rates: list[float],
    npr: int,
    friction: float,
    pair_law: str = "surface",
) -> list[dict]:
    """Run test 7 or 8 at omega R = rates x v_n and print the rebound against the theory."""
    radii = (RADIUS, RADIUS if test == 7 else LARGE * RADIUS)
    rows = [
        pair_impact(dimension, radii, spins, npr, friction, pair_law)
        for spins in spin_pairs(test, np.array(rates) * SPEED)
    ]
    print("omegaR/v_n  e     v_t1'   rigid    w1'R    rigid    v_t2'   w2'R  (over v_n)")
    for rate, row in zip(rates, rows, strict=True):
        rigid = pair_theory(dimension, row, row["e"])
        print(
            f"{rate:10.2f}  {row['e']:.3f} {row['v_t_after'][0] / SPEED:7.4f} "
            f"{rigid['v_t_after'][0] / SPEED:7.4f}  {row['spin_after'][0] / SPEED:7.4f} "
            f"{rigid['spin_after'][0] / SPEED:7.4f}  {row['v_t_after'][1] / SPEED:7.4f} "
            f"{row['spin_after'][1] / SPEED:7.4f}"
        )
    return rows


def figure(
    dimension: int,
    test: int,
    rows: list[dict],
    rates: list[float],
    npr: int,
    pair_law: str = "surface",
) -> None:
    """Rebound of body 1 against omega R / v_n for test 7 or 8, with the theory."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    e_mean = float(np.mean([r["e"] for r in rows]))
    fine = np.linspace(0.0, rates[-1] * 1.05, 300)
    template = dict(rows[0])
    curves = {}
    for reversal in (False, True):
        curves[reversal] = [
            pair_theory(dimension, {**template, "spins": spins}, e_mean, reversal)
            for spins in spin_pairs(test, fine * SPEED)
        ]
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
    styles = {
        True: ("k--", 0.8, "full reversal, capped"),
        False: ("k-", 1.5, "rigid body, Coulomb"),
    }
    for ax, key in zip(axes, ("v_t_after", "spin_after"), strict=True):
        for reversal, (style, width, label) in styles.items():
            values = [c[key][0] / SPEED for c in curves[reversal]]
            ax.plot(fine, values, style, lw=width, label=label)
        ax.plot(rates, [r[key][0] / SPEED for r in rows], "o", label="granulate, body 1")
        ax.set_xlabel("spin before, omega R / v_n")
        ax.legend()
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("body 1: tangential rebound speed v_t' / v_n")
    axes[1].set_ylabel("body 1: rebound spin omega' R / v_n")
    shape = "disc" if dimension == 2 else "sphere"
    what = (
        f"two equal {shape}s spinning the same way"
        if test == 7
        else f"a spinning {shape} and one {LARGE:g} times larger at rest"
    )
    suffix = "" if pair_law == "surface" else f"_{pair_law}"
    law = "" if pair_law == "surface" else f", pair_law {pair_law}"
    name = f"pair_impact_test{test}_{dimension}d{suffix}.png"
    resolution = f"R/h = {npr} each{law}"
    save_test_figure(fig, test, f"Head-on impact of {what}", "v_n", resolution, name)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dimension", type=int, default=2, choices=(2, 3))
    parser.add_argument("--test", type=int, default=7, choices=(7, 8))
    parser.add_argument("--nodes", type=int, help="nodes per radius (default 10 in 2D, 6 in 3D)")
    parser.add_argument("--friction", type=float, help="another mu than 0.3: the table only")
    parser.add_argument(
        "--pair-law",
        default="surface",
        choices=("surface", "granulate"),
        help="the contact's pair law: surface (the default) or granulate (the node spheres; the "
        "figure's name ends in _granulate)",
    )
    parser.add_argument("--smoke", action="store_true")
    args = parser.parse_args()
    rates = [0.5, 2.0] if args.smoke else [0.1, 0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 2.0, 3.0, 4.0]
    npr = args.nodes or (10 if args.dimension == 2 else 6)
    friction = MU if args.friction is None else args.friction
    rows = table(args.dimension, args.test, rates, npr, friction, args.pair_law)
    if args.friction is None:
        figure(args.dimension, args.test, rows, rates, npr, args.pair_law)


if __name__ == "__main__":
    main()
