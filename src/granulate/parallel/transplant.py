"""Grains handed from one rank's simulation to another's with their whole state, so that a
distributed run can move grains between ranks (migration, DESIGN.md section 7) and stay the
serial run bit for bit.

A grain's state is read from its owner's core in terms that mean the same on every rank: global
node numbers. Per node its position, velocity, force, dilatation, the overlap its probe opened
with, its bonds' states and the smallest node of its fragment; per pair of nodes in contact
(listed at one of the grain's nodes) the friction spring, per node and wall surface the wall's
friction spring; per collision in progress whose first body lies in the grain (bodies named by
their smallest node) the collision's history. The receiving rank builds its new part from these:
it restores the state, lists every node again (a search, as the serial run makes whenever the
nodes moved far enough: the lists hold every pair within reach either way, so the forces are the
same), and gives each listed pair back its spring. The lists' search is the only step the serial
run does not make at that moment, and it changes no force (tests/test_mpi.py checks the bits).

The checkpoint format (the dict of `core.checkpoint()`, bind_checkpoint.cpp) carries the state
in and out.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from granulate.node_map import NodeMap
    from granulate.simulation import Simulation

NO_SPRING = 2**32 - 1  # ContactModel::no_spring: an entry without a friction spring
# Per collision: approach, normal (3), work, exponent, phase, slide (3), rolling (3).
_COLLISION_VALUES = 13


@dataclass
class GrainState:
    """One grain's state in global node numbers (see the module's docstring)."""

    positions: NDArray[np.float64]  # (n, 3) [m]
    velocities: NDArray[np.float64]  # (n, 3) [m/s]
    forces: NDArray[np.float64]  # (n, 3) force densities of the last step [N/m^3]
    dilatation: NDArray[np.float64]  # (n,)
    opened_rest: NDArray[np.float64]  # (n,) [m]
    bonds: NDArray[np.uint8]  # each bond of the grain's nodes, in the model's bond order
    roots: NDArray[np.int64]  # (n,) the smallest node of each node's fragment
    pair_springs: NDArray[np.int64]  # (k, 2) node, partner
    pair_spring_values: NDArray[np.float64]  # (k, 3) [m]
    wall_springs: NDArray[np.int64]  # (k, 3) node, wall, surface
    wall_spring_values: NDArray[np.float64]  # (k, 3) [m]
    collisions: NDArray[np.int64]  # (k, 3) first node of body a, of body b or the wall, is wall
    collision_values: NDArray[np.float64]  # (k, 13)


def grain_states(
    part: Simulation, saved: dict[str, Any], to_global: NDArray[np.int64], grains: dict[int, slice]
) -> dict[int, GrainState]:
    """The state of `grains` (grain -> its local node slice) of `part`, a rank's simulation
    whose local node i is global node to_global[i]; `saved`: its core's checkpoint()."""
    core = part.core
    fragments = np.asarray(core.fragments(), dtype=np.int64)
    collisions, values = _collisions(saved, body_first_nodes(part, fragments), to_global)
    grain_of_node = np.full(len(to_global), -1, dtype=np.int64)
    for grain, nodes in grains.items():
        grain_of_node[nodes] = grain
    pair_rows, pair_columns, pair_springs = _pair_springs(saved)
    wall_rows, wall_keys, wall_springs = _wall_springs(core, saved)
    pairs = _by_grain(grain_of_node[pair_rows], grains)
    walls = _by_grain(grain_of_node[wall_rows], grains)
    mine = _by_grain(grain_of_node[collisions[:, 0]], grains)
    bond_offsets = np.asarray(part.model.bond_offsets)
    roots = to_global[fragments]
    opened = np.asarray(saved["contact_opened_rest"])
    if len(opened) == 0:
        opened = np.zeros(len(to_global))
    x, v, f = (
        np.asarray(saved[key]).reshape(-1, 3) for key in ("positions", "velocities", "forces")
    )
    dilatation, bonds = np.asarray(saved["dilatation"]), np.asarray(saved["bond_intact"])
    return {
        grain: GrainState(
            positions=x[nodes],
            velocities=v[nodes],
            forces=f[nodes],
            dilatation=dilatation[nodes],
            opened_rest=opened[nodes],
            bonds=bonds[bond_offsets[nodes.start] : bond_offsets[nodes.stop]],
            roots=roots[nodes],
            pair_springs=np.column_stack(
                [to_global[pair_rows[pairs[grain]]], to_global[pair_columns[pairs[grain]]]]
            ),
            pair_spring_values=pair_springs[pairs[grain]],
            wall_springs=np.column_stack(
                [to_global[wall_rows[walls[grain]]], wall_keys[walls[grain]]]
            ),
            wall_spring_values=wall_springs[walls[grain]],
            collisions=np.column_stack(
                [to_global[collisions[mine[grain], 0]], collisions[mine[grain], 1:]]
            ),
            collision_values=values[mine[grain]],
        )
        for grain, nodes in grains.items()
    }


