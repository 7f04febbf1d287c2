"""The time loop of Simulation.run: chunks of steps between the places the loop must stop at
(outputs, stop checks, checkpoints, about half a second of steps), the thread count the tuner
picks for each chunk, progress reports, and a clean end on Ctrl-C or SIGTERM.

The loop advances the simulation through a Stepper: the simulation's own core (CoreStepper), or
a distributed run's ranks (granulate.parallel.stepper), where rank 0 decides what every rank
does next (chunk lengths, outputs, stops), gathers the whole state into its simulation before it
writes or checks, and shares its errors, so that every rank takes the same steps."""

from __future__ import annotations

import functools
import signal
import threading
import time as wallclock
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Protocol, TypeVar

import numpy as np

from granulate import _core, checkpoints, threads
from granulate.errors import InputError
from granulate.input_errors import check_number
from granulate.stopping import StopCriterion

if TYPE_CHECKING:
    from granulate.checkpoints import CheckpointPlan
    from granulate.simulation import Simulation
    from granulate.writers.outputs import Outputs
    from granulate.writers.step_data import StepData


@dataclass(frozen=True)
class Progress:
    """What ``run(progress=...)`` reports after each chunk of steps."""

    step: int
    target_step: int
    time: float
    broken_bonds: int
    steps_per_second: float
    wall_seconds: float


@dataclass(frozen=True)
class RunPlan:
    """What one run() call asked for, checked."""

    steps: int
    stop: Sequence[StopCriterion]
    check_every: int
    progress: Callable[[Progress], None] | None
    write_final: bool
    #: A distributed run's end state into rank 0's simulation (Simulation.run's `gather`).
    gather: bool = True


T = TypeVar("T")


class Stepper(Protocol):
    """How the loop advances a simulation and agrees with the other ranks of a distributed run
    (every method is called on every rank together)."""

    @property
    def step(self) -> int: ...
    @property
    def time(self) -> float: ...
    def advance(self, steps: int) -> None:
        """`steps` time steps."""

    def first_forces(self) -> None:
        """The forces of the current step, before any step (for step 0's frame)."""

    def collect(self, measures: bool = True) -> None:
        """The whole state in the simulation the outputs and stop criteria read; with
        `measures`, for outputs (a distributed run's ranks then measure their grains for them:
        analysis.GivenMeasures)."""

    def agree(self, value: T) -> T:
        """Rank 0's `value`, on every rank."""

    def on_root(self, action: Callable[[], T]) -> T:
        """action() on rank 0, its result on every rank; its error raised on every rank."""

    def any_rank(self, flag: bool) -> bool:
        """Whether `flag` is set on any rank."""

    def together(self, action: Callable[[], object], doing: str) -> None:
        """action() on every rank; an error on one rank ends every rank (a user's InputError
        with its message, else that rank's own error and RankFailed on the others)."""

    def broken_bonds(self) -> int:
        """The broken bonds of the whole simulation."""

    def step_data(
        self, sim: Simulation, tracked: tuple[int, ...], whole: bool, frame: tuple[str, ...] | None
    ) -> StepData | None:
        """The current output step made of the ranks' measures of their own grains, with the
        sums of the `tracked` bodies and, for a frame of every node with the fields `frame`,
        the ranks' rows of it, on rank 0 (None elsewhere); or None once `sim` holds the whole
        state (collect), which the outputs then read: always serially, and on ranks when
        `whole` (the outputs read the whole simulation) or the bodies are cut at node
        level."""

    def save_checkpoint(self, sim: Simulation, path: Path, outputs: Outputs | None) -> Path:
        """The checkpoint at `path`; the path written."""

    def write_pieces(self, folder: Path, fields: tuple[str, ...]) -> None:
        """Each rank's piece of the frame about to be written, with `fields`, into
        `folder`."""


