"""Simulation.run's loop on the ranks of a distributed run (granulate.run_loop.Stepper): every
rank takes the steps of the chunks rank 0 decides; rank 0 writes the outputs of the step its
ranks measured of their grains (step_parts.py) or of their nodes (NodeSplitRun.step_data; a
frame of every node from their rows), or of the whole state its simulation takes (collect)
for writers that may read the simulation; the stop criteria read the ranks' measures put
together (run_measures.py); rank 0's decisions and errors reach every rank."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, TypeVar

from granulate.parallel.agreement import on_root, together
from granulate.parallel.engine import DistributedRun

if TYPE_CHECKING:
    from granulate.parallel.node_split import NodeSplitRun
    from granulate.simulation import Simulation
    from granulate.writers.outputs import Outputs
    from granulate.writers.step_data import StepData

T = TypeVar("T")


class DistributedStepper:
    """The run loop's steps on the ranks of `run` (every method on every rank together)."""

    def __init__(self, run: DistributedRun | NodeSplitRun) -> None:
        self.run = run
        self.comm = run.comm

    @property
    def step(self) -> int:
        return int(self.run.local.core.step)

    @property
    def time(self) -> float:
        return float(self.run.local.core.time)

    def advance(self, steps: int) -> None:
        self.run.run(steps)

    def first_forces(self) -> None:
        """Nothing to do: every part evaluated its forces when it was built."""

    def collect(self, measures: bool = True) -> None:
        self.run.collect(measures)

    def agree(self, value: T) -> T:
        return self.comm.bcast(value, root=0)  # type: ignore[no-any-return]

    def on_root(self, action: Callable[[], T]) -> T:
        return self.comm.bcast(on_root(self.comm, action), root=0)  # type: ignore[no-any-return]

    def any_rank(self, flag: bool) -> bool:
        return bool(self.comm.allreduce(bool(flag), op=self.run.mpi.LOR))

    def together(self, action: Callable[[], object], doing: str) -> None:
        together(self.comm, action, doing)

    def broken_bonds(self) -> int:
        return self.run.broken_bonds()

    def step_data(
        self, sim: Simulation, tracked: tuple[int, ...], whole: bool, frame: tuple[str, ...] | None
    ) -> StepData | None:
        if whole:
            self.run.collect(measures=True)
            return None
        return self.run.step_data(tracked, frame)

    def save_checkpoint(self, sim: Simulation, path: Path, outputs: Outputs | None) -> Path:
        return self.run.save_checkpoint(path, outputs)

    def write_pieces(self, folder: Path, fields: tuple[str, ...]) -> None:
        together(self.comm, lambda: self.run.write_piece(folder, fields), "writing its piece")
