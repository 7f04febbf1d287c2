"""Elastic normal impacts against Hertz's theory: a sphere on a rigid plane, the analogue of Chung
& Ooi (2011, Granular Matter 13:643) test 2, and two identical spheres head-on, their test 1.
Hertz: m* d'' = -4/3 E* sqrt(R*) d^1.5 (d(0) = 0, d'(0) = v, the approach speed), integrated
here with fourth-order Runge-Kutta; against a rigid plane m* = m, R* = R, E* = E / (1 - nu^2);
between two equal spheres m* = m / 2, R* = R / 2, E* = E / (2 (1 - nu^2)). Its peak force and
duration are F_max = 4/3 E* sqrt(R*) d_max^1.5, d_max = (15 m* v^2 / (16 E* sqrt(R*)))^(2/5)
and t_c = 2.87 (m*^2 / (R* E*^2 v))^(1/5).

The grains are conforming peridynamic spheres (R = 1 mm, E = 30 MPa, nu = 0.25, 1200 kg/m^3)
with the contact stiff against them (stiffness_factor 100, see ARCHITECTURE.md, "Choosing kn").
The force between two spheres is the rate of change of one sphere's momentum.

Run: python docs/validation/normal_impact.py [--smoke]; writes docs/validation/normal_impact_3d.png
(the plane) and docs/validation/normal_impact_pair_3d.png (two spheres) and prints the tables.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import granulate as gr

E, NU, RADIUS, DENSITY = 3e7, 0.25, 1e-3, 1200.0
E_STAR = E / (1 - NU**2)


def simulate(nodes_across_radius: int, speed: float, stiffness_factor: float = 100.0) -> dict:
    """The plane's force against time during one impact, and the rebound speed."""
    h = RADIUS / nodes_across_radius
    sim = gr.Simulation(3)
    sim.contact = gr.Contact(restitution=1.0, stiffness_factor=stiffness_factor)
    grain = gr.Material(density=DENSITY, youngs_modulus=E, poisson_ratio=NU, fracture=False)
    sim.add_body(
        gr.Sphere((0, RADIUS + 0.3 * h, 0), RADIUS),
        grain,
        h,
        discretization="conforming",
        velocity=(0, -speed, 0),
    )
    sim.add_wall(gr.Plane((0, 0, 0), (0, 1, 0)), name="floor")
    mass = float(np.sum(sim.volumes) * DENSITY)
    times, forces = [], []
    while True:
        sim.run(2)
        times.append(sim.time)
        forces.append(-sim.wall_reactions()["floor"][1])
        if max(forces) > 0 and sim.core.contact_statistics.wall_contacts == 0:
            break
    t, f = np.array(times), np.array(forces)
    touching = t[f > 0]
    rebound = float(np.average(sim.velocities[:, 1], weights=sim.volumes))
    return {
        "time": t - touching[0],
        "force": f,
        "duration": float(touching[-1] - touching[0]),
        "peak": float(f.max()),
        "restitution": rebound / speed,
        "mass": mass,
    }


def simulate_pair(nodes_across_radius: int, speed: float, stiffness_factor: float = 100.0) -> dict:
    """Two equal spheres meeting head-on at approach speed `speed`: the force between them
    against time (one sphere's momentum change per step), and the restitution."""
    h = RADIUS / nodes_across_radius
    sim = gr.Simulation(3)
    sim.contact = gr.Contact(restitution=1.0, stiffness_factor=stiffness_factor)
    grain = gr.Material(density=DENSITY, youngs_modulus=E, poisson_ratio=NU, fracture=False)
    bodies = [
        sim.add_body(
            gr.Sphere((side * (RADIUS + 0.3 * h), 0, 0), RADIUS),
            grain,
            h,
            discretization="conforming",
            velocity=(-side * speed / 2, 0, 0),
        )
        for side in (-1, 1)
    ]
    first = bodies[0].nodes
    masses = sim.volumes[first] * DENSITY

    def momentum() -> float:
        return float(masses @ sim.velocities[first, 0])

    times, forces, touching = [], [], []
    before = momentum()
    while True:
        sim.run(2)
        now = momentum()
        times.append(sim.time)
        forces.append(-(now - before) / (2 * sim.dt))  # the push on the first sphere, along -x
        before = now
        touching.append(sim.core.contact_statistics.node_contacts > 0)
        if any(touching) and not touching[-1]:
            break
    t, f, on = np.array(times), np.array(forces), np.array(touching)
    start, end = t[on][0], t[on][-1]
    rebound = float(np.average(sim.velocities[first, 0], weights=sim.volumes[first]))
    return {
        "time": t - start,
        "force": f,
        "duration": float(end - start),
        "peak": float(f.max()),
        "restitution": -2 * rebound / speed,
        "mass": float(np.sum(masses)),
    }


