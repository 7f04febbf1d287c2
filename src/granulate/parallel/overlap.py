"""Work a rank does while a step's messages travel (both engines): in PARTS parts, with the MPI
given the chance to move the messages along after each part (Testall). An MPI progresses a
large message only within its own calls, unless it has a progress thread or the network moves
it; these calls let a transfer that began after the first part run during the others."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from granulate.parallel.agreement import attempt

#: The parts a step's overlapped work is cut into.
PARTS = 4


def while_travelling(
    mpi: Any, requests: list[Any], work: Callable[[float], object], failure: Exception | None
) -> tuple[Exception | None, float]:
    """work(k / PARTS) for k = 1 ... PARTS (work(share): the share of it done by then, as
    core.evaluate_bonds and evaluate_dilatation take it), skipped once the step has failed
    (agreement.attempt), each followed by a Testall of `requests`; the step's failure, and
    the seconds spent in Testall [s]."""
    testing = 0.0
    for part in range(1, PARTS + 1):
        failure = attempt(lambda part=part: work(part / PARTS), failure)
        start = time.perf_counter()
        mpi.Request.Testall(requests)
        testing += time.perf_counter() - start
    return failure, testing
