"""The weights of granulate/parallel/work_load.py: per-step seconds of serial runs on one
thread against their nodes n, intact bond copies c and contact list entries e, fitted as
T = a n + b c + d e (least squares of the relative misses).

    python benchmarks/work_weights.py [--dimension 2|3]

2D: granulate.bench_ranks' pile, drum, fine2d and shatter, and the pile's grains far apart
(no contact), resting barely apart (listed, not pressed), fine2d without contact and with a
horizon of 4.5 mesh sizes. 3D: pile3d, its spheres far apart, without contact, with a horizon
of 4 mesh sizes, and pressed 1.95 R apart. Prints each case's counts and seconds, the fit in
nodes' work (b / a, d / a) and each case's miss.
"""

from __future__ import annotations

import argparse
import time
import warnings
from collections.abc import Callable

import numpy as np

import granulate as gr
from granulate import bench_ranks as cases

R = cases.RADIUS


def lattice(grains: int, dimension: int, spacing: float, material: gr.Material, h: float):
    """Discs (spheres) of radius 0.99 R, in rows of 20 (layers of 10 x 10), `spacing` apart,
    on a floor."""
    sim = gr.Simulation(dimension, gravity=(0, -9.81, 0))
    sim.contact = gr.Contact(restitution=0.5, friction=0.5)
    for k in range(grains):
        if dimension == 2:
            row, column = divmod(k, 20)
            centre = (spacing * (column + 0.5 * (row % 2)), spacing * np.sqrt(3) / 2 * row)
            sim.add_body(gr.Disc(centre, 0.99 * R), material, h)
        else:
            layer, rest = divmod(k, 100)
            row, column = divmod(rest, 10)
            centre = (spacing * column, spacing * layer, spacing * row)
            sim.add_body(gr.Sphere(centre, 0.99 * R), material, h)
    sim.add_wall(gr.Wall(gr.Plane((0, -0.99 * R, 0), (0, 1, 0))), name="floor")
    return sim


def without_contact(sim: gr.Simulation) -> gr.Simulation:
    sim.contact = None
    return sim


def horizon(factor: float, h: float) -> gr.Material:
    return cases.ROCK.model_copy(update={"horizon": factor * h})


CASES: dict[int, dict[str, Callable[[], gr.Simulation]]] = {
    2: {
        "pile": lambda: cases.pile(400),
        "drum": lambda: cases.drum(300),
        "fine2d": lambda: cases.fine2d(100),
        "shatter": lambda: cases.shatter(400),
        "apart": lambda: lattice(400, 2, 3 * R, cases.ROCK, R / 5),
        "resting": lambda: lattice(400, 2, 2 * R, cases.ROCK, R / 5),
        "no contact": lambda: without_contact(cases.fine2d(100)),
        "wide": lambda: lattice(60, 2, 2 * R, horizon(4.5, R / 16), R / 16),
    },
    3: {
        "pile3d": lambda: cases.pile3d(200),
        "apart": lambda: lattice(200, 3, 3 * R, cases.ROCK, R / 4),
        "no contact": lambda: without_contact(cases.pile3d(200)),
        "wide": lambda: lattice(100, 3, 2 * R, horizon(4.0, R / 4), R / 4),
        "pressed": lambda: lattice(200, 3, 1.95 * R, cases.ROCK, R / 4),
    },
}


def measure(make: Callable[[], gr.Simulation], steps: int) -> tuple[int, int, int, float]:
    """n, c, e after 30 steps, and the seconds a step of the next `steps`."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sim = make()
        sim.run(30)
    nodes = np.arange(sim.node_count, dtype=np.int64)
    start = time.perf_counter()
    sim.run(steps)
    seconds = (time.perf_counter() - start) / steps
    copies = int(np.asarray(sim.core.intact_bond_copies(nodes)).sum())
    entries = int(np.asarray(sim.core.contact_list_entries(nodes)).sum())
    return sim.node_count, copies, entries, seconds


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--dimension", type=int, choices=(2, 3), default=2)
    parser.add_argument("--steps", type=int, default=60)
    arguments = parser.parse_args()
    gr.set_num_threads(1, adaptive=False)
    rows = {}
    for name, make in CASES[arguments.dimension].items():
        rows[name] = measure(make, arguments.steps)
        n, c, e, t = rows[name]
        print(f"{name:12s} n {n:7d}  c {c:9d}  e {e:8d}  {1e3 * t:8.3f} ms a step", flush=True)
    counts = np.array([row[:3] for row in rows.values()], dtype=float)
    seconds = np.array([row[3] for row in rows.values()])
    fit = np.linalg.lstsq(counts / seconds[:, None], np.ones(len(seconds)), rcond=None)[0]
    print(f"in nodes' work: a bond copy {fit[1] / fit[0]:.3f}, an entry {fit[2] / fit[0]:.3f}")
    for name, predicted in zip(rows, counts @ fit, strict=True):
        print(f"  {name:12s} the fit misses by {predicted / rows[name][3] - 1:+.1%}")


if __name__ == "__main__":
    main()