def hertz(mass: float, speed: float, *, pair: bool = False) -> dict:
    """Hertz's force against time (RK4 on the approach), peak force and duration; `pair`: two
    equal spheres of mass `mass` (else one on a rigid plane)."""
    radius, modulus = (RADIUS / 2, E_STAR / 2) if pair else (RADIUS, E_STAR)
    mass = mass / 2 if pair else mass
    k = 4 / 3 * modulus * np.sqrt(radius)
    duration = 2.87 * (mass**2 / (radius * modulus**2 * speed)) ** 0.2
    dt = duration / 4000
    d, v, t = 0.0, speed, 0.0
    times, forces = [0.0], [0.0]

    def acceleration(x: float) -> float:
        return -k * max(x, 0.0) ** 1.5 / mass

    while d >= 0:
        k1v, k1d = acceleration(d), v
        k2v, k2d = acceleration(d + 0.5 * dt * k1d), v + 0.5 * dt * k1v
        k3v, k3d = acceleration(d + 0.5 * dt * k2d), v + 0.5 * dt * k2v
        k4v, k4d = acceleration(d + dt * k3d), v + dt * k3v
        d += dt / 6 * (k1d + 2 * k2d + 2 * k3d + k4d)
        v += dt / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
        t += dt
        times.append(t)
        forces.append(k * max(d, 0.0) ** 1.5)
    peak_approach = (15 * mass * speed**2 / (16 * modulus * np.sqrt(radius))) ** 0.4
    return {
        "time": np.array(times),
        "force": np.array(forces),
        "duration": duration,
        "peak": k * peak_approach**1.5,
        "contact_radius": float(np.sqrt(radius * peak_approach)),
    }


def figure(pair: bool, speeds: list[float]) -> None:
    """One impact per speed against Hertz: print the table and write the figure."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 4))
    print("two spheres" if pair else "sphere on a plane")
    print("v [m/s]  R/h  a/h   F_max/Hertz  t_c/Hertz  e")
    for speed in speeds:
        run = simulate_pair(8, speed) if pair else simulate(8, speed)
        theory = hertz(run["mass"], speed, pair=pair)
        a_over_h = theory["contact_radius"] / (RADIUS / 8)
        print(
            f"{speed:7.1f}  8  {a_over_h:5.2f}  {run['peak'] / theory['peak']:11.3f}  "
            f"{run['duration'] / theory['duration']:9.3f}  {run['restitution']:.3f}"
        )
        (line,) = ax.plot(theory["time"] * 1e6, theory["force"], "-", lw=1)
        ax.plot(
            run["time"] * 1e6,
            run["force"],
            ".",
            ms=3,
            color=line.get_color(),
            label=f"v = {speed} m/s (line: Hertz)",
        )
    ax.set_xlim(left=-5)
    ax.set_xlabel("time since first touch [us]")
    ax.set_ylabel("force between the spheres [N]" if pair else "force on the plane [N]")
    what = (
        "Two equal spheres head-on (Chung & Ooi test 1 analogue)"
        if pair
        else "Sphere on a rigid plane (Chung & Ooi test 2 analogue)"
    )
    ax.set_title(f"{what}: R/h = 8, stiffness_factor 100", fontsize=9)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    out = Path(__file__).with_name("normal_impact_pair_3d.png" if pair else "normal_impact_3d.png")
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true")
    args = parser.parse_args()
    speeds = [5.0] if args.smoke else [2.0, 5.0, 10.0]
    figure(False, speeds)
    figure(True, speeds)


if __name__ == "__main__":
    main()
