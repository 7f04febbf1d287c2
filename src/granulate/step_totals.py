"""The sums over nodes a history row holds, kept exactly (granulate.exact_sum), so that the sums
of any split of the nodes add up to the whole's to the bit: each rank of a distributed run sums
its own nodes and rank 0 adds the parts, or a serial run sums them all.

Per node i (mass m_i = rho_i V_i [kg; kg/m in 2D], velocity v_i, position x_i, reference X_i):
- kinetic energy 1/2 m_i |v_i|^2, strain energy W_i V_i (W_i the strain energy density
  [J/m^3]), gravity energy -m_i g . x_i, contact energy (the node's share of the normal
  springs' energy, core.node_contact_terms) [J; J/m in 2D];
- V_i phi_i and V_i, whose ratio is the volume-weighted mean damage;
- of each tracked body's nodes: m_i, V_i f_i (f_i the force density [N/m^3]) and x_i - X_i,
  for its resultant less its weight and its mean displacement.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from granulate.analysis import gravity_energies, kinetic_energies
from granulate.exact_sum import ExactSum

_ZERO = ExactSum()


@dataclass(frozen=True)
class TrackedSums:
    """A tracked body's sums over some of its nodes: mass, V f per axis, x - X per axis, and the
    node count."""

    mass: ExactSum = _ZERO
    force: tuple[ExactSum, ...] = (_ZERO, _ZERO, _ZERO)
    displacement: tuple[ExactSum, ...] = (_ZERO, _ZERO, _ZERO)
    nodes: int = 0

    @classmethod
    def of(
        cls,
        mass: ArrayLike,
        volumes: ArrayLike,
        forces: ArrayLike,
        positions: ArrayLike,
        reference: ArrayLike,
    ) -> TrackedSums:
        """The sums over the nodes whose per-node arrays these are ((n,) and (n, 3))."""
        v = np.asarray(volumes, dtype=np.float64)
        f, x, origin = (np.asarray(a, dtype=np.float64) for a in (forces, positions, reference))
        total, *sums = ExactSum.each([mass, *(v[:, None] * f).T, *(x - origin).T])
        return cls(total, tuple(sums[:3]), tuple(sums[3:]), len(v))

    def __add__(self, other: TrackedSums) -> TrackedSums:
        return TrackedSums(
            self.mass + other.mass,
            tuple(a + b for a, b in zip(self.force, other.force, strict=True)),
            tuple(a + b for a, b in zip(self.displacement, other.displacement, strict=True)),
            self.nodes + other.nodes,
        )

    def load(self, gravity: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The resultant of the body's forces other than gravity, sum V f - (sum m) g [N; N/m in
        2D], and its mean displacement [m], (3,) each."""
        weight = self.mass.value * np.asarray(gravity, dtype=np.float64)
        resultant = np.array([total.value for total in self.force]) - weight
        mean = np.array([total.value for total in self.displacement]) / max(self.nodes, 1)
        return resultant, mean


@dataclass(frozen=True)
class StepTotals:
    """A history row's sums over some nodes (the module docstring); adding two adds them."""

    kinetic: ExactSum = _ZERO
    strain: ExactSum = _ZERO
    gravity: ExactSum = _ZERO
    contact: ExactSum = _ZERO
    damaged_volume: ExactSum = _ZERO  # sum V phi
    volume: ExactSum = _ZERO
    tracked: tuple[TrackedSums, ...] = field(default_factory=tuple)

    def __add__(self, other: StepTotals) -> StepTotals:
        return StepTotals(
            self.kinetic + other.kinetic,
            self.strain + other.strain,
            self.gravity + other.gravity,
            self.contact + other.contact,
            self.damaged_volume + other.damaged_volume,
            self.volume + other.volume,
            tuple(a + b for a, b in zip(self.tracked, other.tracked, strict=True)),
        )

    @property
    def mean_damage(self) -> float:
        """sum V phi / sum V."""
        return self.damaged_volume.value / self.volume.value


def node_totals(
    mass: ArrayLike,
    volumes: ArrayLike,
    velocities: ArrayLike,
    positions: ArrayLike,
    gravity: ArrayLike,
    strain_density: ArrayLike,
    damage: ArrayLike,
) -> StepTotals:
    """The kinetic, strain and gravity energies' and the damage's sums over the nodes whose
    per-node arrays these are (no contact energy, which the force evaluation sums, and no
    tracked body's)."""
    v = np.asarray(volumes, dtype=np.float64)
    kinetic, strain, potential, damaged, volume = ExactSum.each(
        [
            kinetic_energies(mass, velocities),
            np.asarray(strain_density, dtype=np.float64) * v,
            gravity_energies(mass, positions, gravity),
            v * np.asarray(damage, dtype=np.float64),
            v,
        ]
    )
    return StepTotals(
        kinetic=kinetic, strain=strain, gravity=potential, damaged_volume=damaged, volume=volume
    )
