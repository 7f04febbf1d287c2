"""How many OpenMP threads the core uses, and how a run picks that number on a busy machine.

The core's results are bitwise identical for any thread count, so a run may change it between
chunks of steps without changing a bit of its output. That is what makes this policy safe:

- The ceiling is the CPUs this process may use: its affinity mask (taskset, batch schedulers),
  capped by a cgroup CPU quota (containers, Slurm), not the machine's core count.
- With the default (no OMP_NUM_THREADS, no set_num_threads, no --threads), ``Simulation.run``
  starts with the CPUs that nothing else is running on (/proc/loadavg) and then measures
  itself: the steps per second of each thread count it uses, in windows of at least
  MEASURE_SECONDS. Now and then (sooner when its rate drops by 40 %) it tries a neighbouring
  count for a short window between two windows at its own, and keeps the faster by
  SWITCH_MARGIN, confirmed by the next full window. A trial that runs at under half the usual
  rate for half a window ends there (it cannot win); after such a trial of more threads, the
  next ones are skipped (backing off the same way) while /proc/loadavg shows others running.
  Failed trials back off to one a minute; a run that started below the ceiling (others busy)
  first tries more threads after 2 s.
- Why: when another process holds a core, a thread waiting at the core's barriers for a
  descheduled sibling costs far more than the work it shares. Next to one busy process on 2
  CPUs, 2 fixed threads ran PeriDEM's small compression deck 2.5 times slower than 1 thread,
  the crushing case 2.4 times slower (``granulate bench --contended``).
- A thread count the user sets (OMP_NUM_THREADS, ``set_num_threads``, ``granulate --threads``)
  is used as given.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from pathlib import Path

from granulate import _core
from granulate.errors import InputError

MEASURE_SECONDS = 0.03  # a rate is measured over at least this much run time
TRIAL_SECONDS = 0.03  # a trial of another count takes this much run time at the current rate
SWITCH_MARGIN = 1.1  # a trial count must be this much faster to be kept
DROP = 0.6  # two windows below this fraction of the usual rate trigger a trial
SMOOTHING = 0.3  # weight of a new window in the usual rate (an exponential average)
FIRST_TRIAL_SECONDS = 0.1  # run time before the first trial
WAIT_AFTER_SWITCH_SECONDS = 2.0  # before trying again after a switch
FIRST_WAIT_SECONDS = 2.0  # the wait after a first failed trial, doubling after each failure
LONGEST_WAIT_SECONDS = 60.0  # failed trials back off (doubling) to at most this interval
DROP_WAIT_SECONDS = 5.0  # a drop in rate brings a trial forward to at most this long after one
HOPELESS = 0.5  # a trial below this fraction of the usual rate for half a window ends there

_adaptive = "OMP_NUM_THREADS" not in os.environ


def cgroup_cpu_quota(root: Path = Path("/sys/fs/cgroup")) -> float | None:
    """CPUs the cgroup of this process may use (quota / period), or None without a quota.
    Reads cgroup v2's cpu.max, else v1's cpu.cfs_quota_us and cpu.cfs_period_us."""
    try:
        quota, period = (root / "cpu.max").read_text().split()[:2]
        return None if quota == "max" else int(quota) / int(period)
    except (OSError, ValueError):
        pass
    try:
        quota_us = int((root / "cpu" / "cpu.cfs_quota_us").read_text())
        period_us = int((root / "cpu" / "cpu.cfs_period_us").read_text())
    except (OSError, ValueError):
        return None
    return None if quota_us <= 0 or period_us <= 0 else quota_us / period_us


def available_cpus() -> int:
    """CPUs this process may run on: its affinity mask, capped by a cgroup CPU quota."""
    try:
        count = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        count = os.cpu_count() or 1
    quota = cgroup_cpu_quota()
    if quota is not None:
        count = min(count, max(1, math.ceil(quota)))
    return max(1, count)


def set_num_threads(threads: int, adaptive: bool = False) -> None:
    """Number of OpenMP threads used by the core (results are identical for any number).
    With ``adaptive``, runs use at most this many and fewer when that is faster (another
    process holding a core); without, exactly this many."""
    global _adaptive
    if isinstance(threads, bool) or not isinstance(threads, int) or threads < 1:
        raise InputError(f"the number of threads must be a positive integer, got {threads!r}")
    _core.set_num_threads(threads)
    _adaptive = bool(adaptive)


def get_num_threads() -> int:
    """Number of OpenMP threads the core will use (the most a run uses, when adaptive)."""
    return int(_core.get_max_threads())


def is_adaptive() -> bool:
    """Whether runs pick their thread count by measurement (see the module docstring)."""
    return _adaptive


def busy_cpus() -> int:
    """Tasks of other processes runnable right now (/proc/loadavg's count less this process's
    running threads, whose OpenMP workers may still be spinning; 0 where unknown)."""
    try:
        running = int(Path("/proc/loadavg").read_text().split()[3].split("/")[0])
        own = 0
        for task in Path("/proc/self/task").iterdir():
            state = (task / "stat").read_text().rsplit(")", 1)[1].split()[0]
            own += state == "R"
    except (OSError, ValueError, IndexError):
        return 0
    return max(0, running - own)


def candidate_counts(most: int) -> list[int]:
    """Thread counts a run tries, fewest first: 1, half, all but one, all."""
    return sorted({1, max(1, most // 2), max(1, most - 1), most})


class ThreadTuner:
    """Picks the thread count of each chunk of a run from measured steps per second (see the
    module docstring). Call ``threads()`` before a chunk, ``step_cap()`` for the most steps it
    may take, and ``record()`` after it. ``seconds_at`` keeps the run time spent at each
    count, ``trials`` each trial.

    A trial is one short window at another count between two windows at the current one; it
    is kept when it beats the mean of those two, so a workload that changes as the run goes on
    (contacts forming, bonds breaking) does not bias the comparison."""

    def __init__(
        self, most: int, start: int | None = None, busy: Callable[[], int] | None = None
    ) -> None:
        self.counts = candidate_counts(most)
        self._busy = busy_cpus if busy is None else busy  # tasks of others running now
        # Start with the CPUs nothing else is running on (a guess the trials then check).
        free = most - self._busy() if start is None else start
        self.current = max([c for c in self.counts if c <= free] or [1])
        self.seconds_at = dict.fromkeys(self.counts, 0.0)
        self.trials: list[tuple[float, int, bool]] = []  # (run time, count tried, kept)
        self._phase = "run"  # "run", "trial" (at the other count), "check" (back, to compare)
        self._trial = most
        self._rates = {"before": 0.0, "trial": 0.0}
        self._window = [0, 0.0]  # steps and seconds measured in the current phase
        self._usual = 0.0  # the current count's usual rate (steps/s), an exponential average
        self._confirm: tuple[int, float] | None = None  # after a switch: the old count, rate
        self._low_windows = 0  # consecutive windows below DROP x usual
        self._run_seconds = 0.0
        # Started below the ceiling because other processes run: trust that for 2 s
        # before trying more threads (a trial at the slower count is what a short run pays).
        first = FIRST_TRIAL_SECONDS if self.current == most else FIRST_WAIT_SECONDS
        self._next_trial = first
        self._wait = first
        self._last_trial = 0.0  # run time at the end of the last trial
        self._direction = -1  # trials go to fewer threads first
        self._hopeless_up = False  # the last trial of more threads was hopeless
        self.skipped = 0  # trials of more threads skipped because others still ran

    def threads(self) -> int:
        """The thread count for the next chunk."""
        due = self._run_seconds >= self._next_trial and self._rates["before"] > 0
        if self._phase == "run" and len(self.counts) > 1 and due:
            trial = self._neighbour()
            if trial > self.current and self._hopeless_up and self._others_hold(trial):
                self.skipped += 1
                self._back_off()
            else:
                self._phase, self._trial = "trial", trial
                self._window = [0, 0.0]
        return self._trial if self._phase == "trial" else self.current

    def step_cap(self) -> int | None:
        """The most steps the next chunk may take, or None: trial windows are kept short, and
        so are the chunks before the first trial (a run's first steps can be far cheaper than
        the next ones, as before an impact)."""
        if self._phase == "run" and self.trials:
            return None
        steps, seconds = self._window
        rate = self._usual if self._usual > 0 else steps / seconds if seconds > 0 else 0.0
        if rate <= 0:
            return None
        window = max(1, int(TRIAL_SECONDS * rate))
        if self._phase == "trial":  # 1 step, then as many as so far: a slow count shows early
            return max(1, min(window, self._window[0]))
        return window

    def record(self, threads: int, steps: int, seconds: float) -> None:
        """A chunk of `steps` took `seconds` with `threads`."""
        self._run_seconds += seconds
        self.seconds_at[threads] = self.seconds_at.get(threads, 0.0) + seconds
        self._window[0] += steps
        self._window[1] += seconds
        if self._phase == "trial" and self._hopeless():
            self._rates["trial"] = self._window[0] / self._window[1]
            self._window = [0, 0.0]
            self._hopeless_up = threads > self.current
            self._decide(self._rates["before"])  # lost: no window back at the current count
            return
        if self._window[1] < MEASURE_SECONDS:
            return
        rate = self._window[0] / self._window[1]
        self._window = [0, 0.0]
        if self._phase == "trial":
            self._rates["trial"], self._phase = rate, "check"
            self._hopeless_up = False
        elif self._phase == "check":
            self._decide((self._rates["before"] + rate) / 2)
        else:
            self._measured(rate)

    def _others_hold(self, count: int) -> bool:
        """Other processes run on the CPUs `count` threads would need (/proc/loadavg)."""
        return max(self.counts) - self._busy() < count

    def _back_off(self) -> None:
        """No switch: the next trial waits twice as long (at least FIRST_WAIT_SECONDS)."""
        self._wait = min(max(2 * self._wait, FIRST_WAIT_SECONDS), LONGEST_WAIT_SECONDS)
        self._next_trial = self._run_seconds + self._wait

    def _hopeless(self) -> bool:
        """The trial has run half a window at under HOPELESS x the rate before it: it cannot
        win (a count that a busy CPU slows 10 times would cost a whole window's steps)."""
        steps, seconds = self._window
        before = self._rates["before"]
        return seconds >= MEASURE_SECONDS / 2 and steps < HOPELESS * before * seconds

    def _measured(self, rate: float) -> None:
        """A window at the current count, between trials."""
        self._rates["before"] = rate
        if self._confirm is not None:
            # The first full window after a switch must beat the old count too (a short trial
            # window can be lucky on a busy machine); if not, go back.
            old, old_rate = self._confirm
            self._confirm = None
            if rate < old_rate:
                self.trials[-1] = (*self.trials[-1][:2], False)
                self.current, self._usual, self._rates["before"] = old, old_rate, old_rate
                self._wait = FIRST_WAIT_SECONDS
                self._next_trial = self._run_seconds + self._wait
                return
        if self._usual <= 0:
            self._usual = rate
            return
        self._low_windows = self._low_windows + 1 if rate < DROP * self._usual else 0
        self._usual += SMOOTHING * (rate - self._usual)
        if self._low_windows >= 2:
            # Something else took our CPUs (or the work per step grew, as when grains shatter):
            # try another count soon, but no sooner than half the wait after failed trials.
            self._low_windows = 0
            soonest = self._last_trial + min(self._wait / 2, DROP_WAIT_SECONDS)
            self._next_trial = min(self._next_trial, max(self._run_seconds, soonest))

    def _decide(self, baseline: float) -> None:
        """Keep the trial's count if it beat the current one's rate around it."""
        trial_rate = self._rates["trial"]
        kept = trial_rate > SWITCH_MARGIN * baseline
        self.trials.append((self._run_seconds, self._trial, kept))
        if kept:
            self._confirm = (self.current, baseline)
            self.current, self._usual = self._trial, trial_rate
            self._rates["before"] = trial_rate
            self._wait = WAIT_AFTER_SWITCH_SECONDS
        else:
            self._rates["before"] = baseline
            self._direction = -self._direction
            self._back_off()
        self._phase = "run"
        self._low_windows = 0
        self._last_trial = self._run_seconds
        self._next_trial = self._run_seconds + self._wait

    def _neighbour(self) -> int:
        """The next count to try: one step fewer or more than the current one, alternating."""
        k = self.counts.index(self.current)
        step = self._direction if 0 <= k + self._direction < len(self.counts) else -self._direction
        self._direction = step
        return self.counts[k + step]
