"""Breakage analytics: fragments, grading curves and breakage indices.

A fragment is a connected piece of one particle through intact bonds (``Simulation`` labels
each node with the smallest node of its piece, so a piece keeps its id until it splits, and
the part holding that node keeps it then). A piece of one node is debris: it is a row of the
fragment table like any other, flagged ``debris``, and counted apart in the history.

Sizes are equivalent diameters: of the disc of the piece's area in 2D, d = 2 sqrt(A / pi), of
the sphere of its volume in 3D, d = (6 V / pi)^(1/3). A grading curve is the mass fraction of
pieces no larger than d, F(d) = sum of m_i over d_i <= d, divided by the total mass.

Breakage indices compare a grading F with the initial one F0:

- Hardin (1985), relative breakage Br = (Bp0 - Bp) / Bp0, with the breakage potential
  Bp = sum_i (m_i / M) log10(d_i / d_c) over pieces larger than the cut-off d_c (Hardin's
  0.074 mm, the No. 200 sieve, unless given): the area between the grading curve and d = d_c
  on a log axis.
- Einav (2007), B = int (F - F0) dln d / int (Fu - F0) dln d over [d_m, d_M], with the
  ultimate fractal grading Fu = (d / d_M)^(D - alpha) (D the dimension; alpha = 2.5 in 3D,
  Einav's value, and 1.5 in 2D, the same exponent). For pieces, int_{d_m}^{d_M} F dln d =
  sum_i (m_i / M) ln(d_M / max(d_i, d_m)) over d_i < d_M, and int Fu dln d =
  (1 - (d_m / d_M)^(D - alpha)) / (D - alpha).
- t10 (Narayanan & Whiten 1988): the mass fraction of pieces no larger than a tenth of their
  parent particle's initial size (here for every parent at once, mass-weighted).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from granulate import reductions
from granulate.errors import InputError
from granulate.io.table import read_columns, write_columns
from granulate.run_sums import Runs

#: Columns of a fragment table, in the order they are written.
COLUMNS = (
    "fragment", "particle", "nodes", "debris", "mass", "volume",
    "x", "y", "z", "vx", "vy", "vz", "diameter",
)  # fmt: skip
#: Hardin's cut-off size [m]: the No. 200 sieve.
HARDIN_CUTOFF = 0.074e-3
_INTEGERS = ("fragment", "particle", "nodes", "debris")

Table = dict[str, NDArray]


def equivalent_diameter(measure: ArrayLike, dimension: int) -> NDArray[np.float64]:
    """Diameter of the disc of area `measure` (2D) or of the sphere of that volume (3D) [m]."""
    m = np.asarray(measure, dtype=np.float64)
    return 2 * np.sqrt(m / math.pi) if dimension == 2 else np.cbrt(6 * m / math.pi)


def fragment_table(
    labels: ArrayLike,
    nodes: ArrayLike,
    particles: ArrayLike,
    positions: ArrayLike,
    velocities: ArrayLike,
    volumes: ArrayLike,
    densities: ArrayLike,
    dimension: int,
) -> Table:
    """One row per piece, in the order of its id (its smallest node): the parent particle,
    node count, debris flag (1 node), mass [kg; kg/m in 2D], volume [m^3; m^2 in 2D], centre
    of mass [m], its velocity [m/s] and the equivalent diameter [m]. `labels` gives each
    node's piece, `nodes` its index (increasing), `particles` its particle; the other arrays
    are per node. The sums are made run by run (run_sums.py): fragment_runs and table_of_runs
    make the table of several processes' nodes."""
    ids, first = np.unique(np.asarray(labels, dtype=np.int64), return_index=True)
    runs = fragment_runs(labels, nodes, positions, velocities, volumes, densities)
    return table_of_runs(runs, ids, np.asarray(particles, dtype=np.int64)[first], dimension)


def fragment_runs(
    labels: ArrayLike,
    nodes: ArrayLike,
    positions: ArrayLike,
    velocities: ArrayLike,
    volumes: ArrayLike,
    densities: ArrayLike,
) -> Runs:
    """The runs of the pieces' sums (Runs.first_sums: m, V, m x, m v)."""
    volume = np.asarray(volumes, dtype=np.float64)
    mass = np.asarray(densities, dtype=np.float64) * volume
    return Runs.first_sums(labels, nodes, mass, volume, positions, velocities)


