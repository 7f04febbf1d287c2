"""Whether the Verlet skin changes any result: every case file, the compression_small bench case
and every PeriDEM deck, run N steps with the default skin and with the skin at 1/1000 of it (a
list search nearly every step); positions and velocities must agree bit for bit.

    python benchmarks/skin_independence.py [--steps 2000]   # about 35 s on one thread

The skin decides only when the contact lists are searched again. A result that depends on it
depends on bookkeeping, and a distributed run, whose ranks search their own lists when their
own nodes have moved, could not reproduce the serial one (docs/parallel.md). Cases without
contact (one body) are skipped. tests/test_determinism.py checks shattering discs the same way.
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import numpy as np

from granulate.case import load_case

ROOT = Path(__file__).resolve().parent.parent
DECKS = ROOT.parent / "shared" / "peridem" / "decks"


def run(path: Path, compat: bool, skin_scale: float, steps: int):
    sim = load_case(path, peridem_compat=compat).build(outputs=False)
    sim.run(1)  # builds the lists with the default skin
    if skin_scale != 1:
        sim.set_neighbor_skin(sim.core.checkpoint()["contact_skin"] * skin_scale)
    sim.run(steps)
    return np.array(sim.core.positions), np.array(sim.core.velocities), sim


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=2000)
    args = parser.parse_args()
    warnings.simplefilter("ignore")  # the decks' notes and contact warnings
    cases = sorted((ROOT / "examples" / "cases").glob("*.yaml"))
    cases.append(ROOT / "src" / "granulate" / "bench_cases" / "compression_small" / "case.yaml")
    decks = [d for d in sorted(DECKS.glob("*/input_0.yaml")) if "n500" not in str(d)]
    runs = [(c, False) for c in cases] + [(d, c) for c in (False, True) for d in decks]
    for path, compat in runs:
        start = time.perf_counter()
        x, v, default = run(path, compat, 1.0, args.steps)
        if default.core.contact_statistics.rebuilds == 0:
            continue  # no contact
        x_small, v_small, small = run(path, compat, 1e-3, args.steps)
        same = np.array_equal(x, x_small) and np.array_equal(v, v_small)
        print(
            f"{path.parent.name}/{path.name}{' --peridem-compat' if compat else ''}: "
            f"{'identical' if same else f'DIFFER by {np.abs(x - x_small).max():.3g} m'}; "
            f"searches {default.core.contact_statistics.rebuilds} and "
            f"{small.core.contact_statistics.rebuilds}, {default.broken_bonds()} bonds broken, "
            f"{time.perf_counter() - start:.0f} s",
            flush=True,
        )


if __name__ == "__main__":
    main()
