"""Every example runs in its smoke mode (the full runs are checked under --full)."""

from __future__ import annotations

import runpy
import sys
from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).parent.parent / "examples").glob("*.py"))


@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.stem)
def test_example_smoke(
    script: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, full: bool
) -> None:
    arguments = ["--out", str(tmp_path / "out")] + ([] if full else ["--smoke"])
    monkeypatch.setattr(sys, "argv", [str(script), *arguments])
    module = runpy.run_path(str(script))
    summary = module["main"](arguments)
    assert summary["nodes"] > 0 and summary["steps"] > 0
    assert (tmp_path / "out" / "simulation.pvd").is_file()
    assert (tmp_path / "out" / "history.csv").is_file()
    if full:
        assert summary["pieces"] >= 2, "the full example must break the specimen"
