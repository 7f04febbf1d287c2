"""Oblique impacts of a disc (sphere) on a rigid plane at constant speed and varying angle, the
2D (3D) analogue of Chung & Ooi (2011, Granular Matter 13:643) test 4, against the rigid-body
impulse theory with Coulomb friction (Maw, Barber & Fawcett 1976 in its gross-sliding limit).

A body of mass m, inertia I = k m R^2 (disc k = 1/2, sphere k = 2/5) hits the plane with normal
speed v_n and tangential speed v_t, no spin; it rebounds with normal restitution e. While the
contact point slides all through the impact (v_t > mu (1 + e) v_n (1 + 1/k)), the friction
impulse is mu (1 + e) m v_n:

    v_t' = v_t - mu (1 + e) v_n,   omega' R = mu (1 + e) v_n / k.

At smaller angles the contact point stops sliding and the rebound depends on the tangential
compliance of the contact, which the rigid theory has not: a rigid body leaves rolling,
v_t' = omega' R = v_t / (1 + k); an elastic contact point springs back (Maw et al.), up to a
full reversal of its tangential velocity, v_t' - omega' R = -v_t, which keeps the tangential
and spin energy (the bound drawn dashed).

Test 6 analogue (--test 6): the body falls straight down (v_t = 0) spinning at omega R; its
contact point slides at u = v_t - omega R, and the same impulse theory applies with the friction
opposing u: gross sliding while |u| > mu (1 + e) v_n (1 + 1/k), rolling below.

Run: python docs/validation/oblique_impact.py [--dimension 2|3] [--test 4|6] [--smoke]; writes
docs/validation/oblique_impact_<d>d.png (test 4) or spinning_impact_<d>d.png (test 6) and
prints the table.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import granulate as gr

SOFT = gr.Material(density=1200, bulk_modulus=2.16e7, shear_modulus=1.296e7, fracture=False)
RADIUS, SPEED, MU, RESTITUTION = 1e-3, 0.5, 0.3, 0.8


def run_through_wall_impact(sim: gr.Simulation) -> None:
    """Run until the body has touched the wall and left it, then 50 steps more."""
    touched = False
    while True:
        sim.run(10)
        touching = sim.core.contact_statistics.wall_contacts > 0
        touched = touched or touching
        if touched and not touching:
            break
    sim.run(50)


def save(fig, title: str, name: str) -> None:
    """Title the figure and write it beside this script."""
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    out = Path(__file__).with_name(name)
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


def impact(
    dimension: int, angle: float, nodes_across_radius: int, spin: float = 0.0, speed: float = SPEED
) -> dict[str, float]:
    """One impact at `angle` degrees from the normal, the body turning at omega R = `spin`
    (positive rolling forwards, towards +x): incoming and rebound velocities and spin."""
    h = RADIUS / nodes_across_radius
    sim = gr.Simulation(dimension)
    sim.contact = gr.Contact(restitution=RESTITUTION, friction=MU)
    a = np.radians(angle)
    velocity = (speed * np.sin(a), -speed * np.cos(a), 0.0)[:dimension]
    centre = (0.0, RADIUS + 0.6 * h, 0.0)[:dimension]
    shape = gr.Disc(centre, RADIUS) if dimension == 2 else gr.Sphere(centre, RADIUS)
    body = sim.add_body(shape, SOFT, h, discretization="conforming", velocity=velocity)
    normal = (0.0, 1.0, 0.0)[:dimension]
    sim.add_wall(gr.Plane((0.0,) * dimension, normal), name="floor")
    if spin:  # rigid rotation about z: v = v_c + omega x (x - c), omega_z = -spin / R
        nodes = body.nodes
        offset = sim.positions[nodes, :2] - np.asarray(centre)[:2]
        sim.velocities[nodes, 0] += spin / RADIUS * offset[:, 1]
        sim.velocities[nodes, 1] -= spin / RADIUS * offset[:, 0]
    run_through_wall_impact(sim)
    nodes = body.nodes
    m = sim.volumes[nodes]
    x, v = sim.positions[nodes], sim.velocities[nodes]
    c, vc = np.average(x, axis=0, weights=m), np.average(v, axis=0, weights=m)
    r, w = x - c, v - vc
    # Angular velocity about z from the inertia tensor (the motion is in the x-y plane).
    inertia = np.einsum(
        "n,nij->ij",
        m,
        np.einsum("ni,ni->n", r, r)[:, None, None] * np.eye(3) - np.einsum("ni,nj->nij", r, r),
    )
    momentum = np.sum(m[:, None] * np.cross(r, w), axis=0)
    turn = momentum / inertia[2, 2] if dimension == 2 else np.linalg.solve(inertia, momentum)
    rate = -turn[2]  # omega', positive rolling forwards
    return {
        "angle": angle,
        "v_n": speed * np.cos(a),
        "v_t": speed * np.sin(a),
        "spin_R_before": spin,
        "e": vc[1] / (speed * np.cos(a)),
        "v_t_after": vc[0],
        "spin_R": rate * RADIUS,  # omega' R
    }


def theory(dimension: int, v_n: float, v_t: float, e: float) -> tuple[float, float]:
    """Rigid-body rebound (v_t', omega' R) with Coulomb friction: gross sliding, or rolling."""
    k = 0.5 if dimension == 2 else 0.4
    impulse = MU * (1 + e) * v_n
    if v_t > impulse * (1 + 1 / k):
        return v_t - impulse, impulse / k
    rolling = v_t / (1 + k)
    return rolling, rolling


def spinning_theory(
    dimension: int, v_n: float, v_t: float, spin: float, e: float
) -> tuple[float, float]:
    """Rigid-body rebound (v_t', omega' R) of a spinning body with Coulomb friction. The contact
    point slides at u = v_t - omega R; while it slides all through the impact
    (|u| > mu (1 + e) v_n (1 + 1/k)) the friction impulse mu (1 + e) m v_n opposes u, else the
    body leaves rolling (u' = 0)."""
    k = 0.5 if dimension == 2 else 0.4
    slip = v_t - spin
    impulse = MU * (1 + e) * v_n
    if abs(slip) > impulse * (1 + 1 / k):
        change = np.sign(slip) * impulse
    else:
        change = k * slip / (1 + k)
    return v_t - change, spin + change / k


def reversal(dimension: int, v_t: float) -> tuple[float, float]:
    """Rebound (v_t', omega' R) that reverses the contact point's velocity, v_t' - omega' R =
    -v_t, with the friction impulse J: v_t' = v_t - J/m, omega' R = J/(k m)."""
    k = 0.5 if dimension == 2 else 0.4
    impulse = 2 * v_t * k / (1 + k)
    return v_t - impulse, impulse / k


def angle_figure(d: int, smoke: bool) -> None:
    """Test 4: constant speed, incidence angles from 2 to 80 degrees."""
    angles = [5, 15, 30, 45, 60, 75] if smoke else [2, 5, 10, 15, 20, 25, 30, 40, 50, 60, 70, 80]
    npr = 10 if d == 2 else 6
    rows = [impact(d, angle, npr) for angle in angles]
    print("angle  e     v_t'/v  rigid   omega'R/v  rigid  (rigid: gross sliding, or rolling)")
    for row in rows:
        vt, wr = theory(d, row["v_n"], row["v_t"], row["e"])
        print(
            f"{row['angle']:5.0f}  {row['e']:.3f} {row['v_t_after'] / SPEED:.4f} {vt / SPEED:.4f}  "
            f"{row['spin_R'] / SPEED:.4f}    {wr / SPEED:.4f}"
        )
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fine = np.linspace(0.5, 85, 200)
    e_mean = float(np.mean([r["e"] for r in rows]))
    curves = np.array(
        [
            theory(d, SPEED * np.cos(np.radians(a)), SPEED * np.sin(np.radians(a)), e_mean)
            for a in fine
        ]
    )
    limit = np.degrees(np.arctan(MU * (1 + e_mean) * (1 + (2.0 if d == 2 else 2.5))))
    sticking = fine[fine < limit]
    reversed_ = np.array([reversal(d, SPEED * np.sin(np.radians(a))) for a in sticking])
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
    for column, ax in enumerate(axes):
        ax.plot(sticking, reversed_[:, column] / SPEED, "k--", lw=0.8, label="full reversal")
    axes[0].plot(fine, curves[:, 0] / SPEED, "k-", label="rigid body, Coulomb")
    axes[0].plot(angles, [r["v_t_after"] / SPEED for r in rows], "o", label="granulate")
    axes[0].set_ylabel("tangential rebound speed v_t' / v")
    axes[1].plot(fine, curves[:, 1] / SPEED, "k-", label="rigid body, Coulomb")
    axes[1].plot(angles, [r["spin_R"] / SPEED for r in rows], "o", label="granulate")
    axes[1].set_ylabel("rebound spin omega' R / v")
    for ax in axes:
        ax.set_xlabel("incidence angle from the normal [degrees]")
        ax.legend()
        ax.grid(alpha=0.3)
    shape = "disc" if d == 2 else "sphere"
    title = (
        f"Oblique impact of a {shape} on a plane (Chung & Ooi test 4 analogue): v = {SPEED} m/s, "
        f"mu = {MU}, e = {RESTITUTION}, R/h = {npr}"
    )
    save(fig, title, f"oblique_impact_{d}d.png")


def spin_figure(d: int, smoke: bool) -> None:
    """Test 6: a spinning body dropped straight down (v_n = SPEED, v_t = 0) at spins omega R
    from -4 to 4 v_n."""
    spins = [-3.0, -1.0, 1.0, 3.0] if smoke else [-4, -3, -2, -1.5, -1, -0.5, 0.5, 1, 1.5, 2, 3, 4]
    npr = 10 if d == 2 else 6
    rows = [impact(d, 0.0, npr, spin=float(w) * SPEED) for w in spins]
    print("omegaR/v  e     v_t'/v  rigid    omega'R/v  rigid  (rigid: gross sliding, or rolling)")
    for w, row in zip(spins, rows, strict=True):
        vt, wr = spinning_theory(d, row["v_n"], 0.0, row["spin_R_before"], row["e"])
        print(
            f"{w:8.2f}  {row['e']:.3f} {row['v_t_after'] / SPEED:7.4f} {vt / SPEED:7.4f}  "
            f"{row['spin_R'] / SPEED:8.4f}  {wr / SPEED:7.4f}"
        )
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    e_mean = float(np.mean([r["e"] for r in rows]))
    fine = np.linspace(-4.2, 4.2, 400)
    curves = np.array([spinning_theory(d, SPEED, 0.0, w * SPEED, e_mean) for w in fine])
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
    for column, (ax, key) in enumerate(zip(axes, ("v_t_after", "spin_R"), strict=True)):
        ax.plot(fine, curves[:, column] / SPEED, "k-", label="rigid body, Coulomb")
        ax.plot(spins, [r[key] / SPEED for r in rows], "o", label="granulate")
        ax.set_xlabel("spin before, omega R / v_n")
        ax.legend()
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("tangential rebound speed v_t' / v_n")
    axes[1].set_ylabel("rebound spin omega' R / v_n")
    shape = "disc" if d == 2 else "sphere"
    title = (
        f"Spinning {shape} dropped on a plane (Chung & Ooi test 6 analogue): v_n = {SPEED} m/s, "
        f"mu = {MU}, e = {RESTITUTION}, R/h = {npr}"
    )
    save(fig, title, f"spinning_impact_{d}d.png")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dimension", type=int, default=2, choices=(2, 3))
    parser.add_argument("--test", type=int, default=4, choices=(4, 6))
    parser.add_argument("--smoke", action="store_true")
    args = parser.parse_args()
    (angle_figure if args.test == 4 else spin_figure)(args.dimension, args.smoke)


if __name__ == "__main__":
    main()
