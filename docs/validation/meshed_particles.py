"""Particles imported from meshes, whose boundary vertices lie on the surface: where they rest,
how they rebound, how far a head-on impact throws them sideways.

PeriDEM's gmsh disc (R = 1 mm, R/h = 5.8) and a tetrahedral sphere (R = 1 mm, R/h = 5.3,
tests/data/meshes): each pair of equal particles meets head-on (the second turned by 0.1 rad,
so the meshes do not mirror each other) at 0.05 and 1 m/s with requested e = 0.6 and 1; the
table gives the measured e and the largest lateral speed over the approach speed. The hexagon
of PeriDEM's decks and the sphere, dropped 0.02 h onto a floor, rest (after 5 ms, with some
viscous damping) this far from their surfaces, in mesh sizes.

    python docs/validation/meshed_particles.py
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import granulate as gr

ROOT = Path(__file__).resolve().parents[2]
MESHES = {
    2: ROOT / "tests" / "data" / "peridem" / "compression_small_set" / "mesh_cir_small_0.msh",
    3: ROOT / "tests" / "data" / "meshes" / "sphere_tet.msh",
}
HEXAGON = ROOT / "tests" / "data" / "peridem" / "compression_small_set" / "mesh_hex_small_0.msh"
SOFT = gr.Material(density=1200, bulk_modulus=2.16e7, shear_modulus=1.296e7, fracture=False)


def mean_velocity(sim: gr.Simulation, body: gr.Body) -> np.ndarray:
    nodes = body.nodes
    return np.average(sim.velocities[nodes], axis=0, weights=sim.volumes[nodes])


def head_on(dimension: int, restitution: float, speed: float) -> tuple[float, float]:
    """(e, the largest lateral speed / the approach speed) of two equal meshed particles."""
    reference = gr.ReferenceShape.from_mesh(str(MESHES[dimension]))
    sim = gr.Simulation(dimension)
    sim.contact = gr.Contact(restitution=restitution)
    zero = (0.0,) * (dimension - 2)
    turn = 0.1 if dimension == 2 else (0.0, 0.0, 0.1)
    a = sim.add_particle(reference, SOFT, position=(0, 0, *zero))
    b = sim.add_particle(
        reference, SOFT, position=(2e-3 + 1.5 * reference.mesh_size, 0, *zero), rotation=turn
    )
    sim.velocities[a.nodes, 0] = speed / 2
    sim.velocities[b.nodes, 0] = -speed / 2
    touched = False
    while not touched or sim.core.contact_statistics.node_contacts > 0:
        sim.run(20)
        touched = touched or sim.core.contact_statistics.node_contacts > 0
    sim.run(100)
    after = mean_velocity(sim, a) - mean_velocity(sim, b)
    return -after[0] / speed, float(np.abs(after[1:]).max()) / speed


def rest(mesh: Path) -> float:
    """Resting height of the centre above its height with the surface on the floor [h]."""
    reference = gr.ReferenceShape.from_mesh(str(mesh))
    d, h = reference.dimension, reference.mesh_size
    sim = gr.Simulation(d, gravity=(0, -9.81, 0)[:d], viscous_damping=30.0)
    sim.contact = gr.Contact(restitution=0.5, friction=0.3)
    lowest = -reference.positions[:, 1].min()
    body = sim.add_particle(reference, SOFT, position=(0, lowest + 0.02 * h, 0)[:d])
    sim.add_wall(gr.Plane((0, 0, 0)[:d], (0, 1, 0)[:d]), name="floor")
    sim.run(until=0.005)
    centre = np.average(sim.positions[body.nodes], axis=0, weights=sim.volumes[body.nodes])
    return (centre[1] - lowest) / h


def main() -> None:
    print(
        "rests (centre above its height on its surface): "
        f"hexagon {rest(HEXAGON):+.3f} h, sphere {rest(MESHES[3]):+.3f} h"
    )
    print("| | e = 0.6, 0.05 m/s | 1.0, 0.05 m/s | 0.6, 1 m/s | 1.0, 1 m/s |")
    print("|---|---|---|---|---|")
    for dimension, name in ((2, "gmsh disc"), (3, "tetrahedral sphere")):
        cells = []
        for speed in (0.05, 1.0):
            for restitution in (0.6, 1.0):
                e, lateral = head_on(dimension, restitution, speed)
                cells.append(f"{e:.3f} ({100 * lateral:.1f} %)")
        print(f"| {name} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
