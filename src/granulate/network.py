"""The contact network and the granular measures made from it: coordination, fabric, stresses.

A contact is a pair of bodies in contact at the last force evaluation, or a body and a wall; a
body is a particle, or one of its fragments once bonds break (named, as in the fragment table,
by its smallest node). For each contact the core gives the whole contact force f on body a from
b [N; N/m in 2D] (springs, friction, the dashpot, surface-law probes; rolling-resistance and
friction couples are moments and not part of it), the unit normal n from b towards a and the
spring-weighted contact point x_c [m]. The normal force is f_n = f . n (positive: the bodies
push each other apart), the tangential force f_t = |f - f_n n|.

Measures (D the dimension, sums over contacts c):

- coordination of a particle: the number of other particles it touches (the fragments of a
  particle count as that particle, a pair of particles once however many of their pieces touch;
  walls are not counted), and the mean coordination number Z = 2 C / N over all N particles,
  C the touching pairs of distinct particles;
- fabric tensor (Satake 1982): Phi = (1 / C) sum n (x) n over those pairs' contacts (trace 1),
  of the contact normals or of the lines between the particles' centres;
- particle stress, Love-Weber: sigma_p = (1 / V_p) sum_c sym((x_c - x_p) (x) f_c) over p's
  contacts with other particles and walls, f_c the force on p, x_p its centre of mass, V_p its
  volume (its area in 2D, where forces are per unit thickness, so sigma is in Pa both ways).
  For a particle in equilibrium it is the mean of its Cauchy stress; ``internal_stresses``
  gives the same mean from the particle's bond forces, -(1 / V_p) sum_i V_i sym((x_i - x_p)
  (x) b_i) with b_i the bond force density of node i, which agrees with it at rest;
- assembly stress: sum_p V_p sigma_p / V over a volume V (default: the particles' own
  volume). For an assembly at rest under gravity g this sum is the virial of its external
  forces, sum_walls x_c (x) f_c + sum_p m_p x_p (x) g (the identity the tests check);
- wall stress: |F| / A, the particles' resultant force on a wall over its nominal area A
  (``Wall(area=...)``).

Tension is positive in the stresses; compression, as in a pile or a crushing test, is negative.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from granulate import reductions
from granulate.io.table import read_columns, write_columns

#: Columns of a contact table (frames/contacts_NNNNNN.csv), in the order written: the bodies
#: (a wall contact has particle_b = fragment_b = -1 and wall = the wall's index, else -1), the
#: contact point, the normal from b to a, the force on a, and f_n and f_t.
COLUMNS = (
    "particle_a", "fragment_a", "particle_b", "fragment_b", "wall",
    "x", "y", "z", "nx", "ny", "nz", "fx", "fy", "fz", "normal_force", "tangential_force",
)  # fmt: skip
_INTEGERS = ("particle_a", "fragment_a", "particle_b", "fragment_b", "wall")

Table = dict[str, NDArray]


def contact_table(core_network: Mapping[str, ArrayLike]) -> Table:
    """The contact table from the core's ``contact_network()`` (one row per contact, in the
    core's slot order: pairs of bodies, then bodies and walls)."""
    wall = np.asarray(core_network["wall"]).astype(bool)
    particle_b = np.asarray(core_network["particle_b"]).astype(np.int64)
    fragment_b = np.asarray(core_network["node_b"]).astype(np.int64)
    table: Table = {
        "particle_a": np.asarray(core_network["particle_a"]).astype(np.int64),
        "fragment_a": np.asarray(core_network["node_a"]).astype(np.int64),
        "particle_b": np.where(wall, -1, particle_b),
        "fragment_b": np.where(wall, -1, fragment_b),
        "wall": np.where(wall, particle_b, -1),
    }
    for name, key in (("", "point"), ("n", "normal"), ("f", "force")):
        values = np.asarray(core_network[key], dtype=np.float64).reshape(-1, 3)
        for k, axis in enumerate("xyz"):
            table[name + axis] = values[:, k]
    force, normal = _vectors(table, "f"), _vectors(table, "n")
    normal_force = np.einsum("ij,ij->i", force, normal)
    table["normal_force"] = normal_force
    table["tangential_force"] = np.linalg.norm(force - normal_force[:, None] * normal, axis=1)
    return table