class CoreStepper:
    """A serial run: the simulation's own core, with nothing to agree on."""

    def __init__(self, core: _core.Simulation) -> None:
        self.core = core

    @property
    def step(self) -> int:
        return int(self.core.step)

    @property
    def time(self) -> float:
        return float(self.core.time)

    def advance(self, steps: int) -> None:
        self.core.run(steps)

    def first_forces(self) -> None:
        self.core.run(0)  # prescribed motion and contact of the current step

    def collect(self, measures: bool = True) -> None:
        pass

    def agree(self, value: T) -> T:
        return value

    def on_root(self, action: Callable[[], T]) -> T:
        return action()

    def any_rank(self, flag: bool) -> bool:
        return flag

    def together(self, action: Callable[[], object], doing: str) -> None:
        action()

    def broken_bonds(self) -> int:
        return int(self.core.broken_bonds())

    def step_data(
        self, sim: Simulation, tracked: tuple[int, ...], whole: bool, frame: tuple[str, ...] | None
    ) -> StepData | None:
        return None

    def save_checkpoint(self, sim: Simulation, path: Path, outputs: Outputs | None) -> Path:
        return checkpoints.save(sim, path, outputs)

    def write_pieces(self, folder: Path, fields: tuple[str, ...]) -> None:
        pass  # a serial run's frame writer writes its one piece


@dataclass(frozen=True)
class LoopParts:
    """What the loop drives besides the simulation's public API (its core, stop criteria and
    writers read that): Simulation.run hands these over, so the loop reads no private member of
    Simulation and a test can give its own."""

    outputs: Outputs | None
    record: RunRecord
    checkpoints: CheckpointPlan | None
    tuner: threads.ThreadTuner | None  # None: the thread count stays as it is
    after_chunk: Callable[[], None]  # e.g. Interactions.warn_deep_contact
    stepper: Stepper


@dataclass
class RunRecord:
    """What a simulation's runs have done in this process (run.json's status and timings)."""

    status: str = "not run"
    wall_seconds: float = 0.0
    steps_run: int = 0


class SignalCatcher:
    """During a run, Ctrl-C (SIGINT) and SIGTERM only set ``caught``: the run finishes its
    chunk of steps and stops cleanly. A second signal interrupts at once. Outside the main
    thread (where handlers cannot be installed) nothing changes."""

    def __init__(self) -> None:
        self.caught = False
        self._previous: dict[int, object] = {}

    def _handle(self, number: int, frame: object) -> None:
        if self.caught:
            raise KeyboardInterrupt
        self.caught = True

    def __enter__(self) -> SignalCatcher:
        if threading.current_thread() is threading.main_thread():
            for number in (signal.SIGINT, signal.SIGTERM):
                self._previous[number] = signal.signal(number, self._handle)
        return self

    def __exit__(self, *exc: object) -> None:
        for number, handler in self._previous.items():
            signal.signal(number, handler)  # type: ignore[arg-type]


def steps_to_run(
    time: float, dt: float, steps: int | None, until: float | None, check_every: int
) -> int:
    """The number of steps a run(steps, until=...) takes from time `time` [s] at time step
    `dt` [s]: ceil((until - t) / dt) for a time; InputError for bad arguments."""
    if (steps is None) == (until is None):
        raise InputError("give either steps or until")
    if steps is not None:
        check_number("run: steps", steps, integer=True)
    if until is not None:
        check_number("run: until", until)
        if not np.isfinite(until):
            raise InputError(f"until must be a finite time, got {until}")
        steps = max(0, int(np.ceil((until - time) / dt - 1e-9)))
    assert steps is not None
    if steps < 0:
        raise InputError(f"steps must be non-negative, got {steps}")
    if not (isinstance(check_every, int) and check_every > 0):
        raise InputError(f"check_every must be a positive number of steps, got {check_every}")
    return int(steps)


def run_in_folder(sim: Simulation, plan: RunPlan, parts: LoopParts) -> str | None:
    """The run, in its output folder when outputs are set: its space checked, its lock held
    while it writes, and run.json with its status at the end, whatever ends it."""
    out, record = parts.outputs, parts.record
    serial = isinstance(parts.stepper, CoreStepper)
    parts.stepper.on_root(lambda: _start_writing(sim, plan, out, serial))  # refused: all stop
    if out is None:
        return advance(sim, plan, parts)
    record.status = "running"
    try:
        reason = advance(sim, plan, parts)
        record.status = f"stopped: {reason}" if reason else "finished"
        return reason
    except KeyboardInterrupt:
        record.status = "interrupted"
        raise
    except BaseException as error:
        record.status = f"failed: {error}"
        raise
    finally:
        try:
            out.write_run_record(sim)
        except OSError:
            pass  # a full disk: the error that stopped the run is the one to report
        out.folder.stop_writing()


