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

Test 5 analogue (--test 5): the same theory at a constant normal speed v_n and tangential speeds
from 0.1 to 5 v_n.

Test 6 analogue (--test 6): the body falls straight down (v_t = 0) spinning at omega R; its
contact point slides at u = v_t - omega R, and the same impulse theory applies with the friction
opposing u: gross sliding while |u| > mu (1 + e) v_n (1 + 1/k), rolling below.

In 3D the figures also draw the Hertz-Mindlin (no slip) law of DEM codes for this sphere's
elastic constants (hertz_mindlin.py), the reference in the sticking regime too; the table
gives its v_t' and omega' R beside granulate's. 2D has no Hertz law to draw.

Run: python docs/validation/oblique_impact.py [--dimension 2|3] [--test 4|5|6] [--smoke]; writes
docs/validation/oblique_impact_<d>d.png (test 4), tangential_impact_<d>d.png (test 5) or
spinning_impact_<d>d.png (test 6) and prints the table.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

import granulate as gr

sys.path.insert(0, str(Path(__file__).parent))
import hertz_mindlin  # beside this script

SOFT = gr.Material(density=1200, bulk_modulus=2.16e7, shear_modulus=1.296e7, fracture=False)
RADIUS, SPEED, MU, RESTITUTION = 1e-3, 0.5, 0.3, 0.8
#: Contact options besides e and mu (--tangential-stiffness-ratio), and the figure names' suffix.
CONTACT_OPTIONS: dict[str, float] = {}


def run_through_impact(sim: gr.Simulation, against_wall: bool = True) -> None:
    """Run until the bodies have touched (a body and a wall, or two bodies) and parted, then 50
    steps more."""
    touched = False
    while True:
        sim.run(10)
        statistics = sim.core.contact_statistics
        touching = (statistics.wall_contacts if against_wall else statistics.node_contacts) > 0
        touched = touched or touching
        if touched and not touching:
            break
    sim.run(50)


def run_through_wall_impact(sim: gr.Simulation) -> None:
    """Run until the body has touched the wall and left it, then 50 steps more."""
    run_through_impact(sim, against_wall=True)


def rigid_motion(sim: gr.Simulation, body: gr.Body) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A body's centre of mass, its velocity and its angular velocity (about z in 2D, a vector
    in 3D), from its nodes' momentum and angular momentum (also used by the friction tests)."""
    nodes = body.nodes
    mass = sim.volumes[nodes] * body.material.density
    x, v = sim.positions[nodes], sim.velocities[nodes]
    centre = np.average(x, axis=0, weights=mass)
    velocity = np.average(v, axis=0, weights=mass)
    r = x - centre  # 3 components in 2D too (z = 0)
    momentum = np.sum(mass[:, None] * np.cross(r, v - velocity), axis=0)
    terms = np.einsum("ni,ni->n", r, r)[:, None, None] * np.eye(3) - np.einsum("ni,nj->nij", r, r)
    inertia = np.einsum("n,nij->ij", mass, terms)
    if sim.dimension == 2:
        return centre, velocity, np.array([0.0, 0.0, momentum[2] / inertia[2, 2]])
    return centre, velocity, np.linalg.solve(inertia, momentum)


def save_test_figure(fig, test: int, heading: str, speed: str, resolution: str, name: str) -> None:
    """Title a Chung & Ooi test figure (what it shows, then its parameters) and save it."""
    ratio = CONTACT_OPTIONS.get("tangential_stiffness_ratio")
    title = (
        f"{heading} (Chung & Ooi test {test} analogue)\n"
        f"{speed} = {SPEED} m/s, mu = {MU}, e = {RESTITUTION}, {resolution}"
        + (f", kt/kn = {ratio:.3g}" if ratio is not None else "")
    )
    if ratio is not None:
        name = name.replace(".png", f"_kt{ratio:.3g}.png")
    save(fig, title, name)


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
    sim.contact = gr.Contact(restitution=RESTITUTION, friction=MU, **CONTACT_OPTIONS)
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
    _, vc, omega = rigid_motion(sim, body)
    rate = -omega[2]  # omega', positive rolling forwards
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


def sphere() -> hertz_mindlin.Sphere:
    """The tests' sphere for the Hertz-Mindlin law: SOFT's E and nu (from K and G)."""
    k, g = SOFT.elastic_moduli()
    young, poisson = 9 * k * g / (3 * k + g), (3 * k - 2 * g) / (2 * (3 * k + g))
    return hertz_mindlin.Sphere(RADIUS, SOFT.density, young, poisson)


