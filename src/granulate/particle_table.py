"""Per-particle snapshots (frames/particles_NNNNNN.csv): motion, size, damage, contacts, stress.

For particle p with nodes i (mass m_i, position x_i, velocity v_i; M = sum m_i):

- centre of mass x_p = sum m_i x_i / M [m] and its velocity v_p [m/s];
- angular velocity omega = I^-1 L [rad/s], L = sum m_i (x_i - x_p) x (v_i - v_p) and I the
  inertia tensor about x_p (in 2D omega_z = L_z / I_zz); a particle whose nodes lie on a line
  (or one node) has none: 0;
- radius of gyration R_g = sqrt(sum m_i |x_i - x_p|^2 / M) [m];
- the volume-weighted mean damage; the coordination (other particles touched) and the
  Love-Weber stress [Pa] of granulate.network (2D: sxx, syy, sxy; szz, sxz, syz are NaN).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from granulate import _core
from granulate.io.table import read_columns, write_columns

#: Columns of a particle table, in the order written.
COLUMNS = (
    "particle", "time", "x", "y", "z", "vx", "vy", "vz", "wx", "wy", "wz", "mass",
    "gyration_radius", "damage", "coordination", "sxx", "syy", "szz", "sxy", "sxz", "syz",
)  # fmt: skip
_INTEGERS = ("particle", "coordination")
#: The inertia tensor's places in _core.particle_sums' six components (xx, yy, zz, xy, xz, yz).
_TENSOR = np.array([[0, 3, 4], [3, 1, 5], [4, 5, 2]])
_STRESS = (("sxx", 0, 0), ("syy", 1, 1), ("szz", 2, 2), ("sxy", 0, 1), ("sxz", 0, 2), ("syz", 1, 2))

Table = dict[str, NDArray]


def motion(
    owner: ArrayLike, mass: ArrayLike, positions: ArrayLike, velocities: ArrayLike, count: int
) -> Table:
    """Mass, centre x y z, velocity vx vy vz, angular velocity wx wy wz and gyration_radius of
    each of `count` particles from per-node `owner` (particle index), mass, positions (n, 3)
    and velocities (n, 3). The sums over the nodes are the core's (_core.particle_sums), the
    3 x 3 solves NumPy's."""
    total, centre, velocity, momentum, components, spread = _core.particle_sums(
        np.ascontiguousarray(owner, dtype=np.uint32),
        np.ascontiguousarray(mass, dtype=np.float64),
        np.ascontiguousarray(positions, dtype=np.float64),
        np.ascontiguousarray(velocities, dtype=np.float64),
        count,
    )
    inertia = components[:, _TENSOR]  # (count, 3, 3)
    spin = np.zeros((count, 3))
    solvable = np.linalg.matrix_rank(inertia) == 3
    spin[solvable] = np.linalg.solve(inertia[solvable], momentum[solvable][:, :, None])[:, :, 0]
    flat = ~solvable & (inertia[:, 2, 2] > 0)  # 2D (nodes in the plane z = const): about z only
    spin[flat, 2] = momentum[flat, 2] / inertia[flat, 2, 2]
    table: Table = {"mass": total}
    for k, axis in enumerate("xyz"):
        table[axis] = centre[:, k]
        table["v" + axis] = velocity[:, k]
        table["w" + axis] = spin[:, k]
    table["gyration_radius"] = np.sqrt(spread / total)
    return table


def add_stresses(table: Table, stresses: ArrayLike, dimension: int) -> None:
    """The stress columns from (N, D, D) tensors; the out-of-plane ones are NaN in 2D."""
    sigma = np.asarray(stresses, dtype=np.float64)
    for name, i, j in _STRESS:
        inside = i < dimension and j < dimension
        table[name] = sigma[:, i, j] if inside else np.full(len(sigma), np.nan)


def write_table(path: str | Path, table: Table) -> None:
    """The table as CSV with a header row (``pandas.read_csv`` reads it)."""
    write_columns(path, table, COLUMNS, _INTEGERS)


def read_table(path: str | Path) -> Table:
    """A particle table written by ``write_table`` (a run's frames/particles_NNNNNN.csv)."""
    return read_columns(path, what="particle table", columns=COLUMNS, integers=_INTEGERS)
