"""What a stiffer contact spring costs in time steps: the stable estimate of two grains of the
compression example's material (K = 21.6 MPa, rho = 1200 kg/m^3, horizon 3 h) for several
stiffness_factor values, as the number of steps relative to the default.

    python benchmarks/contact_time_step.py   # a few seconds

2D: two discs of radius 1 mm at h = 0.2 mm (R/h = 5); 3D: two spheres at R/h = 6. The ratio
does not depend on K or the density (both the bonds' and the contact's bounds scale alike), only
on how the contact spring compares with a node's bonds. The figures back ARCHITECTURE.md,
"Choosing kn".
"""

from __future__ import annotations

import granulate as gr

FACTORS = (1.0, 2.0, 4.0, 10.0, 100.0)
RADIUS = 1e-3


def stable_dt(dim: int, stiffness_factor: float) -> float:
    h = 0.2e-3 if dim == 2 else RADIUS / 6
    material = gr.Material(
        density=1200,
        bulk_modulus=2.16e7,
        shear_modulus=1.296e7,
        fracture_energy=50,
        horizon=3 * h,
    )
    sim = gr.Simulation(dim)
    sim.contact = gr.Contact(stiffness_factor=stiffness_factor)
    for x in (0.0, 2.2 * RADIUS):
        shape = gr.Disc((x, 0), RADIUS) if dim == 2 else gr.Sphere((x, 0, 0), RADIUS)
        sim.add_body(shape, material, h)
    return sim.stable_dt


def main() -> None:
    print("stiffness_factor " + " ".join(f"{f:>8g}" for f in FACTORS))
    for dim in (2, 3):
        dts = [stable_dt(dim, f) for f in FACTORS]
        print(f"{dim}D stable dt [s] " + " ".join(f"{dt:8.3g}" for dt in dts))
        print(f"{dim}D steps x       " + " ".join(f"{dts[0] / dt:8.2f}" for dt in dts))


if __name__ == "__main__":
    main()
