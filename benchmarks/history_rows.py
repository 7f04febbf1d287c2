"""What a history row costs rank 0 of a distributed run: the gathering of the state into its
simulation (DistributedRun.collect, with the ranks' measures of their grains) and the row's
sections (energies, breakage, granular measures) computed from it, at one fixed state.

    mpiexec -n 2 python benchmarks/history_rows.py CASE [--peridem-compat] [--steps 10]
        [--repeats 40]

CASE is a case file or a PeriDEM deck (the paper's n500_circ_hex deck, say). The run takes
`--steps` steps, then gathers and computes the row `--repeats` times, the ranks starting each
together (a barrier); rank 0 prints the medians in ms. One thread per rank unless
OMP_NUM_THREADS says otherwise. Run two installs alternating for an A/B.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
from mpi4py import MPI

from granulate.case import load_case
from granulate.parallel import DistributedRun
from granulate.writers import history_sections
from granulate.writers.step_data import StepData

SECTIONS = (
    history_sections.Energies(),
    history_sections.Breakage(),
    history_sections.GranularMeasures(),
)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("case", type=Path)
    parser.add_argument("--peridem-compat", action="store_true")
    parser.add_argument("--steps", type=int, default=10)
    parser.add_argument("--repeats", type=int, default=40)
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    sim = load_case(args.case, peridem_compat=args.peridem_compat).build(outputs=False)
    run = DistributedRun(sim, comm)
    run.run(args.steps)
    run.collect()  # rank 0 builds its whole simulation once, untimed
    outputs = SimpleNamespace(tracked=())
    gathering, rows = [], []
    for _ in range(args.repeats):
        comm.Barrier()
        start = time.perf_counter()
        run.collect()
        gathered = time.perf_counter()
        if comm.Get_rank() == 0:
            data = StepData.of(sim)
            for section in SECTIONS:
                section.columns(data, outputs)
        gathering.append(gathered - start)
        rows.append(time.perf_counter() - gathered)
    if comm.Get_rank() == 0:
        together = np.add(gathering, rows)
        print(
            f"{comm.Get_size()} ranks, {sim.node_count:,} nodes: rank 0 per row "
            f"{1e3 * np.median(together):.1f} ms (gathering {1e3 * np.median(gathering):.1f} "
            f"ms, the row {1e3 * np.median(rows):.1f} ms), median of {args.repeats}"
        )


if __name__ == "__main__":
    main()
