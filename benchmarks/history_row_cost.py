"""What a history row costs a serial run, against the steps between rows: the row's measures
(StepData.of: energies, damage, fragments, particles, contacts) and its sections, made every
`--every` steps of a case as `granulate run` makes them.

    python benchmarks/history_row_cost.py CASE [--peridem-compat] [--every 15] [--rows 30]

CASE is a case file or a PeriDEM deck (the paper's n500_circ_hex deck writes a row every 15
steps). Prints the median of the rows and of the steps between them [ms], and the rows' share
of such a run. One thread unless OMP_NUM_THREADS says otherwise.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from granulate import threads
from granulate.case import load_case
from granulate.writers import history_sections
from granulate.writers.step_data import StepData

SECTIONS = (
    history_sections.Energies(),
    history_sections.Breakage(),
    history_sections.GranularMeasures(),
    history_sections.WallLoads(),
)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("case", type=Path)
    parser.add_argument("--peridem-compat", action="store_true")
    parser.add_argument("--every", type=int, default=15)
    parser.add_argument("--rows", type=int, default=30)
    args = parser.parse_args()
    if "OMP_NUM_THREADS" not in os.environ:
        threads.set_num_threads(1, adaptive=False)
    sim = load_case(args.case, peridem_compat=args.peridem_compat).build(outputs=False)
    outputs = SimpleNamespace(tracked=(), track_areas={})
    sim.run(args.every)
    rows, steps = [], []
    for _ in range(args.rows):
        start = time.perf_counter()
        sim.run(args.every)
        stepped = time.perf_counter()
        data = StepData.of(sim)
        for section in SECTIONS:
            section.columns(data, outputs)  # type: ignore[arg-type]
        rows.append(time.perf_counter() - stepped)
        steps.append(stepped - start)
    row, between = float(np.median(rows)), float(np.median(steps))
    print(
        f"{sim.node_count} nodes: a history row {1e3 * row:.1f} ms, {args.every} steps "
        f"{1e3 * between:.1f} ms; rows {100 * row / (row + between):.1f} % of the run"
    )


if __name__ == "__main__":
    main()
