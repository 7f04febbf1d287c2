"""Distributed runs (DESIGN.md section 7). So far: the decomposition of an assembly over ranks,
whole grains per rank with the ghosts contact needs (partition.py), and its measures; the
engine that runs a case over MPI ranks is not built yet, so the command line refuses to start
as several ranks (launch.py)."""

from granulate.parallel.partition import Partition, bisect, ghosts, near_pairs

__all__ = ["Partition", "bisect", "ghosts", "near_pairs"]
