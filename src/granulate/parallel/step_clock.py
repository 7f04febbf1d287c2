"""A rank's step seconds per unit of its modelled work, for a balance weighted by time
(granulate.LoadBalance(weight="time"), LAMMPS' ``fix balance ... weight time``).

Over a window of steps (from one comparison of the ranks' work, or one migration, to the next)
a rank's steps took T seconds of its own compute (DistributedRun.seconds["steps"]: the
exchanges and checks left out) for modelled work W a step (work_load.py); its grains then
weigh W_g T / (W s) each (s steps): a rank whose grains cost more than their counts say
(contact costlier than its entries, breaking bonds) sheds some at the next cut.
"""

from __future__ import annotations


class StepClock:
    """Seconds per unit of modelled work over the current window; the last window's when the
    current one has no step yet (right after a migration), None before any."""

    def __init__(self) -> None:
        self._seconds = 0.0  # DistributedRun.seconds["steps"] when the window began
        self._step = 0
        self._scale: float | None = None

    def restart(self, seconds: float, step: int, work: float) -> None:
        """End the window at `step` (its scale kept for an empty next one) and begin anew."""
        self._scale = self.scale(seconds, step, work)
        self._seconds, self._step = seconds, step

    def scale(self, seconds: float, step: int, work: float) -> float | None:
        """Seconds a step per unit of work `work` (the rank's now) since the window began."""
        steps = step - self._step
        if steps <= 0 or work <= 0:
            return self._scale
        return (seconds - self._seconds) / (steps * work)
