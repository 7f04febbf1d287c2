"""A body split at node level on the ranks of MPI.COMM_WORLD (granulate.parallel.node_split)
against the serial run on rank 0: prints the largest difference of every node's position,
velocity, force and dilatation, the bonds broken, each rank's halo, and whether the fragment
labels the ranks find together and the output step made of the ranks' measures
(NodeSplitRun.step_data: totals, the body tracked, fragment and particle tables, stresses)
are the serial run's bit for bit.

    mpiexec -n K python tests/mpi_split_check.py SHAPE MODEL STEPS

SHAPE and MODEL as tests/assemblies.py's `pulled` takes them (plate, strip or block; lps
or pmb)."""

from __future__ import annotations

import sys

import numpy as np
from mpi4py import MPI

from assemblies import pulled
from granulate.parallel.node_split import NodeSplitRun
from granulate.writers.step_data import StepData
from rank_zero import wait_asleep

FIELDS = ("positions", "velocities", "forces", "dilatation")


def main() -> int:
    shape, model, steps = sys.argv[1], sys.argv[2], int(sys.argv[3])
    comm = MPI.COMM_WORLD
    split = NodeSplitRun(pulled(shape, model), comm)
    split.run(steps)
    gathered = {field: split.gather(field) for field in FIELDS}
    halos = comm.gather((len(split.own), split.halo_nodes), root=0)
    broken = split.broken_bonds()
    exchange = comm.gather(split.seconds["exchange"] / sum(split.seconds.values()), root=0)
    labels = comm.gather(split.fragment_labels(), root=0)
    data = split.step_data((0,))  # the body tracked
    if comm.Get_rank() != 0:
        return 0
    serial = pulled(shape, model)
    serial.core.run(steps)
    differences = {
        field: float(np.abs(gathered[field] - np.asarray(getattr(serial.core, field))).max())
        for field in FIELDS
    }
    print(f"ranks {comm.Get_size()}, {shape} {model}, {steps} steps: {differences}")
    print(f"bonds broken {broken} against {serial.core.broken_bonds()} serially")
    print(f"own and halo nodes per rank {halos}; exchange shares {[round(s, 3) for s in exchange]}")
    whole = np.empty(serial.node_count, dtype=np.int64)
    for nodes, part in zip(split.nodes_of, labels, strict=True):
        whole[nodes] = part
    pieces = np.asarray(serial.core.fragments())
    print(
        f"fragment labels as serially: {np.array_equal(whole, pieces)}, pieces {len(set(pieces))}"
    )
    print(f"step data as serially: {same_step(data, StepData.of(serial, (serial.bodies[0],)))}")
    return 0


def same_step(a: StepData, b: StepData) -> bool:
    """Whether two output steps have the same bits in every table, sum and stress."""
    tables = ((a.fragments, b.fragments), (a.particles, b.particles))
    columns = all(
        t.keys() == u.keys() and all(np.array_equal(t[k], u[k], equal_nan=True) for k in t)
        for t, u in tables
    )
    stresses = all(np.array_equal(x, y) for x, y in zip(a.stresses, b.stresses, strict=True))

    def numbers(d: StepData) -> tuple[float | int, ...]:
        totals, (body,) = d.totals, d.totals.tracked
        sums = (totals.kinetic, totals.strain, totals.gravity, totals.contact, body.mass)
        sums += (*body.force, *body.displacement)
        return (d.step, d.time, d.broken_bonds, d.mean_damage, body.nodes, *(s.value for s in sums))

    return columns and stresses and numbers(a) == numbers(b)


if __name__ == "__main__":
    code = main()
    wait_asleep(MPI.COMM_WORLD)  # while rank 0 runs serially and compares
    sys.exit(code)
