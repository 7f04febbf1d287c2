"""Shared fixtures. ``pytest --full`` runs validation cases at their full size."""

from __future__ import annotations

import os
from collections.abc import Iterator

import pytest


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption(
        "--full",
        action="store_true",
        default=False,
        help="run validation cases at full resolution (slow); default is the smoke size",
    )


def pytest_configure(config: pytest.Config) -> None:
    if os.environ.get("PYTEST_XDIST_WORKER"):
        # The suite runs on one worker per CPU (-n auto, pyproject.toml): each worker's runs get
        # one thread, as the adaptive policy would pick next to a busy sibling, without its
        # trials. Tests of the thread count still set their own.
        from granulate import threads

        threads.set_num_threads(1)
    config.addinivalue_line(
        "markers",
        "full_only: a variant that only --full runs; the default suite runs a smoke version of"
        " the same claim (another parameter or a smaller size), to stay within its time budget",
    )


#: The test modules that run MPI ranks (mpiexec): queued first.
MPI_MODULES = ("test_mpi", "test_mpi_cli")


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Without --full, the variants marked full_only are deselected (counted as such in
    pytest's summary line). The MPI tests are queued first, then the validation tests, the
    longest, so that the workers end on short tests and finish together (the order of the
    rest is kept). With --dist load, pytest-xdist (3.8) first sends each worker a chunk of
    consecutive tests, a quarter of its share of the queue: the first worker's holds every MPI
    test, the second's validation tests, so one MPI test runs at a time, beside a serial
    test (2 or 3 ranks beside it oversubscribe the 2 cores). The suite took 4-5 % less so
    (two rounds alternating with the validation tests first under worksteal: 305.8 and 325.6 s
    against 317.0 and 343.9 s)."""
    kept, dropped = [], []
    for item in items:
        full_only = item.get_closest_marker("full_only") is not None
        (dropped if full_only and not config.getoption("--full") else kept).append(item)
    if dropped:
        config.hook.pytest_deselected(items=dropped)
    kept.sort(
        key=lambda item: (
            getattr(item.module, "__name__", "") not in MPI_MODULES,
            item.get_closest_marker("validation") is None,
        )
    )
    items[:] = kept


@pytest.fixture
def full(request: pytest.FixtureRequest) -> bool:
    """True under ``pytest --full``."""
    return bool(request.config.getoption("--full"))


@pytest.fixture(autouse=True)
def _thread_policy_restored() -> Iterator[None]:
    """Tests that pin the thread count (determinism, threads) leave the policy as they found it:
    without this, every later test ran on 2 fixed threads instead of the adaptive default,
    which runs small models on 1 thread when that is faster (the three-disc stack took 7.8 s on
    2 fixed threads, 5.4-5.8 s adaptive)."""
    from granulate import threads

    count, adaptive = threads.get_num_threads(), threads.is_adaptive()
    yield
    threads.set_num_threads(count, adaptive=adaptive)