def _by_grain(labels: NDArray[np.int64], grains: dict[int, slice]) -> dict[int, NDArray[np.int64]]:
    """Per grain, the indices of the items labelled with it, in their order (one sort, not a
    pass over the items per grain)."""
    order = np.argsort(labels, kind="stable")
    ordered = labels[order]
    return {
        grain: order[np.searchsorted(ordered, grain) : np.searchsorted(ordered, grain, "right")]
        for grain in grains
    }


def body_first_nodes(
    part: Simulation, fragments: NDArray[np.int64] | None = None
) -> NDArray[np.int64]:
    """Each body's smallest local node, in the core's body numbering: the particles while no
    bond has broken on this rank, else the fragments in the order of their smallest node
    (ContactModel::label_bodies). `fragments`: core.fragments(), when already at hand."""
    if part.core.broken_bonds() == 0:
        particle = np.asarray(part.model.node_particle, dtype=np.int64)
        return np.flatnonzero(np.diff(particle, prepend=-1) != 0)
    labels = part.core.fragments() if fragments is None else fragments
    return np.unique(np.asarray(labels, dtype=np.int64))


def csr_rows(offsets: NDArray[np.int64]) -> NDArray[np.int64]:
    """The row of each entry of CSR lists with these offsets (rows + 1 of them)."""
    return np.repeat(np.arange(len(offsets) - 1), np.diff(offsets))


def wall_lists(core: Any) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
    """The core's wall lists: per node the offsets of its entries, each entry's node and its
    (wall, surface), (entries, 2)."""
    offsets, flat = (np.asarray(a, dtype=np.int64) for a in core.contact_wall_entries())
    return offsets, csr_rows(offsets), flat.reshape(-1, 2)


def _collisions(
    saved: dict[str, Any], bodies_first: NDArray[np.int64], to_global: NDArray[np.int64]
) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """The slots of the checkpoint `saved` that hold a collision in progress: (k, 3) local
    first node of body a, global first node of body b (or the wall), 1 for a wall slot; and
    their (k, 13) values."""
    slots = np.asarray(saved["contact_slots"], dtype=np.int64).reshape(-1, 2)
    count = len(slots)
    values = np.zeros((count, _COLLISION_VALUES))
    values[:, 0] = saved["contact_slot_approach"]
    values[:, 1:4] = np.asarray(saved["contact_slot_normal"]).reshape(-1, 3)
    values[:, 4:7] = np.asarray(saved["contact_slot_work"]).reshape(-1, 3)
    for column, key in ((7, "contact_slot_slide"), (10, "contact_slot_rolling")):
        entries = np.asarray(saved[key])
        if len(entries):
            values[:, column : column + 3] = entries.reshape(-1, 3)
    no_collision = np.zeros(_COLLISION_VALUES)
    no_collision[5] = 1.0  # the exponent of Collision{}
    open_ = np.any(values != no_collision, axis=1)
    wall = np.arange(count) >= int(saved["contact_particle_slot_count"])
    first = bodies_first[slots[:, 0]]
    second = np.where(wall, slots[:, 1], to_global[bodies_first[np.where(wall, 0, slots[:, 1])]])
    keys = np.column_stack([first, second, wall.astype(np.int64)])
    return keys[open_], values[open_]


def _pair_springs(
    saved: dict[str, Any],
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.float64]]:
    """The list entries that hold a friction spring: local rows, partners and spring values."""
    offsets = np.asarray(saved["contact_pair_offsets"], dtype=np.int64)
    if len(offsets) == 0:
        empty = np.zeros(0, dtype=np.int64)
        return empty, empty, np.zeros((0, 3))
    held = np.asarray(saved["contact_pair_springs"], dtype=np.int64)
    has = held != NO_SPRING
    pool = np.asarray(saved["contact_springs"]).reshape(-1, 3)
    partners = np.asarray(saved["contact_pair_partners"], dtype=np.int64)
    return csr_rows(offsets)[has], partners[has], pool[held[has]]