def _start_writing(sim: Simulation, plan: RunPlan, out: Outputs | None, serial: bool) -> None:
    """The output folder checked for space and locked, when outputs are set; refused to a
    `serial` run on one of several MPI ranks, with what to do (launch.serial_copies_hint)."""
    if out is None:
        return
    # The frames this run writes: one every `every` steps, the last step's when it falls
    # between, and step 0's when none is written yet; each about 8 bytes per component of its
    # fields per node.
    steps = plan.steps
    frames = steps // out.every + (steps % out.every > 0) + (out.frames == 0)
    out.folder.require_space(frames, sim.node_count * (12 + 8 * 3 * len(out.fields)))
    try:
        out.folder.start_writing()
    except InputError as error:
        if not serial:
            raise
        from granulate.parallel.launch import serial_copies_hint

        raise InputError(f"{error}{serial_copies_hint()}") from None


def _report(progress: Callable[[Progress], None] | None, report: Progress) -> None:
    """`report` to the `progress` function, when this rank has one."""
    if progress is not None:
        progress(report)


def chunk_end(step: int, plan: RunPlan, parts: LoopParts, target: int, limit: int) -> int:
    """Steps from `step` to the next place the loop must stop at: the run's end, an output or
    history step, a stop check, a checkpoint, or `limit` (about half a second)."""
    out, check_every = parts.outputs, plan.check_every
    boundaries = [target - step, limit]
    if out is not None:
        boundaries.append(out.steps_to_next(step))
    if plan.stop:
        boundaries.append(check_every - step % check_every)
    to_checkpoint = None if parts.checkpoints is None else parts.checkpoints.steps_to_next(step)
    if to_checkpoint is not None:
        boundaries.append(to_checkpoint)
    return min(boundaries)


def advance(sim: Simulation, plan: RunPlan, parts: LoopParts) -> str | None:
    """The time loop: chunks of steps between outputs, stop checks and checkpoints, with the
    thread count the tuner picks; the reason a stop criterion gave, or None."""
    stepper, out = parts.stepper, parts.outputs
    if stepper.agree(out is not None and out.frames == 0):
        stepper.first_forces()  # the forces of step 0 (prescribed motion, contact), for the frame
        write_outputs(stepper, sim, out)
    target = stepper.step + plan.steps
    first_step = stepper.step
    most = threads.get_num_threads()
    start = wallclock.perf_counter()
    reason = None
    try:
        with SignalCatcher() as signals:
            chunks = _Chunks(sim, plan, parts, start)
            reports = stepper.agree(plan.progress is not None)
            while stepper.step < target and reason is None:
                reason = chunks.run(target)
                if reports:  # every rank together: a function raising on one stops every rank
                    call = functools.partial(_report, plan.progress, chunks.progress(target))
                    stepper.together(call, "in its progress function")
                if stepper.any_rank(signals.caught):
                    path = stepper.agree(checkpoints.interrupt_path(parts.checkpoints, out))
                    saved = None if path is None else stepper.save_checkpoint(sim, path, out)
                    where = f"; checkpoint written to {saved}" if saved else ""
                    raise KeyboardInterrupt(f"interrupted at step {stepper.step}{where}")
    finally:
        _core.set_num_threads(most)
        parts.record.wall_seconds += wallclock.perf_counter() - start
        parts.record.steps_run += stepper.step - first_step
    if plan.gather:
        stepper.collect()  # the end state in the simulation (rank 0's, in a distributed run)
    final = plan.write_final or reason is not None
    write_outputs(stepper, sim, out, final=final, collected=plan.gather)
    return reason


