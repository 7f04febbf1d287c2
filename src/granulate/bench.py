"""Benchmarks: ``granulate bench [--quick] [--case NAME ...] [--threads N] [--json]``.

Cases (../shared/BENCHMARKS.md gives the peers' figures):

=================  ===========================================================================
lps3d_lattice      LAMMPS' peri/lps case: 31^3 simple-cubic nodes, a = 0.5 mm, horizon 3.015 a,
                   K = 14.9 GPa, G = 14.0 GPa, rho = 2200 kg/m^3, dt = 1e-8 s, 200 steps
lps2d_square       a 316 x 316 square (99,856 nodes), horizon 3h, LPS with fracture, pulled
two_particles      two discs (PeriDEM's 123-node mesh each) colliding, 20,000 steps
compression_small  PeriDEM's compression_small_set deck as a case file (1,969 nodes), 20,000 steps
compression_502    the paper's compression set-up (57,394 nodes), the first 2,000 steps
scaling            N discs settling in a box (N = 100, 1,600, 10,000): cost per node-step
vtu_1m             writing one VTU frame of a million nodes (all output fields)
crushing           six brittle discs (7,584 nodes) hitting a floor at 40 m/s and breaking,
                   3,000 steps: the cost of contact with continuous fracture
=================  ===========================================================================

Only the time loop is timed (set-up and the first force evaluation are excluded). Each case
gives: case, nodes, bonds, particles, steps, threads, seconds, node_steps_per_s,
bond_evals_per_s (bonds counted once per end, as LAMMPS does), peak_rss_mb, phases (seconds in
peridynamics, contact_search, contact_forces, walls, integration, output; wall contacts are
evaluated in the same passes as node pairs, so their time is part of contact_forces and
``walls`` is null) and memory (the core's bytes per bond and per node, against the budget of 16
bytes per bond plus 300 per node).

The case files are installed with the package (granulate/bench_cases; GRANULATE_BENCH_CASES
points elsewhere), so ``granulate bench`` runs from any folder.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from granulate.errors import InputError
from granulate.threads import get_num_threads, set_num_threads

BOND_BUDGET, NODE_BUDGET = 16, 300


def cases_folder() -> Path:
    """The benchmark case files: GRANULATE_BENCH_CASES if set, else the ones shipped in the
    package (granulate/bench_cases)."""
    chosen = os.environ.get("GRANULATE_BENCH_CASES")
    folder = Path(chosen) if chosen else Path(__file__).with_name("bench_cases")
    if not (folder / "compression_502.yaml").is_file():
        raise InputError(
            f"benchmark case files not found in {folder} (compression_502.yaml); unset "
            "GRANULATE_BENCH_CASES to use the ones installed with granulate"
        )
    return folder


def _timed(sim, steps: int, case: str, threads: int, extra: dict | None = None) -> dict:
    """Run `steps` after a first step, and report (see the module docstring)."""
    sim.run(1)  # builds the model, evaluates the first forces, writes frame 0
    live = sim.core.phase_times
    before = (live.peridynamics, live.contact, live.contact_search, live.integration, live.loading)
    output_before = sim.output_seconds
    start = time.perf_counter()
    sim.run(steps)
    seconds = time.perf_counter() - start
    phases = sim.core.phase_times
    search = phases.contact_search - before[2]
    bonds, other = sim.core.memory_bytes()
    result = {
        "case": case,
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
            "contact_search": search,
            "contact_forces": phases.contact - before[1] - search,
            "walls": None,
            "integration": phases.integration - before[3] + phases.loading - before[4],
            "output": sim.output_seconds - output_before,
        },
        "memory": {
            "core_mb": (bonds + other) / 1e6,
            "bytes_per_bond": bonds / max(sim.bond_count, 1),
            "other_bytes_per_node": other / sim.node_count,
            "within_budget": bonds + other
            <= BOND_BUDGET * sim.bond_count + NODE_BUDGET * sim.node_count,
        },
    }
    seconds_at = sim.seconds_at_threads
    if seconds_at is not None:  # the adaptive policy: run time at each thread count
        result["seconds_at_threads"] = {c: round(t, 3) for c, t in seconds_at.items()}
    result.update(extra or {})
    return result


def lps3d_lattice(quick: bool, threads: int, out: Path) -> list[dict]:
    import granulate as gr

    a = 0.5e-3
    cells = 10 if quick else 31
    material = gr.Material(
        density=2200, bulk_modulus=14.9e9, shear_modulus=14.0e9, horizon=3.015 * a, fracture=False
    )
    sim = gr.Simulation(3, dt=1e-8)
    sim.add_body(gr.Box((0, 0, 0), (cells * a,) * 3), material, a)
    sim.velocities[:] = np.random.default_rng(87287).normal(scale=1e-6, size=(sim.node_count, 3))
    return [_timed(sim, 20 if quick else 200, "lps3d_lattice", threads)]


def lps2d_square(quick: bool, threads: int, out: Path) -> list[dict]:
    import granulate as gr

    h = 1e-4
    side = 60 if quick else 316
    material = gr.Material(
        density=1200, bulk_modulus=2.16e7, shear_modulus=1.296e7, fracture_energy=50.0
    )
    sim = gr.Simulation(2)
    sim.add_body(gr.Rectangle((0, 0), (side * h, side * h)), material, h)
    sim.fix(sim.select(gr.Rectangle((-1, -1), (3 * h, 1))))
    sim.prescribe_velocity(sim.select(gr.Rectangle((side * h - 3 * h, -1), (1, 1))), (0.05, 0))
    return [_timed(sim, 20 if quick else 200, "lps2d_square", threads)]


def two_particles(quick: bool, threads: int, out: Path) -> list[dict]:
    import granulate as gr

    disc = gr.ReferenceShape.from_mesh(
        str(cases_folder() / "compression_small" / "mesh_cir_small_0.msh")
    )
    material = gr.Material(
        density=1200, bulk_modulus=2.16e7, shear_modulus=1.296e7, fracture_energy=50, horizon=6e-4
    )
    sim = gr.Simulation(2, dt=3e-7)
    sim.contact = gr.Contact(restitution=0.95)
    sim.add_particle(disc, material, position=(0, 0), velocity=(0.5, 0))
    sim.add_particle(disc, material, position=(2.3e-3, 0), velocity=(-0.5, 0))
    return [_timed(sim, 2000 if quick else 20000, "two_particles", threads)]


def crushing(quick: bool, threads: int, out: Path) -> list[dict]:
    """Brittle discs crushed on a floor: bonds break at most steps (``rebuilds`` reports how
    often the contact lists were rebuilt)."""
    import granulate as gr

    material = gr.Material(
        density=2000, youngs_modulus=1e9, poisson_ratio=0.25, fracture_energy=2.0, horizon_factor=3
    )
    sim = gr.Simulation(2, gravity=(0, -9.81))
    sim.contact = gr.Contact(restitution=0.5)
    for k in range(6):
        sim.add_body(gr.Disc((k * 2.2e-3, 1.2e-3), 1e-3), material, 0.5e-4, velocity=(0, -40.0))
    sim.add_wall(gr.Plane((0, 0), (0, 1)), name="floor")
    row = _timed(sim, 300 if quick else 3000, "crushing", threads)
    row["rebuilds"] = int(sim.core.contact_statistics.rebuilds)
    row["broken_bonds"] = int(sim.broken_bonds())
    return [row]


def _case_file(name: str, path: Path, steps: int, threads: int, out: Path) -> list[dict]:
    from granulate.case import load_case

    case = load_case(path)
    sim = case.build(output=out / name, overwrite=True)
    return [_timed(sim, steps, name, threads)]


def compression_small(quick: bool, threads: int, out: Path) -> list[dict]:
    path = cases_folder() / "compression_small" / "case.yaml"
    return _case_file("compression_small", path, 1000 if quick else 20000, threads, out)


def compression_502(quick: bool, threads: int, out: Path) -> list[dict]:
    return _case_file(
        "compression_502",
        cases_folder() / "compression_502.yaml",
        200 if quick else 2000,
        threads,
        out,
    )


def scaling(quick: bool, threads: int, out: Path) -> list[dict]:
    """N discs (52 nodes each, one shared shape) on a grid in a box, every other row thrown
    down onto the row below, under gravity, contact with restitution 0.5 and friction 0.5."""
    import granulate as gr

    rows = []
    first = None
    for count in (100, 400) if quick else (100, 1600, 10000):
        rock = gr.Material(
            density=2000, youngs_modulus=1e7, poisson_ratio=0.25, fracture_energy=10.0
        )
        disc = gr.ReferenceShape.from_shape(gr.Disc((0, 0), 1e-3), 0.25e-3)
        side = math.ceil(math.sqrt(count))
        pitch = 2.1e-3
        sim = gr.Simulation(2, gravity=(0, -9.81))
        sim.contact = gr.Contact(restitution=0.5, friction=0.5)
        for k in range(count):
            row = k // side
            sim.add_particle(
                disc,
                rock,
                position=(pitch * (k % side + 1), pitch * (row + 1)),
                rotation=0.1 * k,
                velocity=(0.0, -0.3 * (row % 2)),
            )
        sim.add_wall(gr.BoxContainer((0, 0), (pitch * (side + 1), pitch * (side + 30))), name="box")
        sim.run(200)  # into contact
        row_result = _timed(sim, 200, f"scaling_{count}", threads)
        cost = 1e9 / row_result["node_steps_per_s"]
        first = first or cost
        row_result["ns_per_node_step"] = cost
        row_result["cost_vs_smallest"] = cost / first
        rows.append(row_result)
    return rows


def vtu_1m(quick: bool, threads: int, out: Path) -> list[dict]:
    """One VTU frame with every output field of a million-node lattice with smooth fields."""
    from granulate.io import write_vtu

    side = 316 if quick else 1000
    n = side * side
    grid = (
        np.stack(np.meshgrid(np.arange(side), np.arange(side), indexing="ij"), -1).reshape(-1, 2)
        * 1e-4
    )
    points = np.zeros((n, 3))
    points[:, :2] = grid
    # Smooth fields with the round-off noise of real results (exact repeats would make zlib's
    # work unrepresentatively easy or hard).
    noise = 1 + 1e-9 * np.random.default_rng(1).standard_normal((n, 1))
    wave = np.sin(grid[:, :1] * 50) * np.cos(grid[:, 1:] * 30) * noise
    vector = np.concatenate([wave * 1e-6, wave * 2e-6, np.zeros((n, 1))], axis=1)
    fields = {
        "Displacement": vector,
        "Velocity": vector * 1e3,
        "Force_Density": vector * 1e9,
        "Force": vector * 1e1,
        "Damage": np.where(wave[:, 0] > 0.99, 0.3, 0.0),
        "Damage_Z": np.abs(wave[:, 0]) * 0.1,
        "Dilatation": wave[:, 0] * 1e-5,
        "Particle_ID": (np.arange(n) // 200).astype(np.uint32),
        "Fixity": np.zeros(n, np.uint8),
        "Nodal_Volume": np.full(n, 1e-8),
    }
    target = out / "vtu_1m.vtu"
    target.parent.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    write_vtu(target, points + vector, fields)
    seconds = time.perf_counter() - start
    size = target.stat().st_size
    target.unlink()
    return [
        {
            "case": "vtu_1m",
            "nodes": n,
            "bonds": 0,
            "particles": 0,
            "steps": 1,
            "threads": threads,
            "seconds": seconds,
            "node_steps_per_s": n / seconds,
            "bond_evals_per_s": 0.0,
            "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
            "phases": {"output": seconds},
            "file_mb": size / 1e6,
        }
    ]


CASES: dict[str, Callable[[bool, int, Path], list[dict]]] = {
    "lps3d_lattice": lps3d_lattice,
    "lps2d_square": lps2d_square,
    "two_particles": two_particles,
    "compression_small": compression_small,
    "compression_502": compression_502,
    "scaling": scaling,
    "vtu_1m": vtu_1m,
    "crushing": crushing,
}


def _row(r: dict) -> str:
    memory = r.get("memory")
    bytes_text = f"{memory['bytes_per_bond']:5.1f} B/bond" if memory and r["bonds"] else " " * 12
    return (
        f"{r['case']:<18} {r['nodes']:>9} {r['steps']:>6} {r['threads']:>3} {r['seconds']:8.2f} "
        f"{r['node_steps_per_s'] / 1e6:9.3f} {r['bond_evals_per_s'] / 1e6:9.1f} "
        f"{r['peak_rss_mb']:7.0f}  {bytes_text}"
    )


def _chosen(names: list[str] | None) -> list[str]:
    chosen = names or list(CASES)
    unknown = [n for n in chosen if n not in CASES]
    if unknown:
        raise InputError(f"unknown benchmark case(s) {unknown}; choose from {', '.join(CASES)}")
    return chosen


def main(
    names: list[str] | None, quick: bool, threads: int | None, as_json: bool, out: Path
) -> int:
    """Run the cases with a fixed thread count; print a table or JSON lines."""
    threads = threads or get_num_threads()
    set_num_threads(threads, adaptive=False)
    chosen = _chosen(names)
    if not as_json:
        print(
            f"{'case':<18} {'nodes':>9} {'steps':>6} {'thr':>3} {'seconds':>8} "
            f"{'M node-st/s':>9} {'M bond-ev/s':>9} {'RSS MB':>7}  memory"
        )
    for name in chosen:
        for result in CASES[name](quick, threads, out):
            print(json.dumps(result) if as_json else _row(result), flush=True)
    return 0


def contended(names: list[str] | None, quick: bool, as_json: bool, out: Path) -> int:
    """Run each case next to one busy process (a Python loop holding a core), with 1 thread,
    with all threads fixed, and with all threads adaptive (granulate.threads); print the rates
    and each one's ratio to the 1-thread run."""
    most = get_num_threads()
    chosen = _chosen(names)
    policies = [("1 fixed", 1, False), (f"{most} fixed", most, False)]
    policies.append((f"{most} adaptive", most, True))
    busy = subprocess.Popen([sys.executable, "-c", "while True: pass"])
    try:
        time.sleep(0.2)
        if not as_json:
            print(f"one busy process alongside; {os.cpu_count()} CPUs")
            print(
                f"{'case':<18} {'threads':<12} {'seconds':>8} {'M node-st/s':>11} {'vs 1':>6}"
                "  (adaptive: time at each count)"
            )
        for name in chosen:
            single: dict[int, float] = {}  # the 1-thread rate of each row of the case
            for label, count, adaptive in policies:
                set_num_threads(count, adaptive=adaptive)
                for k, result in enumerate(CASES[name](quick, count, out)):
                    result["thread_policy"] = label
                    rate = result["node_steps_per_s"]
                    single.setdefault(k, rate)
                    if as_json:
                        print(json.dumps(result), flush=True)
                        continue
                    at = result.get("seconds_at_threads", {})
                    print(
                        f"{result['case']:<18} {label:<12} {result['seconds']:8.2f} "
                        f"{rate / 1e6:11.3f} {rate / single[k]:6.2f}  "
                        + ", ".join(f"{t:.2f} s at {c}" for c, t in at.items() if t > 0),
                        flush=True,
                    )
    finally:
        busy.kill()
        busy.wait()
    set_num_threads(most, adaptive=False)
    return 0


def _parser() -> argparse.ArgumentParser:  # for benchmarks/*.py
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--case", action="append")
    parser.add_argument("--threads", type=int)
    parser.add_argument("--json", action="store_true")
    parser.add_argument("--out", type=Path, default=Path("out") / "bench")
    return parser
