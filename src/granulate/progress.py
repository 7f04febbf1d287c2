"""Progress of a run for people: a bar in a terminal or a notebook, lines in a log."""

from __future__ import annotations

import sys
import time
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from granulate.simulation import Progress


def _interactive() -> bool:
    """A terminal or a Jupyter notebook (where rich draws live bars)."""
    from rich.console import Console

    console = Console()
    return bool(console.is_terminal or console.is_jupyter or sys.stdout.isatty())


def duration(seconds: float) -> str:
    """A duration for people: seconds, minutes or hours."""
    if seconds < 120:
        return f"{seconds:.0f} s"
    if seconds < 7200:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


class ProgressReporter:
    """A progress bar in a terminal or a Jupyter notebook, plain lines (every 10 % or 30 s)
    otherwise; called with each Progress of a run (``Simulation.run(progress=True)`` and
    ``granulate run``). ``close()`` ends the bar."""

    def __init__(self, total: int, quiet: bool = False) -> None:
        self.total = max(total, 1)
        self.quiet = quiet
        self.bar = None
        self.last_line = time.perf_counter()
        self.last_tenth = -1
        if not quiet and _interactive():
            from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

            self.bar = Progress(
                TextColumn("[bold]step {task.completed:>9}/{task.total}"),
                BarColumn(),
                TextColumn(
                    "{task.fields[rate]} steps/s  t = {task.fields[time]} s  "
                    "broken {task.fields[broken]}"
                ),
                TimeRemainingColumn(),
            )
            self.task = self.bar.add_task("run", total=self.total, rate="-", time="0", broken=0)
            self.bar.start()
        self.start_step: int | None = None

    def __call__(self, p: Progress) -> None:
        if self.quiet:
            return
        if self.start_step is None:
            self.start_step = p.step
        done = p.step - (p.target_step - self.total)
        if self.bar is not None:
            self.bar.update(
                self.task,
                completed=done,
                rate=f"{p.steps_per_second:,.0f}",
                time=f"{p.time:.4g}",
                broken=p.broken_bonds,
            )
            return
        tenth = int(10 * done / self.total)
        now = time.perf_counter()
        if tenth > self.last_tenth or now - self.last_line > 30:
            self.last_tenth, self.last_line = tenth, now
            remaining = (p.target_step - p.step) / max(p.steps_per_second, 1e-9)
            print(
                f"step {p.step} ({100 * done / self.total:.0f} %), t = {p.time:.4g} s, "
                f"{p.steps_per_second:,.0f} steps/s, broken bonds {p.broken_bonds}, "
                f"ETA {duration(remaining)}",
                flush=True,
            )

    def close(self) -> None:
        if self.bar is not None:
            self.bar.stop()
