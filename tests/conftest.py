"""Shared fixtures. ``pytest --full`` runs validation cases at their full size."""

from __future__ import annotations

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
