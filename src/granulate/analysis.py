"""Measures of a built simulation's current state: damage, strain energy, fragments (pieces
held together by intact bonds) and their table, particles broken, the particle table (motion,
damage, coordination, Love-Weber stress), the contact network and particle stresses, and the
gravity energy. Each reads the core's live state when called; the fragment labels are kept for
one step and bond count. A distributed run's rank 0 is given the measures its ranks made of
their own grains instead (GivenMeasures), for the state it gathered. The formulas are in
granulate.fragments, granulate.particle_table and granulate.network."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from granulate import _core, fragments, network, particle_table
from granulate.assembly import Body
from granulate.errors import InputError
from granulate.exact_sum import ExactSum
from granulate.run_sums import Runs


def kinetic_energies(mass: ArrayLike, velocities: ArrayLike) -> NDArray[np.float64]:
    """Per node 1/2 m_i |v_i|^2 [J; J/m in 2D] for masses m_i = rho_i V_i [kg; kg/m in 2D] and
    (n, 3) velocities [m/s]: each row's the same bits wherever it is computed."""
    v = np.asarray(velocities, dtype=np.float64)
    return 0.5 * np.asarray(mass, dtype=np.float64) * _squared_norms(v)


def gravity_energies(
    mass: ArrayLike, positions: ArrayLike, gravity: ArrayLike
) -> NDArray[np.float64]:
    """Per node -m_i g . x_i [J; J/m in 2D] for gravity g [m/s^2] (zero at the origin)."""
    x, g = np.asarray(positions, dtype=np.float64), np.asarray(gravity, dtype=np.float64)
    return -np.asarray(mass, dtype=np.float64) * (x[:, 0] * g[0] + x[:, 1] * g[1] + x[:, 2] * g[2])


def complete_particle_table(
    motion: particle_table.Table,
    volumes: NDArray[np.float64],
    damage: NDArray[np.float64],
    contacts: network.Table,
    time: float,
    dimension: int,
) -> tuple[particle_table.Table, NDArray[np.float64]]:
    """The particle table of particles with these motion columns (particle_table.motion),
    volumes [m^3; m^2 in 2D] and volume-weighted damage, at `time` [s], and their Love-Weber
    stresses (N, D, D) [Pa] from `contacts`: the motion columns then particle, time, damage,
    coordination and the stresses (granulate.particle_table)."""
    count = len(volumes)
    table = dict(motion)
    table["particle"] = np.arange(count)
    table["time"] = np.full(count, time)
    table["damage"] = damage
    table["coordination"] = network.coordination(contacts, count)
    centres = np.column_stack([table[axis] for axis in "xyz"])
    stresses = network.love_weber_stresses(contacts, centres, volumes, dimension)
    particle_table.add_stresses(table, stresses, dimension)
    return table, stresses


def read_only(array: NDArray) -> NDArray:
    """A view of `array` that cannot be written (the core keeps writing the original)."""
    view = array.view()
    view.flags.writeable = False
    return view


def squared_distances(positions: ArrayLike) -> NDArray[np.float64]:
    """Per node |x_i|^2 [m^2], its distance from the origin squared."""
    return _squared_norms(np.asarray(positions, dtype=np.float64))


def _squared_norms(rows: NDArray[np.float64]) -> NDArray[np.float64]:
    """x^2 + y^2 + z^2 of each row, added in that order."""
    return rows[:, 0] * rows[:, 0] + rows[:, 1] * rows[:, 1] + rows[:, 2] * rows[:, 2]


@dataclass(frozen=True)
class GivenMeasures:
    """The measures of every grain at one step made where its bonds are evaluated (each rank of
    a distributed run, of the grains it owns; whole_state.install puts them together), bit for
    bit what the whole core gives: per node the damage phi and PeriDEM's Z (core.damage), the
    fragment label (core.fragments), the strain energy density W [J/m^3]
    (core.strain_energy_density), and per particle the motion columns (particle_table.motion).
    These are the measures that read the bonds or sum over every node."""

    damage: NDArray[np.float64]
    damage_z: NDArray[np.float64]
    labels: NDArray[np.uint32]
    strain_energy_density: NDArray[np.float64]
    motion: particle_table.Table


