"""Errors and decisions shared by every rank of a communicator, so that no rank is left waiting
in a collective call that another rank will never make: an action that fails on one rank ends
every rank (`together`), an action only rank 0 takes (writing a folder, reading a checkpoint)
tells the others whether it failed (`on_root`)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar

from granulate.errors import InputError

T = TypeVar("T")


class RankFailed(RuntimeError):
    """Raised on every other rank when one rank's action or step failed (that rank raises its
    own error)."""


def together(comm: Any, action: Callable[[], T], doing: str = "building its part") -> T:
    """action() on every rank; when it raised on some rank, every rank stops
    (stop_if_any_failed: a user's error with its message on every rank, else the first failing
    rank with its own error, the others with RankFailed naming it and what it was `doing`)."""
    failure, result = None, None
    try:
        result = action()
    except Exception as error:  # re-raised below, once every rank knows
        failure = error
    stop_if_any_failed(comm, failure, doing)
    return result  # type: ignore[return-value]


def attempt(action: Callable[[], object], failure: Exception | None = None) -> Exception | None:
    """action() unless a part of the step failed before (`failure`): None, or the error it
    raised, kept for the step's reduction (stop_if_any_failed), so that every rank goes
    through every exchange of the step."""
    if failure is not None:
        return failure
    try:
        action()
    except Exception as error:  # raised after the step's exchanges, once every rank knows
        return error
    return None


def stop_if_any_failed(comm: Any, failure: Exception | None, doing: str) -> None:
    """One reduction: when some rank's `failure` is set, every rank stops. Each failing rank
    raises its own error. When the first one's is an InputError (a user's error: a missing
    file, a model too large), the others raise it with its message (one broadcast), so that
    rank 0 reports it; else RankFailed naming that rank and what it was `doing`."""
    from mpi4py import MPI

    size = comm.Get_size()
    first = comm.allreduce(comm.Get_rank() if failure is not None else size, op=MPI.MIN)
    if first == size:
        return
    mine = str(failure) if isinstance(failure, InputError) else None
    shared = comm.bcast(mine, root=first)
    if failure is not None:
        raise failure
    if shared is not None:
        raise InputError(shared)
    raise RankFailed(f"rank {first} failed while {doing}; every rank stops")


def on_root(comm: Any, action: Callable[[], T]) -> T | None:
    """action() on rank 0 alone: its result there, None on the others. An InputError it
    raises is raised on every rank (the same message: a user error every rank shares); any
    other error (a full disk, a bug) is raised on rank 0 and ends the others with RankFailed."""
    result, failure = None, None
    problem: tuple[type[Exception], str] | None = None
    if comm.Get_rank() == 0:
        try:
            result = action()
        except InputError as error:
            failure, problem = error, (InputError, str(error))
        except Exception as error:  # rank 0 reports it, the others stop
            failure = error
            problem = (RankFailed, f"rank 0 failed: {type(error).__name__}: {error}")
    problem = comm.bcast(problem, root=0)
    if failure is not None:
        raise failure
    if problem is not None:
        kind, message = problem
        raise kind(message)
    return result
