"""Simulation's view of the run: the state as NumPy views, energies and counts, fragments, the
particle and contact tables, stresses and the run's summary.

The measures themselves live in granulate.analysis (on the core's arrays) and in
granulate.fragments, granulate.network and granulate.particle_table; this is the front door to
them. ``SimulationResults`` is a part of ``granulate.Simulation``, not a class to use alone.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from granulate import _core, core_model, fragments, network, particle_table, threads
from granulate._version import __version__
from granulate.analysis import Analysis, read_only
from granulate.assembly import Assembly, Body
from granulate.errors import InputError
from granulate.evaluation import Evaluation
from granulate.interactions import Interactions
from granulate.run_loop import RunRecord
from granulate.shapes import Shape
from granulate.writers.outputs import Outputs


class SimulationResults:
    """The results half of Simulation's API (see granulate.simulation.Simulation)."""

    # What Simulation provides (made in its __init__ and _build).
    dimension: int
    case_fingerprint: str
    bodies: list[Body]
    _assembly: Assembly
    _interactions: Interactions
    _core: _core.Simulation | None
    _model: _core.Model | None
    _analysis: Analysis | None
    _reference: NDArray[np.float64] | None
    _gravity: NDArray[np.float64]
    _precracks: list[tuple[NDArray[np.float64], NDArray[np.float64], Shape | None]]
    _tuner: threads.ThreadTuner | None
    _record: RunRecord
    _output: Outputs | None
    _gathered: Evaluation | None
    _comm: Any
    _distributed: Any  # granulate.parallel.DistributedRun, once a distributed run is made
    _build: Callable[[], _core.Simulation]
    _distributed_run: Callable[[], Any]

    @property
    def positions(self) -> NDArray[np.float64]:
        """(n, 3) current positions x [m]: a live, writable view. Writing moves nodes before
        or between runs (bonds stretch accordingly; contact lists follow); the forces are
        recomputed at the next step. Read-only in a distributed run (rank 0's copy of the
        gathered state: the grains live on the ranks; set the start with start_from)."""
        positions = self._build().positions
        return positions if self._comm is None else read_only(positions)

    @property
    def velocities(self) -> NDArray[np.float64]:
        """(n, 3) velocities v [m/s]: a live, writable view (set initial or changed velocities
        before or between runs; prescribed nodes keep their prescribed motion). Read-only in a
        distributed run, as positions."""
        velocities = self._build().velocities
        return velocities if self._comm is None else read_only(velocities)

    @property
    def forces(self) -> NDArray[np.float64]:
        """(n, 3) net force densities f [N/m^3] of the last step: a live, read-only view (the
        next step starts from them)."""
        return read_only(self._build().forces)

    def bond_forces(self) -> NDArray[np.float64]:
        """(n, 3) the bond force densities b [N/m^3] at the current positions: the peridynamic
        part of ``forces``, so ``forces - bond_forces()`` is what contact, walls, gravity and
        loads put on each node. A new array, from one pass over the bonds."""
        return np.asarray(self._build().bond_force_densities()).reshape(-1, 3)

    @property
    def displacements(self) -> NDArray[np.float64]:
        """(n, 3) displacements x - X [m] (a copy)."""
        core = self._build()
        return core.positions - self._reference

    @property
    def volumes(self) -> NDArray[np.float64]:
        """(n,) nodal volumes [m^3; m^2 in 2D], read-only."""
        self._build()
        assert self._model is not None
        return read_only(self._model.volumes)

    @property
    def damage(self) -> NDArray[np.float64]:
        """(n,) damage phi = 1 - intact / initial influence-weighted volume of the bonds,
        read-only."""
        return self.analysis.damage_phi()

    @property
    def damage_z(self) -> NDArray[np.float64]:
        """(n,) PeriDEM's Damage_Z: max over a node's bonds of |stretch| / s0."""
        return self.analysis.damage()[1]

    @property
    def time(self) -> float:
        """Simulated time [s] (in a distributed run, on every rank)."""
        if self._comm is not None:
            return float(self._distributed_run().local.core.time)
        return self._build().time

    @property
    def step(self) -> int:
        """Steps taken (in a distributed run, on every rank)."""
        if self._comm is not None:
            return int(self._distributed_run().local.core.step)
        return self._build().step

    def kinetic_energy(self) -> float:
        """sum 1/2 rho V |v|^2 [J; J/m in 2D], correctly rounded (granulate.exact_sum)."""
        return self.analysis.kinetic_energy()

    def farthest_node_distance(self) -> float:
        """The largest distance of a node from the origin [m]."""
        return self.analysis.farthest_node_distance()

    def strain_energy(self) -> float:
        """sum W_i V_i over intact bonds [J; J/m in 2D]."""
        return self.analysis.strain_energy()

    def broken_bonds(self) -> int:
        """Number of broken bonds, each counted once."""
        return self._build().broken_bonds()

    def wall_displacement(self, name: str) -> float:
        """Distance the named wall has moved (translation) or angle it has turned [m or rad]."""
        core = self._build()
        names = self._interactions.wall_names
        for label, wall in zip(names, core.walls, strict=True):
            if label == name:
                return float(wall.displacement(core.time))
        raise InputError(f"no wall named {name!r}; walls: {', '.join(names) or 'none'}")

    def fully_broken_particles(self) -> int:
        """Number of particles none of whose bonds is intact (with at least one bond)."""
        return self.analysis.fully_broken_particles(self.bodies)

    def precrack(
        self, point: ArrayLike, normal: ArrayLike, *, region: Shape | None = None
    ) -> int | None:
        """Break the bonds that cross the plane through ``point`` with ``normal`` (in the reference
        configuration), only those whose midpoint lies in ``region`` if given: a pre-crack or a
        notch without removing material. Before the simulation is built (the first run, or the
        first look at its state) the pre-crack is kept and applied when it is, and None is
        returned, so contact, walls and loading can still be set; after, the bonds break at
        once and their number is returned."""
        vector = self._assembly.vector
        crack = (vector(point, "point"), vector(normal, "normal"), region)
        if region is not None and not isinstance(region, Shape):
            raise InputError(f"precrack: region must be a shape, got {type(region).__name__}")
        if self._distributed is not None:
            raise InputError("precrack a distributed simulation before its first run")
        if self._core is None:
            self._precracks.append(crack)
            return None
        return core_model.break_crossing_bonds(self._core, self.model, *crack)

    def fragments(self, min_nodes: int = 1) -> list[NDArray[np.uint32]]:
        """Pieces held together by intact bonds, largest first, each as its node indices.

        Fragments smaller than ``min_nodes`` (dust, single detached nodes) are left out.
        """
        return self.analysis.fragments(min_nodes)

    def gravity_energy(self) -> float:
        """Potential energy in the gravity field, -sum m_i g . x_i [J; J/m in 2D] (zero at the
        origin)."""
        return self.analysis.gravity_energy(self._gravity)

    def fragment_table(self) -> fragments.Table:
        """One row per fragment (debris included, flagged) of the current state: its id,
        parent particle, nodes, mass, volume, centre of mass, velocity and equivalent diameter
        (granulate.fragments; ``pandas.DataFrame(table)`` makes it a data frame)."""
        return self.analysis.fragment_table()

    @property
    def analysis(self) -> Analysis:
        """The measures of the current state (granulate.analysis.Analysis), built on first
        access: fragments, the particle and contact tables, particle stresses."""
        self._build()
        assert self._analysis is not None
        return self._analysis

    @property
    def node_count(self) -> int:
        return self._assembly.node_count

    @property
    def bond_count(self) -> int:
        """Bonds, each counted once per end (as LAMMPS counts them)."""
        self._build()
        assert self._model is not None
        return self._model.bond_count

    def summary(self) -> dict[str, float | int]:
        """Counts, time step and timings of the run so far: ``steps`` is the current step,
        ``steps_run`` and ``wall_seconds`` the steps advanced and the wall time taken by this
        process's runs (after a resume, only the resumed part)."""
        # A distributed run's step, time and timings are rank 0's part's (every part steps
        # with the serial run's time step): rank 0's whole simulation is built only when the
        # whole state is gathered.
        run = self._distributed
        core = self._build() if run is None else run.local.core
        bonds = self.bond_count if run is None else run.bond_count
        stable = core.stable_time_step if run is None else run.stable_dt
        phases = core.phase_times
        return {
            "granulate": __version__,
            "case_fingerprint": self.case_fingerprint,
            "dimension": self.dimension,
            "bodies": len(self.bodies),
            "nodes": self.node_count,
            "bonds": bonds,
            "dt": core.time_step,
            "stable_dt": stable,
            "steps": core.step,
            "time": core.time,
            "ranks": 1 if self._comm is None else int(self._comm.Get_size()),
            "threads": threads.get_num_threads(),
            "threads_in_use": self._tuner.current if self._tuner is not None else None,
            "status": self._record.status,
            "steps_run": self._record.steps_run,
            "wall_seconds": self._record.wall_seconds,
            "peridynamics_seconds": phases.peridynamics,
            "integration_seconds": phases.integration,
            "loading_seconds": phases.loading,
            "contact_seconds": phases.contact,
            "neighbor_list_rebuilds": core.contact_statistics.rebuilds,
        }

    @property
    def seconds_at_threads(self) -> dict[int, float] | None:
        """The run time [s] the adaptive thread policy measured at each thread count it tried
        (granulate.threads), or None before a run or under a fixed thread count."""
        return None if self._tuner is None else dict(self._tuner.seconds_at)

    def particle_table(
        self, contacts: network.Table | None = None, damage: ArrayLike | None = None
    ) -> particle_table.Table:
        """One row per particle of the current state (granulate.particle_table): time, centre
        of mass [m], velocity [m/s], angular velocity [rad/s], mass [kg; kg/m in 2D], radius
        of gyration [m], volume-weighted mean damage, coordination and Love-Weber stress [Pa]
        (granulate.network), from `contacts` (default: ``contact_table()``)."""
        contacts = self.contact_table() if contacts is None else contacts
        return self.analysis.particles(contacts, damage)[0]

    def contact_table(self) -> network.Table:
        """One row per contact of the last force evaluation (pairs of particles or of their
        fragments, and particles on walls): the bodies, contact point [m], normal, force on
        the first body [N; N/m in 2D], normal and tangential force (granulate.network; wall
        k is ``list(sim.wall_reactions())[k]``)."""
        if self._gathered is not None:
            return self._gathered.contacts
        return self.analysis.contact_table()

    def evaluation(self) -> Evaluation:
        """What the last force evaluation left besides the nodes' state: contacts, contact
        energy and counts, wall reactions (granulate.evaluation). In a distributed run, rank 0's
        simulation holds them as gathered at the last output, stop check or end of a run."""
        if self._gathered is not None:
            return self._gathered
        return Evaluation.of_core(self._build(), self.analysis.contact_table())

    def particle_stresses(
        self,
        method: Literal["contacts", "bonds"] = "contacts",
        contacts: network.Table | None = None,
    ) -> NDArray:
        """Each particle's mean stress, (particles, D, D) [Pa; tension positive]: Love-Weber
        from its contacts (`contacts`: the current contact table, made when not given), or from
        its bond forces (granulate.network; the two agree for a particle at rest)."""
        if method == "contacts" and contacts is None:
            contacts = self.contact_table()
        return self.analysis.particle_stresses(method, contacts)

    @property
    def output_seconds(self) -> float:
        """Wall-clock seconds spent writing outputs so far (by the current output(...))."""
        return 0.0 if self._output is None else self._output.seconds
