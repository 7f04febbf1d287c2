"""Shared fixtures. ``pytest --full`` runs validation cases at their full size."""

from __future__ import annotations

from collections.abc import Iterator

import pytest


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption(
        "--full",
        action="store_true",
        default=False,
        help="run validation cases at full resolution (slow); default is the smoke size",
    )


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
