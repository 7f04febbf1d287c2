"""Whether this process was started as one of several MPI ranks (mpirun, mpiexec, srun), read
from the variables the launchers set, without importing MPI.

`granulate run case.yaml` started as K ranks runs the case over them (granulate.parallel), and
`granulate bench --ranks` measures them. The other commands that write files would be K copies
writing the same files at once: the command line refuses them with one message from rank 0 (the
other ranks exit with the same code, silently).
"""

from __future__ import annotations

import os
from collections.abc import Mapping

# (size, rank) variables of each launcher: Open MPI, MPICH's and Intel MPI's Hydra, Slurm's srun
# (SLURM_STEP_NUM_TASKS is the job step's: 1 in a batch script outside srun).
_LAUNCHERS = (
    ("OMPI_COMM_WORLD_SIZE", "OMPI_COMM_WORLD_RANK"),
    ("PMI_SIZE", "PMI_RANK"),
    ("SLURM_STEP_NUM_TASKS", "SLURM_PROCID"),
)


def launched_ranks(environ: Mapping[str, str] | None = None) -> tuple[int, int]:
    """(number of ranks, this process's rank) as the launcher set them; (1, 0) if none did."""
    env = os.environ if environ is None else environ
    for size_name, rank_name in _LAUNCHERS:
        size, rank = env.get(size_name, ""), env.get(rank_name, "")
        if size.isdigit() and rank.isdigit() and int(size) > 1:
            return int(size), int(rank)
    return 1, 0


def serial_only_message(command: str, size: int) -> str:
    """What a user who started `granulate <command>` on `size` ranks is told."""
    return (
        f"'granulate {command}' was started as {size} MPI processes (mpirun, mpiexec or srun); "
        "only 'granulate run' (and 'granulate bench --ranks') runs over MPI ranks, and the copies "
        f"would write the same files at once. Start one process: granulate --threads N {command} "
        "..."
    )


def serial_copies_hint(environ: Mapping[str, str] | None = None) -> str:
    """What is added to a serial simulation's refused output folder when this process is one
    of several MPI ranks (a script started with mpiexec whose gr.Simulation has no comm: every
    rank runs it whole and writes the same folder); "" otherwise."""
    size, rank = launched_ranks(environ)
    if size == 1:
        return ""
    return (
        f". This process is rank {rank} of {size} MPI ranks, each running its own serial "
        "simulation: give gr.Simulation(..., comm=MPI.COMM_WORLD) to run one simulation over "
        "the ranks (docs/parallel.md), or each rank its own output folder"
    )
