"""Work that only rank 0 of a check needs (the serial reference run, the comparison), while
the other ranks wait asleep.

An MPI rank blocked in a collective spins on its core (MPICH polls), and the checks run 2 or
3 ranks on the CI's 2 cores beside another test: a rank spinning at a barrier while rank 0
ran the serial reference took most of a core from it. Waiting here polls a non-blocking
barrier between short sleeps instead.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any, TypeVar

T = TypeVar("T")

#: Between two polls of the barrier [s]: short against the seconds a reference run takes.
POLL_SECONDS = 0.002


def wait_asleep(comm: Any) -> None:
    """A barrier on `comm` that sleeps between polls instead of spinning."""
    request = comm.Ibarrier()
    while not request.Test():
        time.sleep(POLL_SECONDS)


def on_rank_0(comm: Any, work: Callable[[], T]) -> T | None:
    """work() on rank 0 of `comm`, its result there (None elsewhere), every rank leaving
    together once it is done."""
    result = work() if comm.Get_rank() == 0 else None
    wait_asleep(comm)
    return result
