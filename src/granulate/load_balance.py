"""How a distributed run keeps its ranks' work even (granulate.parallel, docs/parallel.md).

A rank's work is the sum over its grains' nodes of work_load.node_work (nodes, intact bond
copies, contact list entries). The ranks compare it at the start, after a checkpoint is loaded
and every ``every`` steps (one allgather of a number per rank); when the most loaded rank
carries over ``threshold`` times the mean, and over ``threshold`` times what the last cut left
it (a grain too heavy to share out would otherwise cut again at every check), the next step
begins with a migration that cuts the grains anew by their work. LAMMPS users know this as
``fix balance Nfreq thresh``. Whatever the cut, the run is the serial run, bit for bit: these
settings change its speed, never its results. A serial run, and a body cut at node level
(whose nodes never change hands), ignore them.

``weight="time"`` (LAMMPS' ``weight time``) scales each rank's modelled work by the seconds its
steps took per unit of it since the last comparison (parallel/step_clock.py): the cut then
follows costs the counts miss (contact costlier than its entries say, grains breaking), at
the price of cuts that differ from run to run (the results do not). A grain carries its
rank's factor to its next rank, so a rank slow for its own sake (a slower core) is not what
it evens out: its grains are taken for costly ones wherever they go.
"""

from __future__ import annotations

from dataclasses import dataclass

from granulate.errors import InputError
from granulate.input_errors import checked_arguments


@checked_arguments
@dataclass(frozen=True)
class LoadBalance:
    """When the ranks of a distributed run compare their work and cut the grains anew.

    Attributes:
        every: steps between two comparisons (an integer >= 0; default 100); 0 compares only
            at the start and after a checkpoint is loaded (the grains' migrations, which follow
            their motion, still cut by work). Each comparison is one allgather.
        threshold: the most loaded rank's work over the mean (a number >= 1; default 1.1)
            above which the ranks cut anew; each such cut costs about what 20 steps do.
            ``float("inf")`` (YAML ``.inf``) never cuts for the balance: the ranks keep the
            cut by nodes of the start until the grains' motion makes them migrate.
        weight: ``"work"`` (default) weighs a grain by its counts (work_load.py), the same
            every run; ``"time"`` by those counts times its rank's measured step seconds per
            unit of them since the last comparison (before any step has been timed, by the
            counts alone).
    """

    every: int = 100
    threshold: float = 1.1
    weight: str = "work"

    def __post_init__(self) -> None:
        if self.every < 0:
            raise InputError(
                f"LoadBalance: every must be a number of steps >= 0 (0: only at the start), "
                f"got {self.every}"
            )
        if not self.threshold >= 1:  # nan too
            raise InputError(
                "LoadBalance: threshold must be a ratio >= 1 of the most loaded rank's work over "
                f"the mean (1.1: cut anew past 10 % over; inf: never), got {self.threshold}"
            )
        if self.weight not in ("work", "time"):
            raise InputError(f"LoadBalance: weight must be 'work' or 'time', got {self.weight!r}")

    @classmethod
    def from_text(cls, text: str) -> LoadBalance:
        """The settings a command line gives as comma-separated KEY=VALUE pairs of the
        attributes, any of them (the others their defaults): ``every=50,threshold=1.05``,
        ``weight=time``, ``threshold=inf``."""
        values: dict[str, object] = {}
        for item in text.split(","):
            key, equals, value = (part.strip() for part in item.partition("="))
            if not (key and equals and value):
                raise InputError(
                    f"LoadBalance {text!r}: {item.strip()!r} is not KEY=VALUE; write e.g. "
                    "every=100,threshold=1.1,weight=time"
                )
            values[key] = _value(key, value)
        return cls(**values)

    def as_text(self) -> str:
        """The settings as from_text reads them: ``every=100,threshold=1.1,weight=work``."""
        return f"every={self.every},threshold={self.threshold!r},weight={self.weight}"

    def due(self, step: int) -> bool:
        """Whether the ranks compare their work after `step`."""
        return self.every > 0 and step % self.every == 0


#: The attributes whose text is a number: their type, and what the message calls it.
_NUMBERS: dict[str, tuple[type, str]] = {
    "every": (int, "an integer"),
    "threshold": (float, "a number"),
}


def _value(key: str, text: str) -> object:
    """A LoadBalance attribute's value from its text: every an integer, threshold a number
    (``inf`` included), anything else the text (LoadBalance names what it does not take)."""
    if key not in _NUMBERS:
        return text
    kind, expected = _NUMBERS[key]
    try:
        return kind(text)
    except ValueError:
        raise InputError(f"LoadBalance: {key} must be {expected}, got {text!r}") from None