def table_of_runs(
    runs: Runs, ids: NDArray[np.int64], particles: NDArray[np.int64], dimension: int
) -> Table:
    """The fragment table (fragment_table) of the pieces `ids` (sorted), whose parents are
    `particles`, from the runs of their nodes in node order."""
    places = np.searchsorted(ids, runs.group)
    sums, nodes = runs.totals(len(ids), places), runs.nodes(len(ids), places)
    piece_mass = sums[:, 0]
    table: Table = {
        "fragment": ids.astype(np.int64),
        "particle": particles.astype(np.int64),
        "nodes": nodes,
        "debris": (nodes == 1).astype(np.int64),
        "mass": piece_mass,
        "volume": sums[:, 1],
    }
    for k, axis in enumerate("xyz"):
        table[axis] = sums[:, 2 + k] / piece_mass
    for k, axis in enumerate("xyz"):
        table["v" + axis] = sums[:, 5 + k] / piece_mass
    table["diameter"] = equivalent_diameter(table["volume"], dimension)
    return table


def summary(table: Table, mean_damage: float) -> dict[str, float | int]:
    """The history columns of a fragment table: fragments (pieces of two nodes or more),
    debris_nodes, debris_mass, particles_split (particles in two pieces or more; not the stop
    criterion's particles that lost every bond), and `mean_damage`, the volume-weighted mean
    damage of all nodes (step_totals.StepTotals.mean_damage)."""
    debris = table["debris"] == 1
    pieces = np.bincount(table["particle"])
    return {
        "fragments": int(np.count_nonzero(~debris)),
        "debris_nodes": int(np.count_nonzero(debris)),
        "debris_mass": float(table["mass"][debris].sum()),
        "particles_split": int(np.count_nonzero(pieces > 1)),
        "mean_damage": mean_damage,
    }


def write_table(path: str | Path, table: Table) -> None:
    """The table as CSV with a header row (``pandas.read_csv`` reads it)."""
    write_columns(path, table, COLUMNS, _INTEGERS)


def read_table(path: str | Path) -> Table:
    """A fragment table written by ``write_table`` (a run's frames/fragments_NNNNNN.csv)."""
    return read_columns(path, what="fragment table", columns=COLUMNS, integers=_INTEGERS)


def grading_curve(table: Mapping[str, NDArray]) -> tuple[NDArray, NDArray]:
    """Sizes d [m], ascending, and the mass fraction of pieces no larger than each."""
    order = np.argsort(table["diameter"], kind="stable")
    sizes = np.asarray(table["diameter"])[order]
    passing = np.cumsum(np.asarray(table["mass"])[order])
    return sizes, passing / passing[-1]


def hardin_breakage(
    initial: Mapping[str, NDArray], current: Mapping[str, NDArray], cutoff: float = HARDIN_CUTOFF
) -> float:
    """Hardin's relative breakage Br = (Bp0 - Bp) / Bp0 (module docstring); 0 when intact."""
    initial_potential = _potential(initial, cutoff)
    if initial_potential <= 0:
        raise InputError(f"no piece of the initial grading is larger than the cut-off {cutoff} m")
    return (initial_potential - _potential(current, cutoff)) / initial_potential


def _potential(table: Mapping[str, NDArray], cutoff: float) -> float:
    d, m = np.asarray(table["diameter"]), np.asarray(table["mass"])
    return reductions.dot(m, np.log10(np.maximum(d, cutoff) / cutoff)) / float(m.sum())


def einav_breakage(
    initial: Mapping[str, NDArray],
    current: Mapping[str, NDArray],
    dimension: int,
    smallest: float,
    largest: float | None = None,
    alpha: float | None = None,
) -> float:
    """Einav's breakage index B over sizes [smallest, largest] (largest: the initial
    grading's largest piece; alpha: 2.5 in 3D, 1.5 in 2D; module docstring)."""
    d_max = float(np.max(initial["diameter"])) if largest is None else largest
    if not 0 < smallest < d_max:
        raise InputError(f"einav_breakage needs 0 < smallest < largest, got {smallest}, {d_max}")
    exponent = dimension - (alpha if alpha is not None else dimension - 0.5)
    if exponent <= 0:
        raise InputError(f"the fractal dimension must be below {dimension}, got {alpha}")
    ultimate = (1 - (smallest / d_max) ** exponent) / exponent
    start = _area(initial, smallest, d_max)
    return (_area(current, smallest, d_max) - start) / (ultimate - start)


def _area(table: Mapping[str, NDArray], smallest: float, largest: float) -> float:
    """int_{smallest}^{largest} F(d) dln d for the grading of `table`."""
    d, m = np.asarray(table["diameter"]), np.asarray(table["mass"])
    spans = np.log(largest / np.clip(d, smallest, largest))
    return reductions.dot(m, spans) / float(m.sum())


def t10(table: Mapping[str, NDArray], parent_sizes: ArrayLike) -> float:
    """Mass fraction of pieces no larger than a tenth of their parent's initial size
    (`parent_sizes[particle]` [m])."""
    parent = np.asarray(parent_sizes, dtype=np.float64)[np.asarray(table["particle"])]
    fine = np.asarray(table["diameter"]) <= parent / 10
    m = np.asarray(table["mass"])
    return float(m[fine].sum() / m.sum())