def write_outputs(
    stepper: Stepper,
    sim: Simulation,
    out: Outputs | None,
    final: bool | None = None,
    collected: bool = False,
) -> None:
    """The current step's outputs, written by rank 0 (Outputs.write_step; with `final`,
    write_final with that frame flag) once every rank has written its piece of the frame
    they write, when the frames go in pieces written by the ranks. They read the step made of
    the ranks' measures (stepper.step_data) or, when `collected` or that cannot be, the
    whole state collected into `sim`."""
    data = None
    if not collected:
        planned = None  # rank 0's: the tracked bodies, and whether the outputs read the whole
        if out is not None:
            tracked = tuple(body.index for body in out.tracked)
            step = stepper.step
            planned = (tracked, out.needs_whole_state(step, final), out.one_file_frame(step, final))
        agreed = stepper.agree(planned)
        if agreed is not None:  # the step made of the ranks' measures, or the state collected
            data = stepper.step_data(sim, *agreed)
    mine = None  # rank 0's: where the pieces go and their fields, when the frame has pieces
    if out is not None and (folder := out.piece_folder(stepper.step, final)) is not None:
        mine = (folder, out.fields)
    pieces = stepper.agree(mine)
    if pieces is not None:
        stepper.write_pieces(*pieces)
    if final is None:
        stepper.on_root(lambda: out.write_step(sim, data) if out is not None else None)
    else:
        stepper.on_root(
            lambda: out.write_final(sim, frame=final, data=data) if out is not None else None
        )


def stop_reason(stepper: Stepper, sim: Simulation, criteria: Sequence[StopCriterion]) -> str | None:
    """The reason of the first of `criteria` met now, or None, on every rank: each reads the
    run's measures (Simulation.measures: on ranks, the ranks' put together), or rank 0's whole
    simulation when it needs the whole state (its state collected before)."""
    measured = sim.measures()
    for criterion in criteria:
        if criterion.needs_whole_state:
            reason = stepper.on_root(lambda c=criterion: c.check(sim))
        else:
            reason = criterion.check(measured)
        if reason is not None:
            return reason
    return None


class _Chunks:
    """The chunks of one run: each up to the next stopping place, about half a second long (as
    rank 0 measures it, in a distributed run)."""

    def __init__(self, sim: Simulation, plan: RunPlan, parts: LoopParts, start: float) -> None:
        self.sim, self.plan, self.parts, self.start = sim, plan, parts, start
        self.stepper = parts.stepper
        self.limit = 10  # steps: the first chunk measures the rate
        self.rate = 0.0

    def run(self, target: int) -> str | None:
        """One chunk, then its outputs, stop check and checkpoint; a stop criterion's reason."""
        sim, plan, parts, stepper = self.sim, self.plan, self.parts, self.stepper
        out, tuner = parts.outputs, parts.tuner
        chunk = chunk_end(stepper.step, plan, parts, target, self.limit)
        if tuner is not None:
            count = tuner.threads()
            chunk = min(chunk, tuner.step_cap() or chunk)
            _core.set_num_threads(count)
        chunk = stepper.agree(chunk)
        began = wallclock.perf_counter()
        stepper.advance(chunk)
        elapsed = wallclock.perf_counter() - began
        if tuner is not None:
            tuner.record(count, chunk, elapsed)
        parts.after_chunk()
        # Aim at chunks of about half a second: responsive to Ctrl-C and progress.
        self.rate = chunk / max(elapsed, 1e-9)
        self.limit = int(min(10_000, max(1, 0.5 * self.rate)))
        step = stepper.step
        writes = out is not None and out.is_output_step(step)
        checks = bool(plan.stop) and step % plan.check_every == 0
        checkpoint = parts.checkpoints
        saves = checkpoint is not None and checkpoint.is_due(step)
        writes, saves = stepper.agree((writes, saves))
        whole = checks and any(criterion.needs_whole_state for criterion in plan.stop)
        if whole:
            stepper.collect(measures=writes)
        if writes:
            write_outputs(stepper, sim, out, collected=whole)
        reason = stop_reason(stepper, sim, plan.stop) if checks else None
        if saves and checkpoint is not None:
            stepper.save_checkpoint(sim, checkpoint.path, out)
            checkpoint.saved()
        return reason

    def progress(self, target: int) -> Progress:
        """Where the run stands (every rank computes it; rank 0 reports it)."""
        stepper = self.stepper
        return Progress(
            stepper.step,
            int(target),
            stepper.time,
            stepper.broken_bonds(),
            self.rate,
            self.parts.record.wall_seconds + wallclock.perf_counter() - self.start,
        )
