"""Per-rank speed and communication share of one body cut at node level
(granulate.parallel.node_split): the same as ``granulate bench --ranks --case block``
(granulate/bench_ranks.py describes the case and the table): a notched LPS block of glass,
53,400 nodes, stretched until it cracks, its nodes dealt to the ranks.

    mpiexec -n K python benchmarks/node_split.py [--steps S] [--threads T] [--json]

One thread per rank unless --threads. On 2 cores, K > 2 oversubscribes: correctness, not speed.
"""

from __future__ import annotations

import argparse

from mpi4py import MPI

from granulate import bench_ranks
from granulate.threads import set_num_threads


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--steps", type=int, default=100)
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--json", action="store_true")
    arguments = parser.parse_args()
    set_num_threads(arguments.threads, adaptive=False)
    bench_ranks.main(
        MPI.COMM_WORLD, "block", None, arguments.steps, 0, quick=False, as_json=arguments.json
    )


if __name__ == "__main__":
    main()
