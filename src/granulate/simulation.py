"""The Python front of a granulate simulation.

Build the model (bodies, materials, loading, outputs), then ``run``. The model is handed to the
C++ core on the first run (or the first access to the state); after that, bodies can no longer
be added. State arrays (``positions``, ``velocities``, ...) are zero-copy NumPy views into the
core: they stay valid as long as the simulation exists, and writing to ``velocities`` before a
run sets initial conditions.

Units are SI. In 2D a body is a slab of unit thickness: volumes are areas [m^2], force
densities stay N/m^3, forces (force density x volume) are N per metre of thickness and
energies J per metre.

Simulation is one class in three files: the set-up calls (bodies, loading, contact, walls,
outputs) are in simulation_setup.py, the views of the state and the measures in
simulation_results.py; this file holds the construction, the build of the core, the time step,
run and checkpoints.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from granulate import (
    _core,
    checkpoints,
    core_model,
    fingerprints,
    run_loop,
    threads,
)
from granulate.analysis import Analysis
from granulate.assembly import Assembly, Body
from granulate.checkpoints import CheckpointPlan
from granulate.errors import GranulateWarning, InputError
from granulate.evaluation import Evaluation
from granulate.input_errors import check_number, unknown_name
from granulate.interactions import Interactions
from granulate.load_balance import LoadBalance
from granulate.loading import Components, Loading
from granulate.materials import Material
from granulate.run_loop import LoopParts, Progress, RunPlan, RunRecord
from granulate.shapes import Shape
from granulate.simulation_results import SimulationResults
from granulate.simulation_setup import SimulationSetup
from granulate.stopping import RunMeasures, StopCriterion
from granulate.writers.outputs import Outputs
from granulate.writers.vtu_frame import FIELDS

if TYPE_CHECKING:
    from granulate.node_map import NodeMap
    from granulate.parallel import DistributedRun
    from granulate.parallel.node_split import NodeSplitRun

__all__ = ["FIELDS", "Body", "Components", "Progress", "Simulation"]


def _warn_above_stable(dt: float, stable: float, stacklevel: int) -> None:
    """A GranulateWarning when the time step dt exceeds the stable estimate [s]."""
    if dt > stable:
        warnings.warn(
            f"time step {dt:.4g} s exceeds the stable estimate {stable:.4g} s; the run may "
            "become unstable",
            GranulateWarning,
            stacklevel=stacklevel,
        )


def _check_time_step(dt: float, stable: float, tolerance: float = 5.0) -> None:
    """InputError if the time step dt exceeds `tolerance` times the stable estimate [s]."""
    if dt > tolerance * stable:
        raise InputError(
            f"time step {dt:.4g} s is {dt / stable:.1f} times the stable estimate {stable:.4g} s; "
            "use at most the estimate (or leave dt out: the default is 0.8 times it)"
        )


class Simulation(SimulationSetup, SimulationResults):
    """A peridynamic simulation of one or more bodies.

    Args:
        dimension: 2 or 3.
        plane: 2D assumption, ``"strain"`` (default) or ``"stress"``; ignored in 3D.
            ``"peridem"`` reproduces PeriDEM's 2D LPS (3D coefficients and critical stretch in
            2D), for comparisons with PeriDEM only: it does not give the material's 2D moduli.
        dt: time step [s]; default ``dt_safety`` times the stable estimate.
        dt_safety: fraction of the stable estimate used when ``dt`` is not given.
        gravity: body acceleration [m/s^2], e.g. (0, -9.81, 0).
        viscous_damping: background damping rate gamma [1/s] (force density -gamma rho v) for
            quasi-static settling; 0 (off) for dynamics, since it also damps rigid motion.
        comm: an mpi4py communicator (``MPI.COMM_WORLD``) to run on its ranks: whole grains per
            rank, the serial run's results bit for bit (granulate.parallel, docs/parallel.md).
            Every rank sets the simulation up alike and calls ``output``, ``run``, ``dt``,
            ``step``, ``time`` and the checkpoint methods together; rank 0 writes the outputs,
            and its simulation holds the whole state (gathered at each output, stop check and
            run's end) for the results: ``positions``, tables, energies. The other ranks' raise.
    """

    def __init__(
        self,
        dimension: int = 2,
        plane: Literal["strain", "stress", "peridem"] = "strain",
        *,
        dt: float | None = None,
        dt_safety: float = 0.8,
        gravity: ArrayLike | None = None,
        viscous_damping: float = 0.0,
        comm: object | None = None,
    ) -> None:
        if dimension not in (2, 3):
            raise InputError(f"dimension must be 2 or 3, got {dimension!r}")
        if plane not in ("strain", "stress", "peridem"):
            raise InputError(f"plane must be 'strain', 'stress' or 'peridem', got {plane!r}")
        if not 0 < dt_safety <= 1:
            raise InputError(f"dt_safety must be in (0, 1], got {dt_safety}")
        self.dimension = dimension
        self.plane = plane
        self._dt = None if dt is None else self._check_dt(dt)
        self._dt_safety = dt_safety
        self._gravity = np.zeros(3)
        self._assembly = Assembly(dimension)
        self._loading = Loading(self._assembly)
        self._interactions = Interactions(self._assembly)
        self._output: Outputs | None = None
        self._core: _core.Simulation | None = None
        self._model: _core.Model | None = None
        self._analysis: Analysis | None = None
        self._gathered: Evaluation | None = None  # a distributed run's, on rank 0
        #: Rank 0 of a distributed run: the ranks have moved on (steps, a checkpoint loaded in
        #: pieces) since its simulation last took their state, which it then refuses to give.
        self._ranks_ahead = False
        #: what rank 0 checked it has the memory for (_require_room_on_root)
        self._room_checked: set[str] = set()
        self._reference: NDArray[np.float64] | None = None
        self._record = RunRecord()
        self._precracks: list[tuple[NDArray[np.float64], NDArray[np.float64], Shape | None]] = []
        self._start: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None  # start_from
        self._start_step = 0  # start_from's step
        self._tuner: threads.ThreadTuner | None = None
        self._core_materials: list[Material] = []
        self._setup_digest: str | None = None
        self._checkpoint: CheckpointPlan | None = None
        self._comm = comm
        self._load_balance = LoadBalance()
        self._distributed: DistributedRun | NodeSplitRun | None = None
        self._output_path: Path | None = None  # output's directory, on every rank
        self._dt_warned = False  # a distributed run's parts: said once, by rank 0
        #: Extra text identifying the set-up (a case file's hash), checked by load_checkpoint.
        self.case_fingerprint = ""
        self.viscous_damping = viscous_damping
        if gravity is not None:
            self.gravity = gravity  # type: ignore[assignment]

    # ------------------------------------------------------------------ building
    @staticmethod
    def _check_dt(dt: float) -> float:
        check_number("time step dt", dt)
        if not (np.isfinite(dt) and dt > 0):
            raise InputError(f"time step dt must be a positive number of seconds, got {dt!r}")
        return float(dt)

    #: The attributes a user may set besides the properties with setters.
    _SETTABLE = ("dimension", "plane", "case_fingerprint")

    def __setattr__(self, name: str, value: object) -> None:
        """Refuses attributes the class does not have: a misspelt or invented one
        (``sim.damping = 5``) would otherwise be stored and do nothing."""
        if name.startswith("_") or name in self._SETTABLE:
            object.__setattr__(self, name, value)
            return
        known = getattr(type(self), name, None)
        if isinstance(known, property) and known.fset is not None:
            object.__setattr__(self, name, value)
            return
        settable = sorted(
            n
            for part in type(self).__mro__
            for n, v in vars(part).items()
            if isinstance(v, property) and v.fset is not None
        )
        what = "cannot be set" if known is not None else "is not an attribute of Simulation"
        raise InputError(f"{name!r} {what}{unknown_name(name, settable)}")

    # ------------------------------------------------------------------ the core
    def _build(self) -> _core.Simulation:
        """The core simulation, made on first use: the model (materials, shapes, particles,
        bonds), contact laws, walls and damping, the time step, loads, initial velocities,
        precracks."""
        if self._comm is not None and self._comm.Get_rank() != 0:
            raise InputError(
                f"this is rank {self._comm.Get_rank()} of a distributed simulation: the whole "
                "state is on rank 0 (read results where comm.Get_rank() == 0)"
            )
        if self._ranks_ahead:
            raise InputError(
                f"rank 0's simulation does not hold the run's state at step {self.step}: it "
                "takes the ranks' state at the end of run() and at outputs that read it, not "
                "after run(..., gather=False) or a checkpoint loaded on ranks (in pieces, or "
                "of bodies cut at node level); run with "
                "gather=True, read sim.measures() on every rank, or read the run's outputs"
            )
        if self._core is not None:
            return self._core
        if not self.bodies:
            raise InputError("the simulation has no body; add one with add_body")
        outer_layers = self._interactions.uses_surface_law()
        model, core_materials = core_model.build_model(self._assembly, self.plane, outer_layers)
        core = _core.Simulation(model)
        self._interactions.apply(core, core_materials)
        self._core_materials = core_materials
        if self._start is not None:
            core.positions[:] = self._start[0]
        self._interactions.check_start(model, core, self.dimension)
        self._set_time_step(core)
        core.step, core.time = self._start_step, self._start_step * core.time_step
        core.set_body_acceleration(tuple(self._gravity))
        core.viscous_damping = self._viscous_damping
        self._loading.apply(core)
        self._assembly.set_initial_velocities(model, core)
        if self._start is not None:
            core.velocities[:] = self._start[1]
        self._model = model
        self._core = core
        self._analysis = Analysis(core, model, len(self.bodies))
        self._reference = model.reference_positions
        for crack in self._precracks:
            core_model.break_crossing_bonds(core, model, *crack)
        return core

    def _subdomain(
        self,
        grains: NDArray[np.int64],
        dt: float | None = None,
        skin: float | None = None,
        initial_motion: bool = True,
    ) -> tuple[Simulation, NodeMap]:
        """A new simulation of the bodies `grains` (increasing indices) alone, set up as this
        one is (loads on their nodes, contact, walls, gravity, damping, precracks, start
        state; the initial velocities unless `initial_motion` is False, for a part whose state
        is restored), with the time step `dt` and neighbour skin `skin` when given; and the map
        of this simulation's node indices to its own (-1: left out). For granulate.parallel,
        whose ranks each hold their grains and ghosts; this simulation is not built."""
        interactions = self._interactions
        part = Simulation(
            self.dimension,
            self.plane,
            dt=dt if dt is not None else self._dt,
            dt_safety=self._dt_safety,
            viscous_damping=self._viscous_damping,
        )
        part._gravity = self._gravity.copy()
        part._dt_warned = True  # the whole simulation's estimate is the one to judge dt by
        assembly, node_map = self._assembly.subset(grains)
        if not initial_motion:
            assembly.initial_velocities = []
        part._assembly = assembly
        part._loading = self._loading.subset(assembly, node_map)
        part._interactions = interactions.on(assembly)
        if skin is not None:
            part._interactions.set_skin(skin)
        part._precracks = list(self._precracks)
        if self._start is not None:
            kept = node_map.kept()  # kept nodes keep their order
            part._start = (self._start[0][kept], self._start[1][kept])
            part._start_step = self._start_step
        return part, node_map

    def _set_time_step(self, core: _core.Simulation) -> None:
        """dt as given (warned above the stable estimate), or dt_safety times that estimate."""
        if self._dt is None:
            core.time_step = self._dt_safety * core.stable_time_step
            return
        if not self._dt_warned:
            _warn_above_stable(self._dt, core.stable_time_step, stacklevel=5)
        core.time_step = self._dt

    @property
    def core(self) -> _core.Simulation:
        """The C++ simulation (built on first access)."""
        return self._build()

    @property
    def model(self) -> _core.Model:
        """The frozen C++ model: nodes, particles, materials, bonds (built on first access)."""
        self._build()
        assert self._model is not None
        return self._model

    @property
    def dt(self) -> float:
        """Time step [s]."""
        if self._comm is not None:
            return self._distributed_run().dt
        return self._build().time_step

    @dt.setter
    def dt(self, value: float) -> None:
        self._dt = self._check_dt(value)
        if self._core is not None:
            _warn_above_stable(self._dt, self._core.stable_time_step, stacklevel=3)
            self._core.time_step = self._dt

    @property
    def distribution(self) -> str | None:
        """How a distributed run (``comm``) deals its work to the ranks: "grains" (whole grains
        per rank, granulate.parallel.DistributedRun) or "nodes" (nothing touches, so the bodies
        are cut at node level, NodeSplitRun); None for a serial run."""
        if self._comm is None:
            return None
        return "nodes" if self._interactions.contact_free() else "grains"

    @property
    def stable_dt(self) -> float:
        """Stable time-step estimate [s] (Silling & Askari's bound, see Model::stable_time_step)."""
        return self._build().stable_time_step

    def run(
        self,
        steps: int | None = None,
        *,
        until: float | None = None,
        stop: Sequence[StopCriterion] = (),
        check_every: int = 100,
        progress: Callable[[Progress], None] | bool | None = None,
        write_final: bool = True,
        gather: bool = True,
    ) -> str | None:
        """Advance ``steps`` time steps, or until simulated time ``until`` [s].

        Writes outputs at step 0 and every ``output(every=...)`` steps, and checkpoints as set
        by ``checkpoint_every``. ``stop`` criteria (granulate.stopping) are checked every
        ``check_every`` steps; the run ends at the first one met and its reason is returned
        (None when the run reached its last step). ``progress=True`` shows a progress bar (a
        terminal or a Jupyter notebook; lines in a log); a callable is called with a Progress
        after each chunk of steps (about every half second). Raises InstabilityError if the
        integration blows up.

        Ctrl-C or SIGTERM during a run finishes the current chunk, writes a checkpoint (when
        checkpoints or outputs are set) and raises KeyboardInterrupt; outputs stay intact.

        When the run ends (its last step or a stop criterion) between output steps, the frame
        and history row of its last step are written too (``write_final=False`` skips them at
        the last step, for a run advanced in pieces; a stop criterion met always writes them),
        and run.json is brought up to date.

        In a distributed run (``comm``), every rank calls it; at its end rank 0's simulation
        takes the ranks' state, so that its results (positions, tables, energies) can be read
        there. ``gather=False`` skips that, for a run too large for one process: rank 0 then
        never builds the whole model unless an output reads it (frames not in pieces, a
        writer that reads the simulation) or a stop criterion does, and its results raise an
        InputError until it takes the state again; ``measures()`` and the outputs give them.
        """
        stepper = self._stepper()
        steps = run_loop.steps_to_run(stepper.time, self.dt, steps, until, check_every)
        self._require_checkpoint_budget(steps)
        if not (progress is None or isinstance(progress, bool) or callable(progress)):
            raise InputError(
                f"progress must be True, False or a function of a Progress, got {progress!r}"
            )
        callback = None if isinstance(progress, bool) else progress
        plan = RunPlan(steps, tuple(stop), check_every, callback, write_final, gather)
        if self._comm is not None:
            self._require_room_on_root(plan)
        parts = LoopParts(
            self._output,
            self._record,
            self._checkpoint,
            self._thread_tuner(threads.get_num_threads()),
            self._after_chunk,
            stepper,
        )
        if progress is True and self._comm is not None and self._comm.Get_rank() != 0:
            progress = None  # rank 0 shows it
        if progress is not True:
            return run_loop.run_in_folder(self, plan, parts)
        from granulate.progress import ProgressReporter

        reporter = ProgressReporter(steps)
        try:
            return run_loop.run_in_folder(self, replace(plan, progress=reporter), parts)
        finally:
            reporter.close()

    def _stepper(self) -> run_loop.Stepper:
        """What advances the run: the core, or the ranks of the distributed run."""
        if self._comm is None:
            self.validate_time_step()
            return run_loop.CoreStepper(self.core)
        from granulate.parallel.stepper import DistributedStepper

        if self._output is not None:  # rank 0's: each rank writes its piece of a frame
            self._output.piece_ranks = self._comm.Get_size()
        return DistributedStepper(self._distributed_run())

    def _distributed_run(self) -> DistributedRun | NodeSplitRun:
        """The run on the ranks of `comm` (made on first use, by every rank together; its time
        step checked as validate_time_step checks a serial one): whole grains per rank, or,
        when nothing touches, the nodes dealt to the ranks (granulate.parallel.node_split)."""
        if self._distributed is None:
            from granulate.parallel import DistributedRun

            if self.distribution == "nodes":  # nothing touches: the nodes are dealt
                from granulate.parallel.node_split import NodeSplitRun

                run: DistributedRun | NodeSplitRun = NodeSplitRun(self, self._comm)
            else:
                run = DistributedRun(self, self._comm)
            _check_time_step(run.dt, run.stable_dt)
            if self._comm.Get_rank() == 0 and self._dt is not None:
                _warn_above_stable(run.dt, run.stable_dt, stacklevel=4)
            self._dt_warned = True  # rank 0's whole simulation, built later, is quiet
            self._distributed = run
        return self._distributed

    def _require_room_on_root(self, plan: RunPlan) -> None:
        """Every rank, before a distributed run's first step: InputError when rank 0 will take
        the whole state in this run (at its end unless plan.gather is False, for outputs or
        stop criteria that read the whole simulation) and the whole model would not fit in
        its memory (whole_state.require_room);
        or when it will join frames of every node from the ranks' rows and those would not
        (vtu_frame.require_room_for_frames): refused now, not hours in. Each checked once."""
        from granulate.parallel.agreement import on_root
        from granulate.parallel.whole_state import require_room
        from granulate.writers.vtu_frame import require_room_for_frames

        self._distributed_run()  # made by every rank together, before any check
        out = self._output  # rank 0's
        gathers, frames = self._comm.bcast(
            (
                plan.gather
                or any(criterion.needs_whole_state for criterion in plan.stop)
                or (out is not None and out.may_need_whole_state()),
                out is not None and not out.pieces,
            ),
            root=0,
        )
        if gathers and "whole model" not in self._room_checked:
            on_root(self._comm, lambda: require_room(self))
            self._room_checked.add("whole model")
        if frames and "frames" not in self._room_checked:
            on_root(self._comm, lambda: require_room_for_frames(self.node_count, out.fields))
            self._room_checked.add("frames")

    def measures(self) -> RunMeasures:
        """What the stop criteria read (granulate.stopping.RunMeasures: time, kinetic energy,
        farthest node, broken bonds, fully broken particles, wall displacements): this
        simulation, or in a distributed run the ranks' measures put together, the same bits,
        without gathering the state (every rank calls it and each of its methods together)."""
        if self._comm is None:
            return self
        return self._distributed_run().measures()

    def _after_chunk(self) -> None:
        """After each chunk of steps: the warning about bodies pressed deep into each other (in
        a distributed run, the deepest on any rank, warned of by rank 0)."""
        if self._distributed is None:
            self._interactions.warn_deep_contact(self.core.contact_statistics)
            return
        deepest = self._distributed.deepest_contact()
        if self._comm.Get_rank() == 0:
            self._interactions.warn_deep_contact(deepest)

    def _thread_tuner(self, most: int) -> threads.ThreadTuner | None:
        """The run's thread-count picker (kept across runs of this simulation), or None when
        the thread count is the user's or there is one CPU (granulate.threads)."""
        if not threads.is_adaptive() or most == 1:
            return None
        if self._tuner is None or max(self._tuner.counts) != most:
            self._tuner = threads.ThreadTuner(most)
        return self._tuner

    def __repr__(self) -> str:
        """What the simulation holds and where it stands, without building it."""
        parts = [f"{self.dimension}D", f"{len(self.bodies)} bodies", f"{self.node_count:,} nodes"]
        if self._core is None:
            parts.append("not built yet (built by the first run)")
        else:
            core = self._core
            parts += [
                f"{self.bond_count:,} bonds",
                f"step {core.step:,}",
                f"t = {core.time:.6g} s",
                f"dt = {core.time_step:.4g} s",
            ]
        if self._interactions.walls:
            parts.append(f"walls: {', '.join(self._interactions.wall_names)}")
        if self._output is not None:
            parts.append(f"output: {self._output.directory} every {self._output.every} steps")
        return f"Simulation({'; '.join(parts)})"

    @property
    def output_directory(self) -> Path | None:
        """Where output(...) writes, or None (in a distributed run: rank 0's, on every rank)."""
        return self._output_path

    @property
    def checkpoint_path(self) -> Path | None:
        """Where checkpoint_every(...) writes, or None."""
        return None if self._checkpoint is None else self._checkpoint.path

    def validate_time_step(self, tolerance: float = 5.0) -> None:
        """InputError if the time step exceeds ``tolerance`` times the stable estimate (a run
        would blow up); the case runner calls it before running."""
        if self._comm is not None:
            return  # the distributed run checks its time step when it is made
        core = self._build()
        _check_time_step(core.time_step, core.stable_time_step, tolerance)

    # ------------------------------------------------------------------ checkpoints
    def checkpoint_every(
        self,
        steps: int | None = None,
        *,
        minutes: float | None = None,
        path: str | Path | None = None,
    ) -> None:
        """Write a checkpoint every ``steps`` steps and/or every ``minutes`` of wall time, and on
        Ctrl-C/SIGTERM, to ``path`` (default: ``checkpoint.npz`` in the output directory). Each
        checkpoint replaces the last one atomically."""
        self._checkpoint = CheckpointPlan.create(steps, minutes, path, self.output_directory)

    def _require_checkpoint_budget(self, steps: int) -> None:
        if self._checkpoint is not None:
            bonds = (
                self._distributed_run().bond_count if self._comm is not None else self.bond_count
            )
            self._checkpoint.require_budget(steps, self.node_count, bonds)

    def fingerprint(self) -> str:
        """Identifies the set-up a checkpoint belongs to: each body's nodes, volumes and bonds,
        loading, walls, contact (frozen once built: hashed once), time step, body force,
        damping and ``case_fingerprint`` (granulate.fingerprints). Materials are
        named by their order, not by object identity, so the fingerprint is the same in every
        process. In a distributed run every rank calls it; each hashes its own grains."""
        if self._comm is not None:
            return self._distributed_run().fingerprint()
        core = self._build()
        if self._setup_digest is None:
            self._setup_digest = fingerprints.whole_model_digest(self, self.model)
        return fingerprints.fingerprint(self, self._setup_digest, core.time_step)

    def save_checkpoint(self, path: str | Path) -> Path:
        """Write the state (positions, velocities, forces, bond states, contact history, time,
        step) and the output bookkeeping to ``path`` atomically (granulate.checkpoints). In a
        distributed run every rank calls it; rank 0 writes the whole state, which restarts on
        any number of ranks or serially."""
        if self._comm is not None:
            return self._distributed_run().save_checkpoint(path, self._output)
        return checkpoints.save(self, path, self._output)

    def load_checkpoint(self, path: str | Path) -> None:
        """Continue from a checkpoint of this same set-up (else InputError): restores the state
        and, when outputs are set, the frame count, the PVD series and history.csv up to the
        checkpoint's step, so that the outputs that follow are those of an uninterrupted run.
        In a distributed run every rank calls it; the checkpoint may come from any number of
        ranks, or from a serial run."""
        if self._comm is not None:
            self._distributed_run().load_checkpoint(path, self._output)
            return
        checkpoints.load(self, path, self._output)