def _wall_springs(
    core: Any, saved: dict[str, Any]
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.float64]]:
    """The wall entries that hold a friction spring: local rows, (wall, surface) and values."""
    held = np.asarray(saved["contact_wall_springs"], dtype=np.int64)
    if len(held) == 0:
        return np.zeros(0, np.int64), np.zeros((0, 2), np.int64), np.zeros((0, 3))
    _, rows, keys = wall_lists(core)
    has = held != NO_SPRING
    pool = np.asarray(saved["contact_springs"]).reshape(-1, 3)
    return rows[has], keys[has], pool[held[has]]


def restore_grains(
    core: Any, states: list[GrainState], to_local: NodeMap, moment: dict[str, Any]
) -> None:
    """Put `states` (the held grains' states, in the core's grain order) into `core`, a new
    rank part whose global node g is local node to_local[g] (-1: not held): the state, the
    collisions of the pairs of held bodies, a search of the contact lists, then each listed
    pair's friction spring. `moment`: the time, step and contact scalars of any rank's
    checkpoint at this step (the same on every rank)."""
    bonds = np.concatenate([s.bonds for s in states])
    node_body = _node_bodies(states, to_local, broken=bool(np.any(bonds == 0)))
    slots, values, particle_slots = _slots(states, node_body, to_local)
    data = {key: moment[key] for key in _MOMENT_KEYS}
    data |= {
        "positions": np.concatenate([s.positions for s in states]).ravel(),
        "velocities": np.concatenate([s.velocities for s in states]).ravel(),
        "forces": np.concatenate([s.forces for s in states]).ravel(),
        "dilatation": np.concatenate([s.dilatation for s in states]),
        "bond_intact": bonds,
        "contact_built": False,
        "contact_positions_at_build": np.zeros(0),
        "contact_time_at_build": moment["time"],
        "contact_broken_at_build": 0,
        "contact_slots": slots.astype(np.uint32).ravel(),
        "contact_particle_slot_count": particle_slots,
        "contact_slot_approach": values[:, 0].copy(),
        "contact_slot_normal": values[:, 1:4].ravel(),
        "contact_slot_work": values[:, 4:7].ravel(),
        "contact_slot_slide": values[:, 7:10].ravel(),
        "contact_slot_rolling": values[:, 10:13].ravel(),
        "contact_pair_offsets": np.zeros(0, np.uint32),
        "contact_pair_partners": np.zeros(0, np.uint32),
        "contact_springs": np.zeros(0),
        "contact_pair_springs": np.zeros(0, np.uint32),
        "contact_wall_springs": np.zeros(0, np.uint32),
        "contact_opened_rest": np.concatenate([s.opened_rest for s in states]),
    }
    core.restore(data)
    core.search_contacts()
    listed = dict(core.checkpoint())
    _give_springs(core, listed, states, to_local)
    core.restore(listed)


# The entries of a checkpoint that are the same on every rank at a step, or that the receiving
# rank keeps as its own (its counters, its walls' last reactions: recomputed by the next step).
def moment_of(saved: dict[str, Any]) -> dict[str, Any]:
    """Of a core checkpoint (core.checkpoint()), what restore_grains reads besides the grains'
    states: the time, step and contact scalars."""
    return {key: saved[key] for key in _MOMENT_KEYS}


_MOMENT_KEYS = (
    "time",
    "step",
    "contact_skin",
    "contact_last_time",
    "contact_has_last_time",
    "contact_statistics",
    "contact_overlaps",
    "contact_wall_reactions",
)


def _node_bodies(states: list[GrainState], to_local: NodeMap, broken: bool) -> NDArray[np.int64]:
    """Each local node's body as the core numbers them (ContactModel::label_bodies): its
    particle while no bond is broken, else its fragment in the order of their smallest node."""
    if not broken:
        sizes = [len(s.roots) for s in states]
        return np.repeat(np.arange(len(states)), sizes)
    roots = to_local[np.concatenate([s.roots for s in states])]
    return np.unique(roots, return_inverse=True)[1].astype(np.int64)