def _vectors(table: Mapping[str, NDArray], prefix: str) -> NDArray[np.float64]:
    return np.column_stack([table[prefix + axis] for axis in "xyz"]).astype(np.float64)


def _between_particles(table: Mapping[str, NDArray]) -> NDArray[np.bool_]:
    """Contacts between two different particles (not walls, not fragments of one particle)."""
    return (table["wall"] < 0) & (table["particle_a"] != table["particle_b"])


def coordination_pairs(table: Mapping[str, NDArray]) -> NDArray[np.int64]:
    """The distinct pairs of different particles in contact, (k, 2), smaller index first."""
    between = _between_particles(table)
    a, b = (
        np.asarray(table[name][between], dtype=np.int64) for name in ("particle_a", "particle_b")
    )
    # Each pair as one integer, (smaller << 32) | larger: its order is the pairs' (np.unique of
    # integers is far quicker than of rows).
    keys = np.unique((np.minimum(a, b) << 32) | np.maximum(a, b))
    return np.column_stack([keys >> 32, keys & 0xFFFFFFFF])


def coordination(table: Mapping[str, NDArray], particle_count: int) -> NDArray[np.int64]:
    """Per particle, the number of other particles it touches (module docstring)."""
    pairs = coordination_pairs(table)
    return np.bincount(pairs.ravel(), minlength=particle_count).astype(np.int64)


def mean_coordination(table: Mapping[str, NDArray], particle_count: int) -> float:
    """Z = 2 C / N: C touching pairs of distinct particles, N particles (0 without particles)."""
    if particle_count == 0:
        return 0.0
    return 2.0 * len(coordination_pairs(table)) / particle_count


def fabric_tensor(
    table: Mapping[str, NDArray], dimension: int, centres: ArrayLike | None = None
) -> NDArray[np.float64]:
    """Phi = (1 / C) sum n (x) n over the contacts between different particles, D x D (zeros
    without contacts): n the contact normals, or with `centres` (per particle, (N, D) or (N, 3)
    [m]) the unit lines between the two particles' centres (the packing's geometry, without the
    tilt a surface's discretisation gives its normals)."""
    between = _between_particles(table)
    if centres is None:
        normals = _vectors(table, "n")[between, :dimension]
    else:
        x = np.asarray(centres, dtype=np.float64)[:, :dimension]
        lines = x[table["particle_a"][between]] - x[table["particle_b"][between]]
        normals = lines / np.linalg.norm(lines, axis=1)[:, None]
    if len(normals) == 0:
        return np.zeros((dimension, dimension))
    return reductions.outer_sum(normals, normals) / len(normals)


def _symmetric(tensors: NDArray[np.float64]) -> NDArray[np.float64]:
    return 0.5 * (tensors + np.swapaxes(tensors, -1, -2))


def love_weber_stresses(
    table: Mapping[str, NDArray],
    centres: ArrayLike,
    volumes: ArrayLike,
    dimension: int,
) -> NDArray[np.float64]:
    """sigma_p = (1 / V_p) sum_c sym((x_c - x_p) (x) f_c) per particle, (N, D, D) [Pa]:
    `centres` (N, 3) the particles' centres of mass [m], `volumes` (N,) their volumes [m^3;
    m^2 in 2D]. Each contact between two particles counts for both, with f and -f."""
    x_p = np.asarray(centres, dtype=np.float64)
    v_p = np.asarray(volumes, dtype=np.float64)
    count = len(v_p)
    point, force = _vectors(table, ""), _vectors(table, "f")
    d = dimension
    virial = np.zeros((count, d, d))
    a = table["particle_a"]
    external = a != table["particle_b"]  # walls (particle_b = -1) and other particles
    arm = (point - x_p[a])[external, :d]
    np.add.at(virial, a[external], arm[:, :, None] * force[external, None, :d])
    pairs = _between_particles(table)
    b = table["particle_b"][pairs]
    arm = (point[pairs] - x_p[b])[:, :d]
    np.add.at(virial, b, arm[:, :, None] * -force[pairs, None, :d])
    return _symmetric(virial) / v_p[:, None, None]