class Analysis:
    """The measures of one core simulation with `particles` particles (Simulation.analysis)."""

    def __init__(self, core: _core.Simulation, model: _core.Model, particles: int) -> None:
        self._core, self._model = core, model
        self._dimension, self._particles = model.dimension, particles
        #: Measures that read only the bond states, by name, kept with core.bond_changes at the
        #: time (_of_bonds): a history row every few steps needs them anew only when a bond broke.
        self._kept: dict[str, tuple[int, NDArray]] = {}
        self._given: tuple[tuple[int, int], GivenMeasures] | None = None

    def _key(self) -> tuple[int, int]:
        """The step and the broken bonds: the state the given measures are of."""
        return int(self._core.step), int(self._core.broken_bonds())

    def give(self, measures: GivenMeasures | None) -> None:
        """The measures of the current state made elsewhere (a distributed run's rank 0: its
        ranks', whole_state.install), used in place of the core's until the step or the
        broken bonds change; None: none (the core's are made)."""
        self._given = None if measures is None else (self._key(), measures)

    def _given_now(self) -> GivenMeasures | None:
        """The given measures, when they are of the current state."""
        if self._given is None or self._given[0] != self._key():
            return None
        return self._given[1]

    def damage(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Per node the damage phi and PeriDEM's Z (core.damage)."""
        given = self._given_now()
        if given is not None:
            return given.damage, given.damage_z
        phi, z = self._core.damage()
        return np.asarray(phi), np.asarray(z)

    def damage_phi(self) -> NDArray[np.float64]:
        """Per node the damage phi alone (damage()[0]; core.damage_phi, which reads the bonds
        only, so it is kept until a bond state changes). Read-only."""
        given = self._given_now()
        return self._of_bonds("phi", self._core.damage_phi) if given is None else given.damage

    def kinetic_energy(self) -> float:
        """sum_i 1/2 m_i |v_i|^2 [J; J/m in 2D], correctly rounded (ExactSum): the same bits
        however the nodes are dealt to ranks."""
        mass = np.asarray(self._model.node_density) * np.asarray(self._model.volumes)
        return ExactSum.of(kinetic_energies(mass, self._core.velocities)).value

    def farthest_node_distance(self) -> float:
        """max_i |x_i| [m], the largest distance of a node from the origin."""
        return float(np.sqrt(np.max(squared_distances(self._core.positions))))

    def strain_energy_densities(self) -> NDArray[np.float64]:
        """Per node the strain energy density W_i [J/m^3] (core.strain_energy_density)."""
        given = self._given_now()
        if given is not None:
            return given.strain_energy_density
        return np.asarray(self._core.strain_energy_density())

    def strain_energy(self) -> float:
        """sum_i W_i V_i [J; J/m in 2D], correctly rounded (ExactSum)."""
        volumes = np.asarray(self._model.volumes)
        return ExactSum.of(self.strain_energy_densities() * volumes).value

    def fragment_labels(self) -> NDArray[np.uint32]:
        """Each node's piece: its smallest node (core.fragments, kept until a bond state
        changes). Read-only."""
        given = self._given_now()
        return self._of_bonds("labels", self._core.fragments) if given is None else given.labels

    def _of_bonds(self, name: str, measure: Callable[[], ArrayLike]) -> NDArray:
        """The measure `name` of the bond states (`measure` makes it), kept read-only until
        core.bond_changes changes."""
        changes = int(self._core.bond_changes)
        kept = self._kept.get(name)
        if kept is None or kept[0] != changes:
            kept = self._kept[name] = (changes, read_only(np.asarray(measure())))
        return kept[1]

    def forget_fragments(self) -> None:
        """Drop the kept labels, damage and given measures (the bonds were restored from a
        checkpoint)."""
        self._kept.clear()
        self._given = None

    def fragments(self, min_nodes: int) -> list[NDArray[np.uint32]]:
        """Pieces of at least `min_nodes` nodes, largest first, as node indices."""
        labels = self.fragment_labels()
        order = np.argsort(labels, kind="stable")
        _roots, starts, counts = np.unique(labels[order], return_index=True, return_counts=True)
        pieces = [
            order[s : s + c].astype(np.uint32)
            for s, c in zip(starts, counts, strict=True)
            if c >= min_nodes
        ]
        return sorted(pieces, key=lambda piece: (-len(piece), int(piece[0])))

    def fragment_table(self) -> fragments.Table:
        """One row per fragment, debris included (granulate.fragments.fragment_table)."""
        core, model = self._core, self._model
        return fragments.fragment_table(
            self.fragment_labels(),
            np.arange(model.node_count),
            model.node_particle,
            core.positions,
            core.velocities,
            model.volumes,
            model.node_density,
            self._dimension,
        )

    def fully_broken_particles(self, bodies: Sequence[Body]) -> int:
        """Bodies with at least one bond and none intact."""
        intact = np.asarray(self._core.bond_intact)
        offsets = np.asarray(self._model.bond_offsets)
        count = 0
        for body in bodies:
            begin, end = offsets[body.first_node], offsets[body.first_node + body.node_count]
            if end > begin and not intact[begin:end].any():
                count += 1
        return count

    def gravity_energy(self, gravity: NDArray[np.float64]) -> float:
        """-sum m_i g . x_i [J; J/m in 2D], zero at the origin, correctly rounded."""
        model = self._model
        mass = np.asarray(model.node_density) * np.asarray(model.volumes)
        return ExactSum.of(gravity_energies(mass, self._core.positions, gravity)).value

    def contact_table(self) -> network.Table:
        """One row per contact of the last force evaluation (granulate.network)."""
        return network.contact_table(self._core.contact_network())

    def particles(
        self, contacts: network.Table, damage: ArrayLike | None
    ) -> tuple[particle_table.Table, NDArray, NDArray]:
        """The particle table, the particles' Love-Weber stresses (N, D, D) [Pa] and their
        volumes [m^3; m^2 in 2D]: what a frame's table and a history row both need. `damage`:
        phi per node (the core's, when None)."""
        core, count = self._core, self._particles
        owner, volumes, motion = self._motion()
        phi = self.damage_phi() if damage is None else np.asarray(damage)
        nodes = np.arange(len(owner))
        particle_volume, mean_damage = particle_table.volumes(owner, nodes, volumes, phi, count)
        table, stresses = complete_particle_table(
            motion, particle_volume, mean_damage, contacts, float(core.time), self._dimension
        )
        return table, stresses, particle_volume

    def _motion(self) -> tuple[NDArray, NDArray, particle_table.Table]:
        """Each node's particle, each node's volume, and the particles' motion columns
        (granulate.particle_table.motion)."""
        model, core = self._model, self._core
        owner, volumes = np.asarray(model.node_particle), np.asarray(model.volumes)
        given = self._given_now()
        if given is not None:
            return owner, volumes, dict(given.motion)  # the callers add columns
        mass = np.asarray(model.node_density) * volumes
        nodes, x, v = np.arange(len(owner)), core.positions, core.velocities
        motion = particle_table.motion(owner, nodes, mass, volumes, x, v, self._particles)
        return owner, volumes, motion

    def particle_stresses(
        self, method: Literal["contacts", "bonds"], contacts: network.Table | None
    ) -> NDArray:
        """Each particle's mean stress (particles, D, D) [Pa; tension positive], Love-Weber
        from its contacts or from its bond forces (granulate.network)."""
        core, count = self._core, self._particles
        owner, volumes, table = self._motion()
        centres = np.column_stack([table[axis] for axis in "xyz"])
        if method == "contacts":
            network_table = self.contact_table() if contacts is None else contacts
            particle_volume = Runs.of(owner, np.arange(len(owner)), volumes).totals(count)[:, 0]
            return network.love_weber_stresses(
                network_table, centres, particle_volume, self._dimension
            )
        if method == "bonds":
            bonds = np.asarray(core.bond_force_densities()).reshape(-1, 3)
            return network.internal_stresses(
                bonds, core.positions, volumes, owner, centres, self._dimension
            )
        raise InputError(f"particle_stresses: method must be 'contacts' or 'bonds', got {method!r}")
