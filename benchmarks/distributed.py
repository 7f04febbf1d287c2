"""Per-rank speed and communication share of a distributed run (granulate.parallel): the same
as ``granulate bench --ranks`` (granulate/bench_ranks.py describes the cases and the table).

    mpiexec -n K python benchmarks/distributed.py [--case pile|drum|pile3d] [--grains N]
                                                  [--steps S] [--collect-every N] [--json]

The default case is pile here (pile3d for the command), as the measurements in
docs/parallel.md were made; one thread per rank unless --threads.
"""

from __future__ import annotations

import argparse

from mpi4py import MPI

from granulate import bench_ranks
from granulate.threads import set_num_threads


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--case", choices=list(bench_ranks.CASES), default="pile")
    parser.add_argument("--grains", type=int, default=None)
    parser.add_argument("--steps", type=int, default=300)
    parser.add_argument("--collect-every", type=int, default=0, help="steps (0: never)")
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--json", action="store_true")
    arguments = parser.parse_args()
    set_num_threads(arguments.threads, adaptive=False)
    bench_ranks.main(
        MPI.COMM_WORLD,
        arguments.case,
        arguments.grains,
        arguments.steps,
        arguments.collect_every,
        quick=False,
        as_json=arguments.json,
    )


if __name__ == "__main__":
    main()
