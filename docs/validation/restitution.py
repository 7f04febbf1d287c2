"""Normal impacts of a disc (sphere) on a rigid plane with different coefficients of restitution,
the 2D (3D) analogue of Chung & Ooi (2011, Granular Matter 13:643) test 3: the rebound speed over
the impact speed against the requested e (the line e_measured = e_requested is the reference).

The grain is a conforming peridynamic disc (R/h = 10) or sphere (R/h = 6), R = 1 mm, K = 21.6 MPa,
G = 12.96 MPa, 1200 kg/m^3, with the default contact (stiffness_factor 1), dropped at 0.05, 0.5
and 5 m/s. The contact's damping ratio is fitted to each collision's force-approach law F ~ x^p
(p measured from the springs' work), for a contact force that never pulls (the dashpot clipped
at the springs' force as the bodies part; contact/power_law_damping.hpp), and applied on the
collision's secant stiffness. At 5 m/s this soft grain is squashed by about a fifth of its
radius and its force-approach law stiffens (Hertz-like), which the fit follows.

Run: python docs/validation/restitution.py [--smoke]; writes docs/validation/restitution.png and
prints the table.
"""

from __future__ import annotations

import argparse

import numpy as np
from oblique_impact import run_through_wall_impact, save

import granulate as gr

SOFT = gr.Material(density=1200, bulk_modulus=2.16e7, shear_modulus=1.296e7, fracture=False)
RADIUS = 1e-3
NODES_ACROSS_RADIUS = {2: 10, 3: 6}


def rebound(
    dimension: int, restitution: float, speed: float, nodes_across_radius: float | None = None
) -> float:
    """Measured e of one normal impact on a plane: rebound speed of the centre of mass over the
    impact speed, 50 steps after the last node left the plane. The grain has R/h =
    `nodes_across_radius` (default NODES_ACROSS_RADIUS)."""
    h = RADIUS / (nodes_across_radius or NODES_ACROSS_RADIUS[dimension])
    sim = gr.Simulation(dimension)
    sim.contact = gr.Contact(restitution=restitution)
    centre = (0.0, RADIUS + 0.6 * h, 0.0)[:dimension]
    shape = gr.Disc(centre, RADIUS) if dimension == 2 else gr.Sphere(centre, RADIUS)
    velocity = (0.0, -speed, 0.0)[:dimension]
    body = sim.add_body(shape, SOFT, h, discretization="conforming", velocity=velocity)
    sim.add_wall(gr.Plane((0.0,) * dimension, (0.0, 1.0, 0.0)[:dimension]), name="floor")
    run_through_wall_impact(sim)
    nodes = body.nodes
    return float(np.average(sim.velocities[nodes, 1], weights=sim.volumes[nodes]) / speed)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true")
    args = parser.parse_args()
    requested = [0.1, 0.5, 0.9] if args.smoke else [round(0.1 * k, 1) for k in range(1, 11)]
    speeds = [0.05, 0.5, 5.0]
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(9, 4), sharey=True)
    print("d  v [m/s]  " + "  ".join(f"{e:5.2f}" for e in requested))
    for ax, dimension in zip(axes, (2, 3), strict=True):
        for speed in speeds:
            measured = [rebound(dimension, e, speed) for e in requested]
            print(f"{dimension}  {speed:7.2f}  " + "  ".join(f"{e:5.3f}" for e in measured))
            ax.plot(requested, measured, "o-", ms=4, lw=0.8, label=f"v = {speed} m/s")
        line = np.array([0.0, 1.0])
        ax.plot(line, line, "k-", lw=0.8, label="requested")
        ax.fill_between(line, line - 0.05, line + 0.05, color="0.85", label="within 0.05")
        shape = "disc, R/h = 10" if dimension == 2 else "sphere, R/h = 6"
        ax.set_title(f"{dimension}D {shape}", fontsize=9)
        ax.set_xlabel("requested e")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    axes[0].set_ylabel("measured e (rebound / impact speed)")
    save(fig, "Normal impact on a rigid plane (Chung & Ooi test 3 analogue)", "restitution.png")


if __name__ == "__main__":
    main()