def _slots(
    states: list[GrainState], node_body: NDArray[np.int64], to_local: NodeMap
) -> tuple[NDArray[np.int64], NDArray[np.float64], int]:
    """The collisions between held bodies (and of held bodies with walls) as the core's slots:
    (k, 2) body pairs sorted (p <= q), then (body, wall) pairs sorted; their values; the number
    of particle slots."""
    keys = np.concatenate([s.collisions for s in states]).reshape(-1, 3)
    values = np.concatenate([s.collision_values for s in states]).reshape(-1, _COLLISION_VALUES)
    wall = keys[:, 2] == 1
    second = to_local[np.where(wall, 0, keys[:, 1])]
    kept = wall | (second >= 0)
    keys, values, wall, second = keys[kept], values[kept], wall[kept], second[kept]
    p = node_body[to_local[keys[:, 0]]]
    q = np.where(wall, keys[:, 1], node_body[np.where(wall, 0, second)])
    first, last = np.where(wall, p, np.minimum(p, q)), np.where(wall, q, np.maximum(p, q))
    order = np.lexsort((last, first, wall))  # particle slots first, each kind sorted
    slots = np.column_stack([first, last])[order]
    same = np.all(slots[1:] == slots[:-1], axis=1) & (wall[order][1:] == wall[order][:-1])
    if np.any(same):
        raise RuntimeError("migration: two collision histories for one pair of bodies")
    return slots, values[order], int(np.count_nonzero(~wall))


def _give_springs(
    core: Any, listed: dict[str, Any], states: list[GrainState], to_local: NodeMap
) -> None:
    """Each friction spring of `states` to the entry of its pair (or node and wall surface) in
    the freshly searched lists of `listed`, in place. A spring of two held nodes whose pair the
    search did not list would be lost contact: an error, not a silent difference."""
    rows = csr_rows(np.asarray(listed["contact_pair_offsets"], dtype=np.int64))
    pair_entries = np.column_stack([rows, np.asarray(listed["contact_pair_partners"], np.int64)])
    _, wall_rows, wall_keys_listed = wall_lists(core)
    wall_entries = np.column_stack([wall_rows, wall_keys_listed])
    pair_keys = to_local[np.concatenate([s.pair_springs for s in states]).reshape(-1, 2)]
    pair_values = np.concatenate([s.pair_spring_values for s in states]).reshape(-1, 3)
    walls = np.concatenate([s.wall_springs for s in states]).reshape(-1, 3)
    wall_keys = np.column_stack([to_local[walls[:, 0]], walls[:, 1:]])
    wall_values = np.concatenate([s.wall_spring_values for s in states]).reshape(-1, 3)
    held_pairs = np.all(pair_keys >= 0, axis=1)
    pair_keys, pair_values = pair_keys[held_pairs], pair_values[held_pairs]
    pair_springs = _entry_springs(pair_entries, pair_keys, 0)
    wall_springs = _entry_springs(wall_entries, wall_keys, len(pair_keys))
    listed["contact_springs"] = np.concatenate([pair_values, wall_values]).ravel()
    listed["contact_pair_springs"] = pair_springs
    listed["contact_wall_springs"] = wall_springs


def _entry_springs(
    entries: NDArray[np.int64], springs: NDArray[np.int64], first: int
) -> NDArray[np.uint32]:
    """Per entry (rows of integer keys) the index in the pool of the spring with the same key
    (springs numbered from `first` in their order), else NO_SPRING."""
    held = np.full(len(entries), NO_SPRING, dtype=np.uint32)
    if len(springs) == 0:
        return held
    shape = np.maximum(entries.max(axis=0, initial=0), springs.max(axis=0)) + 1
    entry_code = np.ravel_multi_index(entries.T, shape)
    spring_code = np.ravel_multi_index(springs.T, shape)
    order = np.argsort(entry_code, kind="stable")
    found = order[np.clip(np.searchsorted(entry_code[order], spring_code), 0, len(order) - 1)]
    if len(entries) == 0 or np.any(entry_code[found] != spring_code):
        raise RuntimeError("migration: a friction spring's pair is not in the searched lists")
    held[found] = first + np.arange(len(springs), dtype=np.uint32)
    return held
