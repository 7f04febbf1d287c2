"""Frames of a distributed run written by rank 0 (one .vtu each) against frames in pieces (a .pvtu
over one piece per rank, each written by its rank): the run's wall time, rank 0's time writing
outputs and each rank's peak resident memory (VmHWM, over the whole process: give
`--frames one` or `--frames pieces` alone to read it for one kind), rounds alternating.

    mpiexec -n 2 python benchmarks/frame_pieces.py [--grains 1000] [--steps 40] [--every 10]
        [--rounds 2] [--frames both] [--out DIR]

The case is `granulate bench --ranks`'s 3D pile (1,000 grains: 258,624 nodes), one thread per
rank unless OMP_NUM_THREADS says otherwise. Each run writes frames every `--every` steps (and a
history row with each) into DIR/one or DIR/pieces (default: a temporary folder), and ends
without gathering the state into rank 0 (run(gather=False)), as `granulate run` does.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

from mpi4py import MPI
from process_memory import status_mb

import granulate as gr
from granulate.bench_ranks import pile3d


def timed(folder: Path, pieces: bool, grains: int, steps: int, every: int) -> tuple[float, float]:
    """The wall time of `steps` steps of the pile with its frames, and rank 0's seconds
    writing outputs (Outputs.seconds), after its first frame."""
    comm = MPI.COMM_WORLD
    sim = pile3d(grains, comm)
    sim.output(folder, every=every, pieces=pieces, overwrite=True)
    sim.run(0, progress=False, gather=False)  # the parts built, frame 0 written
    before = sim._output.seconds if sim._output is not None else 0.0
    comm.Barrier()
    start = time.perf_counter()
    sim.run(steps, progress=False, gather=False)
    comm.Barrier()
    wall = time.perf_counter() - start
    writing = sim._output.seconds - before if sim._output is not None else 0.0
    return wall, writing


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grains", type=int, default=1000)
    parser.add_argument("--steps", type=int, default=40)
    parser.add_argument("--every", type=int, default=10)
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--frames", choices=("one", "pieces", "both"), default="both")
    parser.add_argument("--out", type=Path, default=None)
    options = parser.parse_args()
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    gr.set_num_threads(int(os.environ["OMP_NUM_THREADS"]))
    comm = MPI.COMM_WORLD
    root = options.out or Path(comm.bcast(tempfile.mkdtemp() if comm.Get_rank() == 0 else None))
    for round_ in range(options.rounds):
        kinds = {"one": (False,), "pieces": (True,), "both": (False, True)}[options.frames]
        for pieces in kinds:
            folder = root / ("pieces" if pieces else "one")
            wall, writing = timed(folder, pieces, options.grains, options.steps, options.every)
            peaks = comm.gather(status_mb("VmHWM")[0], root=0)
            if comm.Get_rank() == 0:
                kind = "pieces" if pieces else "one file"
                print(
                    f"round {round_ + 1}, {comm.Get_size()} ranks, frames {kind}: "
                    f"{options.steps} steps (a frame every {options.every}) in {wall:.2f} s, "
                    f"rank 0 writing outputs {writing:.2f} s; peak memory per rank "
                    f"{', '.join(f'{peak:,.0f}' for peak in peaks)} MB"
                )


if __name__ == "__main__":
    main()
