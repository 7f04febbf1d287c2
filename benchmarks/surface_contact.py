"""The cost of the surface contact law against the node-sphere law, side by side.

    python benchmarks/surface_contact.py               # both laws, alternating, 2 rounds
    python benchmarks/surface_contact.py --rounds 3 --json

Cases: `compression_small` (PeriDEM's compression_small_set as a case file: 15 meshed grains
and two meshed walls, 1,969 nodes, 20,000 steps) and `discs` (400 lattice discs of 52 nodes
each thrown onto each other in a box, 2,000 steps; the `scaling` bench case's set-up). Each is
run with pair_law "granulate" and "surface" in turn, `rounds` times, and the seconds of the
contact phases (search, forces), the list entries and the memory per node are printed.
"""

from __future__ import annotations

import argparse
import copy
import json
import tempfile
from pathlib import Path

import granulate as gr
from granulate import bench
from granulate.case import parse_case
from granulate.yaml_input import load_yaml


def compression_small(law: str, out: Path) -> gr.Simulation:
    path = bench.cases_folder() / "compression_small" / "case.yaml"
    data = load_yaml(path.read_text(), path)
    data = copy.deepcopy(data)
    data["contact"]["pair_law"] = law
    for pair in data.get("contact_pairs", []):
        if pair.get("contact") is not None:
            pair["contact"]["pair_law"] = law
    case = parse_case(__import__("yaml").safe_dump(data), path)
    return case.build(output=out / f"compression_{law}", overwrite=True)


def discs(law: str, out: Path) -> gr.Simulation:
    rock = gr.Material(density=2000, youngs_modulus=1e7, poisson_ratio=0.25, fracture_energy=10.0)
    sim = gr.Simulation(2, gravity=(0, -9.81))
    sim.contact = gr.Contact(restitution=0.5, friction=0.5, pair_law=law)
    disc = gr.ReferenceShape.from_shape(gr.Disc((0, 0), 1e-3), 0.25e-3, centered=True)
    side = 20
    for row in range(side):
        for column in range(side):
            x, y = 2.5e-3 * column + 1.5e-3, 2.5e-3 * row + 1.5e-3
            speed = -1.0 if row % 2 else 0.0
            sim.add_particle(
                disc, rock, position=(x, y), velocity=(0, speed), rotation=0.37 * row + column
            )
    sim.add_wall(
        gr.BoxContainer((0, 0), (2.5e-3 * side + 0.5e-3, 2.5e-3 * side + 10e-3)), name="box"
    )
    sim.output(out / f"discs_{law}", every=10**9, overwrite=True)
    return sim


CASES = {"compression_small": (compression_small, 20000), "discs": (discs, 2000)}


def run(case: str, law: str, out: Path) -> dict:
    make, steps = CASES[case]
    sim = make(law, out)
    result = bench._timed(sim, steps, f"{case}/{law}", gr.get_num_threads())
    result["list_entries"] = int(sim.core.contact_statistics.list_entries)
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--case", action="append", choices=sorted(CASES))
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    cases = args.case or sorted(CASES)
    with tempfile.TemporaryDirectory() as scratch:
        for case in cases:
            for _ in range(args.rounds):
                for law in ("granulate", "surface"):
                    r = run(case, law, Path(scratch))
                    if args.json:
                        print(json.dumps(r))
                        continue
                    p = r["phases"]
                    print(
                        f"{r['case']:28s} search {p['contact_search']:6.2f} s  forces "
                        f"{p['contact_forces']:6.2f} s  peridynamics {p['peridynamics']:6.2f} s  "
                        f"entries {r['list_entries']:7d}  "
                        f"{r['memory']['other_bytes_per_node']:6.1f} B/node",
                        flush=True,
                    )


if __name__ == "__main__":
    main()
