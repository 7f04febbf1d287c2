"""Distributed runs (DESIGN.md section 7). The decomposition of an assembly over ranks, whole
grains per rank with the ghosts contact needs (partition.py), and the engine that steps one
simulation on the ranks of an MPI communicator with those ghosts (engine.py, DistributedRun:
grains migrate between ranks with their whole state, transplant.py; rank 0's simulation takes
the whole state for outputs and stop criteria that read it, whole_state.py; checkpoints in
pieces, checkpoint_pieces.py); a model in which nothing touches has its nodes dealt to the
ranks instead, so that one body runs on many (node_split.py, NodeSplitRun).
Simulation(comm=...) and `mpirun granulate run case.yaml` run through them (stepper.py,
agreement.py, launch.py)."""

from granulate.parallel.engine import DistributedRun
from granulate.parallel.node_split import NodeSplitRun
from granulate.parallel.partition import Partition, bisect, ghosts, near_pairs

__all__ = ["DistributedRun", "NodeSplitRun", "Partition", "bisect", "ghosts", "near_pairs"]