def internal_stresses(
    bond_forces: ArrayLike,
    positions: ArrayLike,
    node_volumes: ArrayLike,
    node_particles: ArrayLike,
    centres: ArrayLike,
    dimension: int,
) -> NDArray[np.float64]:
    """sigma_p = -(1 / V_p) sum_i V_i sym((x_i - x_p) (x) b_i) per particle, (N, D, D) [Pa],
    from the bond force densities b_i [N/m^3] of the core's ``bond_force_densities()`` (per
    node, (n, 3)); the particles' volumes are the sums of their nodes'."""
    b = np.asarray(bond_forces, dtype=np.float64).reshape(-1, 3)
    x = np.asarray(positions, dtype=np.float64)
    v = np.asarray(node_volumes, dtype=np.float64)
    owner = np.asarray(node_particles, dtype=np.int64)
    x_p = np.asarray(centres, dtype=np.float64)
    count, d = len(x_p), dimension
    arm = (x - x_p[owner])[:, :d]
    virial = np.zeros((count, d, d))
    np.add.at(virial, owner, -v[:, None, None] * arm[:, :, None] * b[:, None, :d])
    return _symmetric(virial) / np.bincount(owner, v, count)[:, None, None]


def assembly_stress(
    stresses: ArrayLike, volumes: ArrayLike, volume: float | None = None
) -> NDArray[np.float64]:
    """sum_p V_p sigma_p / V, D x D [Pa]; V defaults to the particles' volume (module
    docstring). For the stress of a packing over its container, give the container's volume:
    the particles' own volume gives the mean stress in the solid."""
    sigma = np.asarray(stresses, dtype=np.float64)
    v = np.asarray(volumes, dtype=np.float64)
    total = float(v.sum()) if volume is None else float(volume)
    return np.einsum("p,pij->ij", v, sigma) / total


def chain_lines(
    table: Mapping[str, NDArray], pieces: Mapping[str, NDArray]
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Force-chain lines for ParaView: points (2 k, 3) and lines (k, 2), from the centre of
    body a to that of body b, or to the contact point on a wall; `pieces`: the fragment table
    of the same state (granulate.fragments), which gives the bodies' centres."""
    ids = np.asarray(pieces["fragment"])
    centres = np.column_stack([pieces[axis] for axis in "xyz"]).astype(np.float64)
    a = centres[np.searchsorted(ids, table["fragment_a"])] if len(ids) else np.zeros((0, 3))
    wall = table["wall"] >= 0
    b = _vectors(table, "").copy()
    if np.any(~wall):
        b[~wall] = centres[np.searchsorted(ids, table["fragment_b"][~wall])]
    count = len(table["particle_a"])
    points = np.empty((2 * count, 3))
    points[0::2], points[1::2] = a.reshape(-1, 3), b
    return points, np.arange(2 * count, dtype=np.int64).reshape(-1, 2)


def chain_fields(table: Mapping[str, NDArray]) -> dict[str, NDArray]:
    """Cell data of the force-chain lines: Normal_Force, Tangential_Force [N; N/m in 2D], Force
    (on body a), Particle_A, Particle_B (-1: a wall) and Wall (-1: none)."""
    return {
        "Normal_Force": np.asarray(table["normal_force"], dtype=np.float64),
        "Tangential_Force": np.asarray(table["tangential_force"], dtype=np.float64),
        "Force": _vectors(table, "f"),
        "Particle_A": np.asarray(table["particle_a"], dtype=np.int64),
        "Particle_B": np.asarray(table["particle_b"], dtype=np.int64),
        "Wall": np.asarray(table["wall"], dtype=np.int64),
    }


def write_table(path: str | Path, table: Table) -> None:
    """The table as CSV with a header row (``pandas.read_csv`` reads it)."""
    write_columns(path, table, COLUMNS, _INTEGERS)


def read_table(path: str | Path) -> Table:
    """A contact table written by ``write_table`` (a run's frames/contacts_NNNNNN.csv)."""
    return read_columns(path, what="contact table", columns=COLUMNS, integers=_INTEGERS)
