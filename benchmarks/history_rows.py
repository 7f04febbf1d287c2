"""What a history row costs a distributed run: (a) made of what the ranks measure of their own
grains (DistributedRun.step_data: parallel/step_parts.py, no node array on rank 0), or of their
own nodes for a body cut at node level (NodeSplitRun.step_data), and (b) the whole state
gathered into rank 0's simulation (collect) and the row computed from it, as every output step
did before session 50 for grains and before session 59 for a body cut at node level, each
followed by the row's sections (energies, breakage, granular measures), at one fixed state.

    mpiexec -n 2 python benchmarks/history_rows.py CASE [--peridem-compat] [--steps 10]
        [--repeats 40]

CASE is a case file or a PeriDEM deck (the paper's n500_circ_hex deck, say), run with whole
grains per rank, or `block`, `granulate bench --ranks`' notched LPS block of 53,400 nodes, cut
at node level. The run takes
`--steps` steps, then makes the row both ways, alternating, `--repeats` times, the ranks
starting each together (a barrier); rank 0 prints the medians in ms, its resident memory
(VmRSS, MB) before the first gathering and after, and whether both rows are equal. The ranks
keep their damage and fragment labels from the first row (as a run does until a bond breaks;
a split body's labels are found at every output step) unless `--fresh` (as after bonds broke
between rows); the gathered path makes them anew each time. One thread per rank unless
OMP_NUM_THREADS says otherwise.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
from mpi4py import MPI
from process_memory import resident_mb

from granulate.bench_ranks import SPLIT_CASES
from granulate.case import load_case
from granulate.parallel import DistributedRun, NodeSplitRun
from granulate.writers import history_sections
from granulate.writers.step_data import StepData

SECTIONS = (
    history_sections.Energies(),
    history_sections.Breakage(),
    history_sections.GranularMeasures(),
)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("case", help="a case file, a PeriDEM deck or " + ", ".join(SPLIT_CASES))
    parser.add_argument("--peridem-compat", action="store_true")
    parser.add_argument("--steps", type=int, default=10)
    parser.add_argument("--repeats", type=int, default=40)
    parser.add_argument(
        "--fresh",
        action="store_true",
        help="make the ranks' damage and fragment labels anew for each row (as after bonds "
        "broke), not kept from the first",
    )
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    if args.case in SPLIT_CASES:
        sim = SPLIT_CASES[args.case](False)
        run: DistributedRun | NodeSplitRun = NodeSplitRun(sim, comm)
    else:
        sim = load_case(Path(args.case), peridem_compat=args.peridem_compat).build(outputs=False)
        run = DistributedRun(sim, comm)
    run.run(args.steps)
    outputs = SimpleNamespace(tracked=())
    measured, gathered = [], []
    rows: list[list[dict[str, float | int]]] = [[], []]
    before = resident_mb()
    for _ in range(args.repeats):
        comm.Barrier()
        if args.fresh:
            run.local.analysis.forget_fragments()
        if isinstance(run, NodeSplitRun):
            run._labels = None  # a run finds them anew at each output step
        start = time.perf_counter()
        data = run.step_data(())
        if data is not None:
            rows[0].append(row(data, outputs))
        measured.append(time.perf_counter() - start)
        comm.Barrier()
        start = time.perf_counter()
        run.collect()
        if comm.Get_rank() == 0:
            rows[1].append(row(StepData.of(sim), outputs))
        gathered.append(time.perf_counter() - start)
    if comm.Get_rank() == 0:
        print(
            f"{comm.Get_size()} ranks, {sim.node_count:,} nodes, per row (median of "
            f"{args.repeats}): from the ranks' measures {1e3 * np.median(measured):.1f} ms; "
            f"through the gathered state {1e3 * np.median(gathered):.1f} ms; rank 0 "
            f"{before:.0f} MB before the first gathering, {resident_mb():.0f} MB after; rows "
            f"equal {rows[0] == rows[1]}"
        )


def row(data: StepData, outputs: SimpleNamespace) -> dict[str, float | int]:
    """The row's sections' columns (SECTIONS)."""
    columns: dict[str, float | int] = {}
    for section in SECTIONS:
        columns.update(section.columns(data, outputs))  # type: ignore[arg-type]
    return columns


if __name__ == "__main__":
    main()
