"""Distributed runs (DESIGN.md section 7). The decomposition of an assembly over ranks, whole
grains per rank with the ghosts contact needs (partition.py), and the engine that steps one
simulation on the ranks of an MPI communicator with those ghosts (engine.py, DistributedRun:
grains migrate between ranks with their whole state, transplant.py, and checkpoints restart on
any number of ranks; outputs are gathered by hand). The command line does not run a case on
several ranks yet and refuses to start as several (launch.py)."""

from granulate.parallel.engine import DistributedRun
from granulate.parallel.partition import Partition, bisect, ghosts, near_pairs

__all__ = ["DistributedRun", "Partition", "bisect", "ghosts", "near_pairs"]