def mindlin(d: int, impacts: list[tuple[float, float, float]], e: float) -> np.ndarray | None:
    """Hertz-Mindlin rebounds (v_t', omega' R) of impacts (v_n, v_t, omega R) in 3D, its
    normal dashpot set to give e; None in 2D."""
    if d == 2:
        return None
    body = sphere()
    alpha = hertz_mindlin.damping_for(body, SPEED, e)
    rebounds = [hertz_mindlin.rebound(body, *impact, MU, alpha)[1:] for impact in impacts]
    return np.array(rebounds)


def plot_rebound(
    measured: tuple[list[float], list[dict]],
    theory_curves: tuple[np.ndarray, np.ndarray],
    reversal_curves: tuple[np.ndarray, np.ndarray] | None,
    xlabel: str,
    unit: str = "v_n",
    mindlin_curves: np.ndarray | None = None,
):
    """Two panels, v_t' and omega' R over SPEED (called `unit` on the axes) against x:
    granulate's rows (points), the rigid-body theory (line), where given the full reversal of
    the contact point's velocity (dashed) and the Hertz-Mindlin law at the theory's x (dotted).
    Returns the figure."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    xs, rows = measured
    fine, curves = theory_curves
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
    for column, (ax, key) in enumerate(zip(axes, ("v_t_after", "spin_R"), strict=True)):
        if reversal_curves is not None:
            sticking, reversed_ = reversal_curves
            ax.plot(sticking, reversed_[:, column] / SPEED, "k--", lw=0.8, label="full reversal")
        ax.plot(fine, curves[:, column] / SPEED, "k-", label="rigid body, Coulomb")
        if mindlin_curves is not None:
            ax.plot(fine, mindlin_curves[:, column] / SPEED, "C3:", label="Hertz-Mindlin (DEM)")
        ax.plot(xs, [r[key] / SPEED for r in rows], "o", label="granulate")
        ax.set_xlabel(xlabel)
        ax.legend()
        ax.grid(alpha=0.3)
    axes[0].set_ylabel(f"tangential rebound speed v_t' / {unit}")
    axes[1].set_ylabel(f"rebound spin omega' R / {unit}")
    return fig


def print_rows(
    label: str,
    xs: list[float],
    rows: list[dict],
    rigid: list,
    scale: float,
    reference: np.ndarray | None = None,
) -> None:
    """The measured rebound against the rigid-body theory (and the Hertz-Mindlin law, in 3D),
    one line per impact."""
    extra = "  H-M v_t' H-M omega'R" if reference is not None else ""
    print(f"{label:>8}  e     v_t'    rigid    omega'R  rigid{extra}   (over {scale} m/s)")
    for k, (x, row, (vt, wr)) in enumerate(zip(xs, rows, rigid, strict=True)):
        line = (
            f"{x:8.2f}  {row['e']:.3f} {row['v_t_after'] / scale:7.4f} {vt / scale:7.4f}  "
            f"{row['spin_R'] / scale:7.4f} {wr / scale:7.4f}"
        )
        if reference is not None:
            line += f"  {reference[k, 0] / scale:7.4f}  {reference[k, 1] / scale:7.4f}"
        print(line)


def sliding_limit(d: int, e: float) -> float:
    """v_t / v_n above which the contact point of a body without spin slides all through the
    impact: mu (1 + e) (1 + 1/k)."""
    return MU * (1 + e) * (1 + (2.0 if d == 2 else 2.5))


def angle_figure(d: int, smoke: bool) -> None:
    """Test 4: constant speed, incidence angles from 2 to 80 degrees."""
    angles = [5, 15, 30, 45, 60, 75] if smoke else [2, 5, 10, 15, 20, 25, 30, 40, 50, 60, 70, 80]
    npr = 10 if d == 2 else 6
    rows = [impact(d, angle, npr) for angle in angles]
    rigid = [theory(d, r["v_n"], r["v_t"], r["e"]) for r in rows]
    e_mean = float(np.mean([r["e"] for r in rows]))
    at_rows = mindlin(d, [(r["v_n"], r["v_t"], 0.0) for r in rows], e_mean)
    print_rows("angle", angles, rows, rigid, SPEED, at_rows)
    fine = np.linspace(0.5, 85, 200)
    curves = np.array(
        [
            theory(d, SPEED * np.cos(np.radians(a)), SPEED * np.sin(np.radians(a)), e_mean)
            for a in fine
        ]
    )
    sticking = fine[fine < np.degrees(np.arctan(sliding_limit(d, e_mean)))]
    reversed_ = np.array([reversal(d, SPEED * np.sin(np.radians(a))) for a in sticking])
    radians = np.radians(fine)
    impacts = [(SPEED * np.cos(a), SPEED * np.sin(a), 0.0) for a in radians]
    fig = plot_rebound(
        (angles, rows),
        (fine, curves),
        (sticking, reversed_),
        "incidence angle from the normal [degrees]",
        unit="v",
        mindlin_curves=mindlin(d, impacts, e_mean),
    )
    heading = f"Oblique impact of a {'disc' if d == 2 else 'sphere'} on a plane"
    save_test_figure(fig, 4, heading, "v", f"R/h = {npr}", f"oblique_impact_{d}d.png")


def tangential_figure(d: int, smoke: bool) -> None:
    """Test 5: constant normal speed v_n = SPEED, tangential speeds v_t from 0.1 to 5 v_n."""
    ratios = [0.5, 2.0, 4.0] if smoke else [0.1, 0.25, 0.5, 0.75, 1, 1.5, 2, 2.5, 3, 4, 5]
    npr = 10 if d == 2 else 6
    rows = [
        impact(d, float(np.degrees(np.arctan(t))), npr, speed=SPEED * float(np.hypot(1, t)))
        for t in ratios
    ]
    rigid = [theory(d, r["v_n"], r["v_t"], r["e"]) for r in rows]
    e_mean = float(np.mean([r["e"] for r in rows]))
    at_rows = mindlin(d, [(r["v_n"], r["v_t"], 0.0) for r in rows], e_mean)
    print_rows("v_t/v_n", ratios, rows, rigid, SPEED, at_rows)
    fine = np.linspace(0.0, 5.2, 300)
    curves = np.array([theory(d, SPEED, t * SPEED, e_mean) for t in fine])
    sticking = fine[fine < sliding_limit(d, e_mean)]
    reversed_ = np.array([reversal(d, t * SPEED) for t in sticking])
    reference = mindlin(d, [(SPEED, t * SPEED, 0.0) for t in fine], e_mean)
    fig = plot_rebound(
        (ratios, rows),
        (fine, curves),
        (sticking, reversed_),
        "v_t / v_n before",
        mindlin_curves=reference,
    )
    heading = f"Oblique impact of a {'disc' if d == 2 else 'sphere'} on a plane"
    save_test_figure(fig, 5, heading, "v_n", f"R/h = {npr}", f"tangential_impact_{d}d.png")


def spin_figure(d: int, smoke: bool) -> None:
    """Test 6: a spinning body dropped straight down (v_n = SPEED, v_t = 0) at spins omega R
    from -4 to 4 v_n."""
    spins = [-3.0, -1.0, 1.0, 3.0] if smoke else [-4, -3, -2, -1.5, -1, -0.5, 0.5, 1, 1.5, 2, 3, 4]
    npr = 10 if d == 2 else 6
    rows = [impact(d, 0.0, npr, spin=float(w) * SPEED) for w in spins]
    rigid = [spinning_theory(d, r["v_n"], 0.0, r["spin_R_before"], r["e"]) for r in rows]
    e_mean = float(np.mean([r["e"] for r in rows]))
    at_rows = mindlin(d, [(r["v_n"], 0.0, r["spin_R_before"]) for r in rows], e_mean)
    print_rows("omegaR/v", spins, rows, rigid, SPEED, at_rows)
    fine = np.linspace(-4.2, 4.2, 400)
    curves = np.array([spinning_theory(d, SPEED, 0.0, w * SPEED, e_mean) for w in fine])
    reference = mindlin(d, [(SPEED, 0.0, w * SPEED) for w in fine], e_mean)
    fig = plot_rebound(
        (spins, rows), (fine, curves), None, "spin before, omega R / v_n", mindlin_curves=reference
    )
    heading = f"Spinning {'disc' if d == 2 else 'sphere'} dropped on a plane"
    save_test_figure(fig, 6, heading, "v_n", f"R/h = {npr}", f"spinning_impact_{d}d.png")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dimension", type=int, default=2, choices=(2, 3))
    parser.add_argument("--test", type=int, default=4, choices=(4, 5, 6))
    parser.add_argument("--smoke", action="store_true")
    parser.add_argument(
        "--tangential-stiffness-ratio",
        type=float,
        help="Contact(tangential_stiffness_ratio=...) (default: granulate's 2/7); Mindlin's is "
        "2 (1 - nu) / (2 - nu), 0.857 for these grains; the figure's name gets _kt<ratio>",
    )
    args = parser.parse_args()
    if args.tangential_stiffness_ratio is not None:
        CONTACT_OPTIONS["tangential_stiffness_ratio"] = args.tangential_stiffness_ratio
    figures = {4: angle_figure, 5: tangential_figure, 6: spin_figure}
    figures[args.test](args.dimension, args.smoke)


if __name__ == "__main__":
    main()
