"""Peridynamics kernel benchmarks: node-steps/s and bond-evaluations/s.

    python benchmarks/peridynamics.py                      # both cases, table
    python benchmarks/peridynamics.py --case lps3d_lattice --threads 1 --json
    python benchmarks/peridynamics.py --quick              # small sizes, for a smoke check

Cases (see ../shared/BENCHMARKS.md):
  lps3d_lattice  LAMMPS' peri/lps case: simple-cubic lattice of 31^3 nodes, spacing a = 0.5 mm,
                 horizon 3.015 a, K = 14.9 GPa, G = 14.0 GPa, rho = 2200 kg/m^3, dt = 1e-8 s,
                 200 steps, no breakage; bonds counted once per end, as LAMMPS counts them.
  lps2d_square   a 2D square of 316 x 316 = 99,856 nodes, horizon 3h, LPS with fracture,
                 left edge held, right edge pulled slowly (no contact).

Only the time loop is timed (set-up and the first force evaluation are excluded). One JSON
object per line with --json: case, nodes, bonds, particles, steps, threads, seconds,
node_steps_per_s, bond_evals_per_s, peak_rss_mb, phases.
"""

from __future__ import annotations

import argparse
import json
import resource
import time

import numpy as np

import granulate as gr


def lps3d_lattice(quick: bool) -> tuple[gr.Simulation, int]:
    a = 0.5e-3
    cells = 10 if quick else 31
    material = gr.Material(
        density=2200, bulk_modulus=14.9e9, shear_modulus=14.0e9, horizon=3.015 * a, fracture=False
    )
    sim = gr.Simulation(3, dt=1e-8)
    sim.add_body(gr.Box((0, 0, 0), (cells * a,) * 3), material, a)
    rng = np.random.default_rng(87287)
    sim.velocities[:] = rng.normal(scale=1e-6, size=(sim.node_count, 3))
    return sim, 20 if quick else 200


def lps2d_square(quick: bool) -> tuple[gr.Simulation, int]:
    h = 1e-4
    side = 60 if quick else 316
    material = gr.Material(
        density=1200, bulk_modulus=2.16e7, shear_modulus=1.296e7, fracture_energy=50.0
    )
    sim = gr.Simulation(2)
    sim.add_body(gr.Rectangle((0, 0), (side * h, side * h)), material, h)
    sim.fix(sim.select(gr.Rectangle((-1, -1), (3 * h, 1))))
    sim.prescribe_velocity(sim.select(gr.Rectangle((side * h - 3 * h, -1), (1, 1))), (0.05, 0))
    return sim, 20 if quick else 200


CASES = {"lps3d_lattice": lps3d_lattice, "lps2d_square": lps2d_square}


def measure(name: str, quick: bool, threads: int) -> dict[str, object]:
    gr.set_num_threads(threads)
    sim, steps = CASES[name](quick)
    sim.run(1)  # builds the model and evaluates the first forces: not part of the loop time
    phases_before = sim.core.phase_times
    before = (phases_before.peridynamics, phases_before.integration, phases_before.loading)
    start = time.perf_counter()
    sim.run(steps)
    seconds = time.perf_counter() - start
    phases = sim.core.phase_times
    return {
        "case": name,
        "nodes": sim.node_count,
        "bonds": sim.bond_count,
        "particles": len(sim.bodies),
        "steps": steps,
        "threads": threads,
        "seconds": seconds,
        "node_steps_per_s": sim.node_count * steps / seconds,
        "bond_evals_per_s": sim.bond_count * steps / seconds,
        "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
        "phases": {
            "peridynamics": phases.peridynamics - before[0],
            "integration": phases.integration - before[1],
            "loading": phases.loading - before[2],
        },
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", action="append", choices=sorted(CASES), help="case (repeatable)")
    parser.add_argument("--threads", type=int, default=gr.get_num_threads())
    parser.add_argument("--quick", action="store_true", help="small sizes")
    parser.add_argument("--json", action="store_true", help="one JSON object per line")
    args = parser.parse_args()
    for name in args.case or sorted(CASES):
        result = measure(name, args.quick, args.threads)
        if args.json:
            print(json.dumps(result), flush=True)
        else:
            print(
                f"{result['case']:>14}  {result['nodes']:>8} nodes  {result['bonds']:>10} bonds  "
                f"{result['steps']:>4} steps  {result['threads']} thr  {result['seconds']:7.2f} s  "
                f"{result['node_steps_per_s'] / 1e6:7.3f} M node-steps/s  "
                f"{result['bond_evals_per_s'] / 1e6:7.1f} M bond-evals/s  "
                f"peak RSS {result['peak_rss_mb']:.0f} MB",
                flush=True,
            )


if __name__ == "__main__":
    main()
