"""Stop criteria: conditions that end a run cleanly before its last step.

Pass them to ``Simulation.run(..., stop=[...])``; they are checked every ``check_every`` steps
(a fixed step interval, so a resumed run stops at the same step). ``run`` returns the reason
of the first one met, or None when it ran to the end.

- ``KineticEnergyBelow(energy, after=0)``: total kinetic energy below ``energy`` [J; J/m in
  2D], once the simulated time is past ``after`` [s] (a settled pile).
- ``WallDisplacement(wall, distance)``: the wall has moved at least ``distance`` [m].
- ``ParticlesBroken(count)``: at least ``count`` particles have lost every bond.
- ``BrokenBonds(count)``: at least ``count`` bonds are broken.
- ``NodeDistance(distance)``: a node is farther than ``distance`` [m] from the origin.

Each reads the run through the measures of ``RunMeasures``, which a Simulation has and which a
distributed run makes on every rank with one reduction each (parallel/run_measures.py), the
same values to the bit: its ranks need not send rank 0 their nodes to check them. A criterion
of your own (a StopCriterion subclass) is given the Simulation: a distributed run gathers the
whole state on rank 0 and checks it there, unless its class sets ``needs_whole_state = False``
because it reads only RunMeasures.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import ClassVar, Protocol

import numpy as np

from granulate.errors import InputError
from granulate.input_errors import checked_arguments


class RunMeasures(Protocol):
    """What the built-in criteria read of a run: a Simulation, or on every rank of a
    distributed run its ranks' measures put together (the same bits)."""

    @property
    def time(self) -> float: ...

    def kinetic_energy(self) -> float: ...

    def wall_displacement(self, name: str) -> float: ...

    def fully_broken_particles(self) -> int: ...

    def broken_bonds(self) -> int: ...

    def farthest_node_distance(self) -> float: ...


class StopCriterion(ABC):
    """A condition checked during a run (see the module docstring)."""

    #: False: ``check`` reads only RunMeasures. True: it is given the whole Simulation (in a
    #: distributed run, rank 0's, after the ranks sent it their state).
    needs_whole_state: ClassVar[bool] = True

    @abstractmethod
    def check(self, run: RunMeasures) -> str | None:
        """The reason to stop, or None."""


class _MeasuredCriterion(StopCriterion):
    """A built-in criterion: it reads RunMeasures only."""

    needs_whole_state: ClassVar[bool] = False


@checked_arguments
@dataclass(frozen=True)
class KineticEnergyBelow(_MeasuredCriterion):
    """Stop when the kinetic energy [J; J/m in 2D] is below ``energy``, from simulated time
    ``after`` [s] on. A run that starts at rest is below any threshold at its first check:
    give ``after`` (say, the time a grain takes to fall onto the pile) so that it stops when
    the grains have settled, not before they move."""

    energy: float
    after: float = 0.0

    def __post_init__(self) -> None:
        if not (self.energy > 0 and np.isfinite(self.energy)):
            raise InputError(f"KineticEnergyBelow needs a positive energy, got {self.energy}")

    def check(self, run: RunMeasures) -> str | None:
        if run.time < self.after:
            return None
        energy = run.kinetic_energy()
        return (
            f"kinetic energy {energy:.4g} below {self.energy:.4g}" if energy < self.energy else None
        )


@checked_arguments
@dataclass(frozen=True)
class WallDisplacement(_MeasuredCriterion):
    wall: str
    distance: float

    def __post_init__(self) -> None:
        if not (self.distance > 0 and np.isfinite(self.distance)):
            raise InputError(f"WallDisplacement needs a positive distance, got {self.distance}")

    def check(self, run: RunMeasures) -> str | None:
        moved = run.wall_displacement(self.wall)
        if moved >= self.distance:
            return f"wall {self.wall!r} moved {moved:.4g} m (limit {self.distance:.4g} m)"
        return None


@checked_arguments
@dataclass(frozen=True)
class ParticlesBroken(_MeasuredCriterion):
    count: int

    def __post_init__(self) -> None:
        if not (isinstance(self.count, int) and self.count > 0):
            raise InputError(f"ParticlesBroken needs a positive count, got {self.count!r}")

    def check(self, run: RunMeasures) -> str | None:
        broken = run.fully_broken_particles()
        if broken >= self.count:
            return f"{broken} particles have lost every bond (limit {self.count})"
        return None


@checked_arguments
@dataclass(frozen=True)
class BrokenBonds(_MeasuredCriterion):
    count: int

    def __post_init__(self) -> None:
        if not (isinstance(self.count, int) and self.count > 0):
            raise InputError(f"BrokenBonds needs a positive count, got {self.count!r}")

    def check(self, run: RunMeasures) -> str | None:
        broken = run.broken_bonds()
        return f"{broken} bonds broken (limit {self.count})" if broken >= self.count else None


@checked_arguments
@dataclass(frozen=True)
class NodeDistance(_MeasuredCriterion):
    """A node is farther than ``distance`` [m] from the origin (a particle escaped the domain;
    PeriDEM's ``Output_Criteria: max_node_dist``)."""

    distance: float

    def __post_init__(self) -> None:
        if not (self.distance > 0 and np.isfinite(self.distance)):
            raise InputError(f"NodeDistance needs a positive distance, got {self.distance}")

    def check(self, run: RunMeasures) -> str | None:
        farthest = run.farthest_node_distance()
        if farthest > self.distance:
            return f"a node is {farthest:.4g} m from the origin (limit {self.distance:.4g} m)"
        return None
