"""What a stop check costs a distributed run (issue 17): the built-in criteria read the ranks'
measures, one reduction each (granulate.parallel.run_measures), where they used to read rank 0's
simulation after every rank sent it its whole state (DistributedRun.collect).

    mpiexec -n K python benchmarks/stop_checks.py [--grains G] [--checks C]

The case is `granulate bench --ranks`' pile3d (G grains, one thread per rank), stepped 5 steps.
Rank 0 prints, per check (the mean of C, after one untimed), the seconds of:
- the ranks' measures: every built-in criterion (kinetic energy, farthest node, broken bonds,
  particles that lost every bond, a wall's displacement) checked on every rank;
- the whole state on rank 0: collect(measures=False), then the same criteria on rank 0's
  simulation, as every check did before; rank 0's resident memory after it (VmRSS, MB) beside
  its memory before the first one;
and the step's seconds, for scale. Both give the same values (printed).
"""

from __future__ import annotations

import argparse

from mpi4py import MPI
from pile_ranks import mean_seconds, stepped_pile
from process_memory import resident_mb

from granulate.parallel import DistributedRun

CRITERIA = (
    "kinetic_energy",
    "farthest_node_distance",
    "broken_bonds",
    "fully_broken_particles",
)


def measured(run: DistributedRun) -> tuple[float, ...]:
    """Every built-in criterion's measure, from the ranks' measures (every rank together)."""
    measures = run.measures()
    return (*(getattr(measures, name)() for name in CRITERIA), measures.wall_displacement("floor"))


def gathered(run: DistributedRun, comm: MPI.Comm) -> tuple[float, ...] | None:
    """The same measures of rank 0's simulation after the ranks sent it the whole state."""
    run.collect(measures=False)
    if comm.Get_rank() != 0:
        return None
    sim = run._sim
    return (*(getattr(sim, name)() for name in CRITERIA), sim.wall_displacement("floor"))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--grains", type=int, default=1000)
    parser.add_argument("--checks", type=int, default=5)
    arguments = parser.parse_args()
    comm = MPI.COMM_WORLD
    run = stepped_pile(arguments.grains, 5, comm)
    step = mean_seconds(lambda: run.run(1), 5, comm)
    before = resident_mb()
    ours = measured(run)
    whole = gathered(run, comm)  # rank 0 builds its whole simulation here, untimed
    after = resident_mb()
    by_ranks = mean_seconds(lambda: measured(run), arguments.checks, comm)
    on_root = mean_seconds(lambda: gathered(run, comm), arguments.checks, comm)
    nodes = comm.reduce(run.owned_node_count, root=0)
    if comm.Get_rank() != 0:
        return
    print(f"pile3d, {arguments.grains} grains, {nodes:,} nodes on {comm.Get_size()} ranks")
    print(f"a step: {step:.4f} s")
    print(f"a check from the ranks' measures: {by_ranks:.4f} s")
    print(
        f"a check on rank 0's whole state: {on_root:.4f} s; rank 0 {before:.0f} MB before its "
        f"first, {after:.0f} MB after"
    )
    print(f"same values: {ours == whole} {dict(zip(CRITERIA, ours, strict=False))}")


if __name__ == "__main__":
    main()
