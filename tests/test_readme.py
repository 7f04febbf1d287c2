"""The README's five-minute tutorial works as written: its commands run a pile (cut short) and
plot it, and its Python block reads the run back."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[1]


def tutorial() -> tuple[list[list[str]], str]:
    """The five-minute section's granulate commands (without comments) and its Python block."""
    text = (ROOT / "README.md").read_text()
    section = text.split("## Five minutes", 1)[1].split("\n## ", 1)[0]
    lines = (line.split("#")[0].split() for line in section.splitlines())
    commands = [words for words in lines if words[:1] == ["granulate"]]
    block = re.search(r"```python\n(.*?)```", section, re.S)
    assert block is not None, "the five-minute section has no Python block"
    return commands, block.group(1)


def test_the_five_minute_tutorial_runs_as_written(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """In a scratch directory (the case file from the repository, the run cut to 3,000 steps):
    the run writes out/pile_2d, the plot writes its PNGs, and the Python block runs."""
    commands, code = tutorial()
    assert [words[1] for words in commands] == ["run", "plot"]
    run, plot = commands
    run = [*run[1:2], str(ROOT / run[2]), *run[3:], "--steps", "3000", "--quiet"]
    cli = [sys.executable, "-m", "granulate"]
    env = {**os.environ, "MPLBACKEND": "Agg"}
    for words in (run, plot[1:]):
        done = subprocess.run([*cli, *words], cwd=tmp_path, env=env, capture_output=True)
        assert done.returncode == 0, done.stderr.decode()
    assert (tmp_path / "out" / "pile_2d" / "energies.png").is_file()
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "README.md", "exec"), {})
