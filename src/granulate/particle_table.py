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

from granulate.io.table import read_columns, write_columns
from granulate.run_sums import Runs

#: Columns of a particle table, in the order written.
COLUMNS = (
    "particle", "time", "x", "y", "z", "vx", "vy", "vz", "wx", "wy", "wz", "mass",
    "gyration_radius", "damage", "coordination", "sxx", "syy", "szz", "sxy", "sxz", "syz",
)  # fmt: skip
_INTEGERS = ("particle", "coordination")
#: The inertia tensor's places in the six moment sums' components (xx, yy, zz, xy, xz, yz).
_TENSOR = np.array([[0, 3, 4], [3, 1, 5], [4, 5, 2]])
_STRESS = (("sxx", 0, 0), ("syy", 1, 1), ("szz", 2, 2), ("sxy", 0, 1), ("sxz", 0, 2), ("syz", 1, 2))

Table = dict[str, NDArray]


def motion(
    owner: ArrayLike,
    nodes: ArrayLike,
    mass: ArrayLike,
    volumes: ArrayLike,
    positions: ArrayLike,
    velocities: ArrayLike,
    count: int,
) -> Table:
    """Mass, centre x y z, velocity vx vy vz, angular velocity wx wy wz and gyration_radius of
    each of `count` particles from per-node `owner` (particle index), node index (increasing),
    mass, volume, positions (n, 3) and velocities (n, 3): the sums over the nodes run by run
    (run_sums.py), so that processes holding whole blocks of a particle each make their share
    (Runs.first_sums, then with the centres Runs.moments); the 3 x 3 solves are NumPy's."""
    first = Runs.first_sums(owner, nodes, mass, volumes, positions, velocities).totals(count)
    centre, velocity = centres(first)
    moments = Runs.moments(owner, nodes, mass, positions, velocities, centre, velocity)
    return table_of(first, moments.totals(count))


def volumes(
    owner: ArrayLike,
    nodes: ArrayLike,
    node_volumes: ArrayLike,
    damage: ArrayLike,
    count: int,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Per particle its volume sum V_i [m^3; m^2 in 2D] and volume-weighted damage
    sum V_i phi_i / sum V_i (`damage`: phi per node), run by run."""
    return volumes_of(volume_runs(owner, nodes, node_volumes, damage).totals(count))


def volume_runs(
    owner: ArrayLike, nodes: ArrayLike, node_volumes: ArrayLike, damage: ArrayLike
) -> Runs:
    """The runs of the volume sums, 2 a run: V, V phi."""
    volume = np.asarray(node_volumes, dtype=np.float64)
    weighted = volume * np.asarray(damage, dtype=np.float64)
    return Runs.of(owner, nodes, np.column_stack([volume, weighted]))


def volumes_of(sums: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Volumes and mean damage from the volume sums (count, 2)."""
    return sums[:, 0], sums[:, 1] / sums[:, 0]


def centres(first: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Per particle its centre of mass c = sum m x / M and velocity V = sum m v / M, from its
    first sums (count, 8: Runs.first_sums')."""
    return first[:, 2:5] / first[:, :1], first[:, 5:8] / first[:, :1]


def table_of(first: NDArray[np.float64], moments: NDArray[np.float64]) -> Table:
    """The motion columns of particles from their first sums (count, 8: Runs.first_sums') and
    moment sums (count, 10: Runs.moments')."""
    count = len(first)
    total = first[:, 0]
    centre, velocity = centres(first)
    momentum, inertia = moments[:, :3], moments[:, 3:9][:, _TENSOR]  # (count, 3, 3)
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
    table["gyration_radius"] = np.sqrt(moments[:, 9] / total)
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
