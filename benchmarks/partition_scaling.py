"""How whole-grain decomposition would scale (issue 17): partitions of a 10^5-grain 3D packing,
their measured ghosts, and a model of the communication share of a step, on paper.

    python benchmarks/partition_scaling.py                   # 10^5 grains, R/h = 6, K = 2 ... 2048
    python benchmarks/partition_scaling.py --json out.json   # the table as JSON too

No distributed run is made: these are partitions and a model. The packing (granulate.pack,
lattice sites in a cube, radii 0.9-1.1 mm) is cut into K ranks by recursive coordinate bisection
of whole grains (granulate.parallel), and each rank's ghosts are the other ranks' grains whose
bounding spheres come within `--reach` of its own: all twelve lattice neighbours, as many as a
dense pile's contact candidates. A step then needs, per rank:

- compute: its nodes / the node-steps per second of one core, measured here on a small 3D
  assembly of the same spheres (conforming, R/h = 6; contact, gravity, no output);
- one exchange: the positions and velocities (48 bytes) of the ghost grains' nodes that can
  touch its own, those within --shell mesh sizes of their surface, one message per
  neighbouring rank (latency + bytes / bandwidth);
- one reduction (the stability check's minimum): 2 log2(K) latencies.

The network is an assumption, printed with the table: latency 1.5 us and 0.39 GB/s per rank (a
100 Gb/s link shared by 32 ranks, every neighbour on another node: the pessimistic case).
"comm %" assumes no overlap of communication with computation; "hidden %" (and the caps
table's second figure) what is left exposed with the exchange under way while the rank
evaluates its bond forces, as DistributedRun does (all but the first of their PARTS
parts; their share of a step measured), which assumes the MPI moves a message on between
its calls (a network's RDMA does; on one machine's shared memory the copy is the CPU's work,
done within the progress calls).

A second table splits one body at node level (`--block N`: an N^3 simple-cubic block, horizon
3.015 spacings, LAMMPS' lattice): the same bisection over its nodes, and as halo each rank's
nodes of other ranks within one horizon (its bonds' partners). An LPS step exchanges twice:
positions (24 bytes) before the dilatation pass and the dilatations (8 bytes) before the force
pass; compute is one core's node-steps per second on a 20^3 block of that lattice (measured).

A third table models the engine as built (granulate.parallel.DistributedRun): whole ghost
grains within the reach plus its margin, stepped but for their bonds (which the core skips for
ghosts; the share of a step a ghost saves is measured on the same 27 spheres), all their
nodes' x and v and the bonds broken exchanged within each step (see as_built).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
from granulate._core import points_within

import granulate as gr
from granulate.parallel import bisect, ghosts, near_pairs
from granulate.parallel.engine import contact_reads
from granulate.parallel.overlap import PARTS

RADIUS = 1e-3
#: The check after each step (one reduction of the travel the core measures in its last half
#: kick, and the Python around it), as a share of a step: 0.2 % on one rank of `granulate bench
#: --ranks`' pile3d (1,000 grains, 258,624 nodes; measured; 4.4 % when it was a NumPy pass).
CHECK_SHARE = 0.002
MATERIAL = gr.Material(density=1200, bulk_modulus=2.16e7, shear_modulus=1.296e7, fracture_energy=50)


def packing(count: int) -> gr.Packing:
    """`count` spheres of radius 0.9-1.1 mm on face-centred cubic sites of a cube."""
    side = 2.2e-3 * np.sqrt(2) * (np.ceil((count / 4) ** (1 / 3)) + 1)  # sites, and a margin
    coarse = gr.Grain(gr.Sphere((0, 0, 0), RADIUS), MATERIAL, RADIUS, gr.Uniform(0.9e-3, 1.1e-3))
    return gr.pack(gr.Box((0, 0, 0), (side, side, side)), [coarse], count, method="lattice", seed=1)


def grain_nodes(nodes_across_radius: int) -> np.ndarray:
    """A conforming sphere's nodes at unit radius, (nodes, 3)."""
    sphere = gr.ReferenceShape.from_shape(
        gr.Sphere((0, 0, 0), RADIUS), RADIUS / nodes_across_radius, discretization="conforming"
    )
    return np.asarray(sphere.positions)[:, :3] / RADIUS


def exchanged_nodes(
    centres: np.ndarray,
    radii: np.ndarray,
    owner: np.ndarray,
    ranks: int,
    pairs,
    unit_nodes: np.ndarray,
    reach: float,
) -> np.ndarray:
    """(ranks,) the ghost nodes each rank needs: of each ghost grain, the nodes within `reach`
    of the bounding sphere of one of the rank's grains near it."""
    first, last = pairs
    crossing = owner[first] != owner[last]
    ghost = np.concatenate([last[crossing], first[crossing]])
    own = np.concatenate([first[crossing], last[crossing]])
    rank = owner[own]
    order = np.lexsort((ghost, rank))
    ghost, own, rank = ghost[order], own[order], rank[order]
    group_start = np.flatnonzero(np.r_[True, (np.diff(rank) != 0) | (np.diff(ghost) != 0)])
    counts = np.zeros(ranks, dtype=np.int64)
    chunk = 4096  # groups at a time: (pairs, nodes) booleans
    for begin in range(0, len(group_start), chunk):
        groups = group_start[begin : begin + chunk]
        end = group_start[begin + chunk] if begin + chunk < len(group_start) else len(ghost)
        rows = slice(groups[0], end)
        nodes = centres[ghost[rows], None, :] + radii[ghost[rows], None, None] * unit_nodes
        gap = np.linalg.norm(nodes - centres[own[rows], None, :], axis=2) - radii[own[rows], None]
        near = np.logical_or.reduceat(gap <= reach, groups - groups[0], axis=0)
        np.add.at(counts, rank[groups], near.sum(axis=1))
    return counts


def touching_spheres(nodes_across_radius: int, pair_law: str = "surface") -> gr.Simulation:
    """27 touching spheres of the packing's mesh in a box under gravity (not yet run)."""
    gr.set_num_threads(1)
    sim = gr.Simulation(3, gravity=(0, -9.81, 0))
    sim.contact = gr.Contact(restitution=0.5, friction=0.3, pair_law=pair_law)
    sphere = gr.ReferenceShape.from_shape(
        gr.Sphere((0, 0, 0), RADIUS), RADIUS / nodes_across_radius, discretization="conforming"
    )
    for index in np.ndindex(3, 3, 3):
        sim.add_particle(sphere, MATERIAL, position=tuple(2.0e-3 * np.array(index) + 1.2e-3))
    sim.add_wall(gr.BoxContainer((0, 0, 0), (6.4e-3, 8e-3, 6.4e-3)), name="box")
    return sim


class Measured(NamedTuple):
    """One core's figures on the 27 touching spheres (node_steps_per_second)."""

    rate: float  # node-steps per second
    bond_share: float  # the bond passes' share of a step
    ghost_saving: float  # the share of a step a ghost saves
    forces: float  # the bond forces' share of a step (bond_force_share)


def node_steps_per_second(nodes_across_radius: int, steps: int = 300) -> Measured:
    """One core's node-steps per second on 27 touching spheres in a box under gravity, the
    share of the bond passes (peridynamics) in the step, the share a ghost saves (the same
    steps again from the same state with every sphere a ghost, core.set_ghost_particles: both
    bond passes skipped; the time saved over the time taken), and the share of the bond forces
    (bond_force_share)."""
    sim = touching_spheres(nodes_across_radius)
    sim.run(20)
    saved = sim.core.checkpoint()
    before = sim.summary()["peridynamics_seconds"]
    start = time.perf_counter()
    sim.core.run(steps)
    seconds = time.perf_counter() - start
    bonds = sim.summary()["peridynamics_seconds"] - before
    sim.core.restore(saved)
    forces = bond_force_share(sim)
    sim.core.restore(saved)
    sim.core.set_ghost_particles(list(range(len(sim.bodies))))
    start = time.perf_counter()
    sim.core.run(steps)
    as_ghosts = time.perf_counter() - start
    ghost_saving = max(0.0, 1.0 - as_ghosts / seconds)
    return Measured(sim.node_count * steps / seconds, bonds / seconds, ghost_saving, forces)


def bond_force_share(sim: gr.Simulation, steps: int = 100) -> float:
    """The share of a step its bond forces take (core.evaluate_bonds: the body forces and pass
    2 of the bonds), measured over `steps` steps taken in halves: what DistributedRun evaluates
    while the step's exchange is under way."""
    core = sim.core
    inside = 0.0
    start = time.perf_counter()
    for _ in range(steps):
        core.begin_step()
        began = time.perf_counter()
        core.evaluate_bonds()
        inside += time.perf_counter() - began
        core.finish_step(np.zeros((0, 2), np.uint32))
    return inside / (time.perf_counter() - start)


def measured_caps(nodes_across_radius: int, depth: float, pair_law: str) -> tuple[float, float]:
    """The engine's caps over this model's layer, measured on the 27 touching spheres after
    320 steps under `pair_law`: for each sphere and each other one, the nodes the engine would
    send of it (as DistributedRun._exchange_caps picks them: list positions within the cutoff
    plus the default cap margin h/2 of the other's, and their anchors, contact_reads, each
    node's x and v; with half a node for each surface normal sent, 3 numbers, of those within
    the normal reach plus the margin bonded to a node outside the cap, the faces) over the
    nodes within `depth` of the other's bounding sphere (exchanged_nodes' layer), summed over
    the pairs with a node in that layer; and what the owner spends computing the faces'
    normals each step (core.surface_normals, timed) in node-steps of these spheres (timed
    too) per node of that layer."""
    sim = touching_spheres(nodes_across_radius, pair_law)
    sim.run(300)
    start = time.perf_counter()
    sim.run(20)
    node_step = (time.perf_counter() - start) / (20 * sim.node_count)
    core = sim.core
    x, nodes = core.list_positions, core.positions
    margin = 0.5 * RADIUS / nodes_across_radius
    cutoff, normal_reach = core.contact_reach, core.contact_surface_normal_reach
    capped, layer, faces = 0.0, 0, [np.zeros(0, np.int64)]
    for body in sim.bodies:
        mine = np.arange(body.node_slice.start, body.node_slice.stop)
        for other in sim.bodies:
            theirs = other.node_slice
            centre = nodes[theirs].mean(axis=0)
            within = np.linalg.norm(nodes[mine] - centre, axis=1) - RADIUS <= depth
            if other is body or not within.any():
                continue
            near = mine[points_within(x[mine], x[theirs], cutoff + margin).astype(bool)]
            normal = near[points_within(x[near], x[theirs], normal_reach + margin).astype(bool)]
            cap = contact_reads(core, near)
            normal = np.asarray(sim.model.bonded_beyond(normal.tolist(), cap.tolist()), np.int64)
            capped += len(cap) + 0.5 * len(normal)
            layer += int(within.sum())
            faces.append(normal)
    return capped / layer, _normals_seconds(core, np.concatenate(faces)) / node_step / layer


def _normals_seconds(core: Any, faces: np.ndarray, repeats: int = 20) -> float:
    """Seconds of one core.surface_normals of `faces`, within a step (after its breaks), as an
    owner computes them; the mean of `repeats`."""
    core.begin_step()
    start = time.perf_counter()
    for _ in range(repeats):
        core.surface_normals(faces.tolist())
    seconds = (time.perf_counter() - start) / repeats
    core.finish_step(np.zeros((0, 2), np.uint32))
    return seconds


def communication_seconds(
    exchanges: int, neighbours: int, sent_bytes: float, ranks: int, args: argparse.Namespace
) -> tuple[float, float]:
    """A step's exchanges with `neighbours` ranks (a message each), `sent_bytes` in all, and
    its one reduction (2 log2 ranks latencies): (exchange seconds, reduction seconds)."""
    exchange = exchanges * neighbours * args.latency + sent_bytes / args.bandwidth
    return exchange, 2 * np.log2(ranks) * args.latency


def rank_table(
    centres: np.ndarray,
    radii: np.ndarray,
    pairs,
    ranks: int,
    unit_nodes: np.ndarray,
    reach: float,
) -> dict[str, float]:
    """One partition, per rank: grains, ghost grains, ghost nodes to receive and neighbouring
    ranks, from the grains' `pairs` in reach (near_pairs); the rank that receives the most ghost
    nodes per owned node is the one reported."""
    partition = bisect(centres, np.ones(len(centres)), ranks)
    needed = ghosts(partition, pairs)
    owned = np.bincount(partition.owner, minlength=ranks)
    ghost_grains = np.array([len(g) for g in needed])
    ghost_nodes = exchanged_nodes(centres, radii, partition.owner, ranks, pairs, unit_nodes, reach)
    neighbours = np.array([len(np.unique(partition.owner[g])) for g in needed])
    worst = int(np.argmax(ghost_nodes / owned))
    return {
        "ranks": ranks,
        "grains_per_rank": float(owned.mean()),
        "ghost_grains_mean": float(ghost_grains.mean()),
        "ghost_grains_over_owned_max": float(np.max(ghost_grains / owned)),
        "owned_nodes": int(owned[worst] * len(unit_nodes)),
        "ghost_nodes": int(ghost_nodes[worst]),
        "neighbours_max": int(neighbours.max()),
        "neighbours_mean": float(neighbours.mean()),
        "candidates_per_grain": 2 * len(pairs[0]) / len(centres),
    }


def modelled(row: dict, measured: Measured, args: argparse.Namespace) -> dict[str, float]:
    """That rank's step: compute, one exchange of its ghost nodes' positions and velocities,
    one reduction; the share of communication in the step, without overlap and with the
    exchange hidden behind the bond forces, as DistributedRun overlaps them (all but their
    first of PARTS parts, measured.forces of a step)."""
    compute = row["owned_nodes"] / measured.rate
    ghost_bytes = 48.0 * row["ghost_nodes"]
    exchange, reduction = communication_seconds(
        1, row["neighbours_max"], ghost_bytes, row["ranks"], args
    )
    hiding = measured.forces * (1 - 1 / PARTS) * compute
    exposed = max(0.0, exchange - hiding) + reduction
    return {
        "ghost_bytes_per_step": ghost_bytes,
        "compute_s": compute,
        "communication_s": exchange + reduction,
        "communication_share": (exchange + reduction) / (compute + exchange + reduction),
        "exposed_share": exposed / (compute + exposed),
    }


def as_built(
    centres: np.ndarray,
    radii: np.ndarray,
    pairs,
    ranks: int,
    unit_nodes: np.ndarray,
    measured: Measured,
    args: argparse.Namespace,
    depths: dict[str, tuple[float, float, float]],
) -> dict:
    """The engine as built (granulate.parallel.DistributedRun), for the rank with the most ghost
    grains per owned grain: its ghosts are whole grains within the reach plus the margin (the
    largest bounding radius; `pairs`: near_pairs at that distance), stepped but for their
    bonds (measured.ghost_saving of a step, which the core skips for ghosts); within the step it
    receives 48 bytes (x, v) of every ghost node and the bonds broken (one message per
    neighbouring rank), checks after each step (CHECK_SHARE of a step, measured) and reduces
    once. Efficiency: its own nodes' compute over its step; the same with the ghosts stepped in
    full, and if ghosts were not stepped at all (not built). "cap_shares": the communication
    share when it receives, instead of whole ghosts, only the ghost nodes within each of
    `depths` (depth [m], factor, normals) of one of its grains' bounding spheres
    (exchanged_nodes; the ghosts still held and stepped whole) times the factor, with a second
    reduction per step (the caps' check within the step), and the owner's computing of the
    normals it sends (as many node-steps per layer node as `depths` says), counted with the
    communication. "cap_exposed": the same with the exchange under way while the rank
    evaluates its bond forces (overlap.while_travelling): hidden but for what
    outlasts the last PARTS - 1 parts of them (measured.forces: their share of a step;
    the MPI is first called on to move the messages after the first part)."""
    rate, ghost_saving = measured.rate, measured.ghost_saving
    partition = bisect(centres, np.ones(len(centres)), ranks)
    needed = ghosts(partition, pairs)
    owned = np.bincount(partition.owner, minlength=ranks)
    worst = int(np.argmax([len(g) / o for g, o in zip(needed, owned, strict=True)]))
    own, ghost = owned[worst] * len(unit_nodes), len(needed[worst]) * len(unit_nodes)
    neighbours = len(np.unique(partition.owner[needed[worst]]))
    useful = own / rate
    stepped = (own + (1.0 - ghost_saving) * ghost) / rate * (1 + CHECK_SHARE)
    in_full = (own + ghost) / rate * (1 + CHECK_SHARE)
    lean = useful * (1 + CHECK_SHARE)

    def communication(sent: int) -> tuple[float, float]:
        # one message per neighbour within a step: x and v of the nodes sent, the bonds broken
        return communication_seconds(1, neighbours, 48.0 * sent, ranks, args)

    talk = sum(communication(ghost))
    hiding = measured.forces * (1 - 1 / PARTS) * useful
    cap_shares, cap_exposed = {}, {}
    for name, (depth, factor, faces) in depths.items():  # a check in the step, the normals
        counts = exchanged_nodes(centres, radii, partition.owner, ranks, pairs, unit_nodes, depth)
        exchange, reduction = communication(round(factor * counts[worst]))
        rest = 2 * reduction + faces * counts[worst] / rate
        capped, exposed = exchange + rest, max(0.0, exchange - hiding) + rest
        cap_shares[name] = capped / (stepped + capped)
        cap_exposed[name] = exposed / (stepped + exposed)
    return {
        "ranks": ranks,
        "ghost_grains_over_owned": len(needed[worst]) / owned[worst],
        "neighbours": neighbours,
        "exchange_bytes": 48.0 * ghost,
        "communication_share": talk / (stepped + talk),
        "efficiency": useful / (stepped + talk),
        "efficiency_ghosts_in_full": useful / (in_full + talk),
        "efficiency_without_ghost_steps": useful / (lean + talk),
        "cap_shares": cap_shares,
        "cap_exposed": cap_exposed,
    }


def lps_node_steps_per_second(steps: int = 30) -> float:
    """One core's node-steps per second of LPS on a 20^3 simple-cubic block (no contact)."""
    gr.set_num_threads(1)
    sim = gr.Simulation(3)
    rock = gr.Material(
        density=2200,
        bulk_modulus=14.9e9,
        shear_modulus=14.0e9,
        horizon_factor=3.015,
        fracture=False,
    )
    sim.add_body(gr.Box((0, 0, 0), (10e-3, 10e-3, 10e-3)), rock, 0.5e-3)
    sim.run(2)
    start = time.perf_counter()
    sim.run(steps)
    return sim.node_count * steps / (time.perf_counter() - start)


#: Cap depths at R/h = 6 (h = R/6, horizon 3 h, the cutoff the reach), each with the contact
#: law whose caps the engine picks measured against it (measured_caps; None: the layer as it is):
#: as the engine picked them before its check within the step (the cutoff, a cap margin of at
#: least 4 h, 2 h for the surface points' offset, and the bonded neighbours a horizon deeper,
#: taken here as depth), the whole of a near ghost; as it picked them in session 45 under the
#: surface law for grains at rest or loaded slowly (the default cap margin h/2, which widens only
#: where the caps last under 50 steps; the points' offset about h each; the neighbours); as it
#: picks them now under the surface law and under PeriDEM's node pairs (measured on the model's
#: own mesh: the layer of the cutoff and the default cap margin, times the engine's caps over
#: that layer); the cutoff alone (caps picked by the owners every step: no cap margin).
CAP_LAYERS = (
    ("before", lambda reach, h: reach + 4 * h + 2 * h + 3 * h, None),
    ("session 45", lambda reach, h: reach + 0.5 * h + 2 * h + 3 * h, None),
    ("surface law", lambda reach, h: reach + 0.5 * h, "surface"),
    ("node pairs", lambda reach, h: reach + 0.5 * h, "peridem"),
    ("cutoff only", lambda reach, h: reach, None),
)


def cap_depths(args: argparse.Namespace) -> dict[str, tuple[float, float, float]]:
    """CAP_LAYERS' (depth [m], factor, the owner's normals in node-steps per layer node) at
    this mesh, the laws' factors and normals measured (measured_caps), printed."""
    h = RADIUS / args.nodes_across_radius
    depths = {}
    for name, layer, law in CAP_LAYERS:
        depth = layer(args.reach, h)
        measured = (
            (1.0, 0.0) if law is None else measured_caps(args.nodes_across_radius, depth, law)
        )
        depths[name] = (depth, *measured)
        if law is not None:
            print(
                f"{name}: the engine's caps are {measured[0]:.2f} times the nodes within "
                f"{1e3 * depth:.2f} mm of a neighbour's sphere (27 touching spheres, measured), "
                f"their normals {measured[1]:.3f} node-steps of compute per node of that layer"
            )
    return depths


def engine_as_built(
    pack: gr.Packing,
    unit_nodes: np.ndarray,
    measured: Measured,
    args: argparse.Namespace,
) -> list[dict]:
    """The table of as_built for 2, 4, ... ranks, and with --caps the table of its
    communication share with the caps of CAP_LAYERS instead of whole ghosts (as the engine
    picks them: a ghost grain farther than the cap's depth from the rank's grains sends
    nothing, a near one all of it at this mesh; and thinner)."""
    margin = float(pack.radii.max())
    pairs = near_pairs(pack.positions, pack.radii, args.reach + margin)
    depths = cap_depths(args) if args.caps else {}
    print(
        f"\nthe engine as built: whole ghost grains within {1e3 * (args.reach + margin):.2f} mm "
        f"(reach + margin) stepped but for their bonds ({100 * measured.ghost_saving:.0f} % of a "
        "step, measured), x, v of every ghost node and the step's broken bonds exchanged, "
        "the check "
        f"({100 * CHECK_SHARE:.1f} % of a step) and one reduction"
    )
    print(
        f"{'ranks':>6} {'ghost/own':>9} {'neighbours':>10} {'exchange kB':>11} {'comm %':>6} "
        f"{'efficiency':>10} {'ghosts in full':>14} {'no ghost steps':>14}"
    )
    rows = []
    ranks = 2
    while ranks <= min(args.largest, args.grains):
        row = as_built(pack.positions, pack.radii, pairs, ranks, unit_nodes, measured, args, depths)
        rows.append(row)
        print(
            f"{ranks:6d} {row['ghost_grains_over_owned']:9.2f} {row['neighbours']:10d} "
            f"{row['exchange_bytes'] / 1e3:11.1f} {100 * row['communication_share']:6.1f} "
            f"{row['efficiency']:10.2f} {row['efficiency_ghosts_in_full']:14.2f} "
            f"{row['efficiency_without_ghost_steps']:14.2f}"
        )
        ranks *= 2
    if depths:
        print(
            "\nthe engine with caps: communication % of the step (x, v of the ghost nodes within "
            "a depth of the rank's grains' spheres; ghosts still held and stepped whole), "
            "without overlap / exposed while the bond forces are evaluated"
        )
        heads = "".join(
            f" {f'{n} {1e3 * d:.2f} mm x{f:.2f}':>30}" for n, (d, f, _) in depths.items()
        )
        print(f"{'ranks':>6} {'whole':>8}" + heads)
        for row in rows:
            exposed = row["cap_exposed"]
            shares = "".join(
                f" {f'{100 * share:.1f} / {100 * exposed[name]:.1f}':>30}"
                for name, share in row["cap_shares"].items()
            )
            print(f"{row['ranks']:6d} {100 * row['communication_share']:8.1f}" + shares)
    return rows


def single_body(args: argparse.Namespace) -> list[dict[str, float]]:
    """The node-level split of one N^3 block: per rank nodes, halo nodes, neighbouring ranks,
    and the modelled share of the two exchanges in an LPS step."""
    side = np.arange(args.block, dtype=float)
    nodes = np.stack(np.meshgrid(side, side, side, indexing="ij"), axis=-1).reshape(-1, 3)
    pairs = near_pairs(nodes, np.zeros(len(nodes)), 3.015)
    rate = lps_node_steps_per_second()
    print(
        f"\none body: {len(nodes):,} nodes, {2 * len(pairs[0]) / len(nodes):.1f} bonds per node; "
        f"one core: {rate / 1e6:.2f} M node-steps/s of LPS (measured)"
    )
    print(
        f"{'ranks':>6} {'nodes/rank':>10} {'halo nodes':>10} {'neighbours':>10} "
        f"{'exchange kB':>11} {'compute ms':>10} {'comm ms':>8} {'comm %':>6}"
    )
    rows = []
    ranks = 2
    while ranks <= args.largest_split:
        partition = bisect(nodes, np.ones(len(nodes)), ranks)
        halo = ghosts(partition, pairs)
        owned = np.bincount(partition.owner, minlength=ranks)
        worst = int(np.argmax([len(h) / o for h, o in zip(halo, owned, strict=True)]))
        neighbours = len(np.unique(partition.owner[halo[worst]]))
        exchanged = 32.0 * len(halo[worst])
        compute = owned[worst] / rate
        communication = sum(communication_seconds(2, neighbours, exchanged, ranks, args))
        row = {
            "ranks": ranks,
            "nodes_per_rank": int(owned[worst]),
            "halo_nodes": len(halo[worst]),
            "neighbours": neighbours,
            "exchange_bytes": exchanged,
            "compute_s": compute,
            "communication_s": communication,
            "communication_share": communication / (compute + communication),
        }
        rows.append(row)
        print(
            f"{ranks:6d} {row['nodes_per_rank']:10d} {row['halo_nodes']:10d} {neighbours:10d} "
            f"{exchanged / 1e3:11.1f} {1e3 * compute:10.2f} {1e3 * communication:8.3f} "
            f"{100 * row['communication_share']:6.1f}"
        )
        ranks *= 2
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grains", type=int, default=100_000)
    parser.add_argument("--nodes-across-radius", type=int, default=6)
    parser.add_argument("--reach", type=float, default=0.5e-3, help="broad-phase reach [m]")
    parser.add_argument("--latency", type=float, default=1.5e-6, help="[s]")
    parser.add_argument("--bandwidth", type=float, default=12.5e9 / 32, help="per rank [B/s]")
    parser.add_argument("--largest", type=int, default=2048, help="ranks: 2, 4, ... this")
    parser.add_argument("--block", type=int, default=100, help="one body: N^3 nodes (0: none)")
    parser.add_argument("--largest-split", type=int, default=64, help="its ranks: 2 ... this")
    parser.add_argument(
        "--caps", action="store_true", help="also the engine with thinner caps (CAP_LAYERS)"
    )
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args()

    start = time.perf_counter()
    pack = packing(args.grains)
    unit_nodes = grain_nodes(args.nodes_across_radius)
    measured = node_steps_per_second(args.nodes_across_radius)
    rate, bond_share = measured.rate, measured.bond_share
    print(
        f"{pack.summary()}; packed in {time.perf_counter() - start:.1f} s\n"
        f"{len(unit_nodes)} nodes per grain (R/h = {args.nodes_across_radius}); one core: "
        f"{rate / 1e6:.2f} M node-steps/s, bond passes {100 * bond_share:.0f} % of the step "
        f"(a ghost saves {100 * measured.ghost_saving:.0f} %, the bond forces take "
        f"{100 * measured.forces:.0f} %; measured)\n"
        f"network assumed: latency {args.latency * 1e6:.1f} us, "
        f"{args.bandwidth / 1e9:.2f} GB/s per rank"
    )
    print(
        f"{'ranks':>6} {'grains/rank':>11} {'nodes/rank':>10} {'ghost nodes':>11} "
        f"{'neighbours':>10} {'exchange kB':>11} {'compute ms':>10} {'comm ms':>8} "
        f"{'comm %':>6} {'hidden %':>8} {'partition s':>11}"
    )
    rows = []
    pairs = near_pairs(pack.positions, pack.radii, args.reach)  # the same for every partition
    ranks = 2
    while ranks <= min(args.largest, args.grains):
        began = time.perf_counter()
        row = rank_table(pack.positions, pack.radii, pairs, ranks, unit_nodes, args.reach)
        row["partition_seconds"] = time.perf_counter() - began
        row |= modelled(row, measured, args)
        rows.append(row)
        print(
            f"{ranks:6d} {row['grains_per_rank']:11.1f} {row['owned_nodes']:10d} "
            f"{row['ghost_nodes']:11d} {row['neighbours_max']:10d} "
            f"{row['ghost_bytes_per_step'] / 1e3:11.1f} {1e3 * row['compute_s']:10.2f} "
            f"{1e3 * row['communication_s']:8.3f} {100 * row['communication_share']:6.1f} "
            f"{100 * row['exposed_share']:8.1f} {row['partition_seconds']:11.2f}"
        )
        ranks *= 2
    print(f"broad phase: {rows[0]['candidates_per_grain']:.1f} candidate partners per grain")
    built = engine_as_built(pack, unit_nodes, measured, args)
    body = single_body(args) if args.block else []
    if args.json is not None:
        settings = vars(args) | {
            "json": None,
            "rate": rate,
            "bond_share": bond_share,
            "ghost_saving": measured.ghost_saving,
            "bond_force_share": measured.forces,
        }
        result = {
            "arguments": settings,
            "grains": rows,
            "as_built": built,
            "one_body": body,
        }
        args.json.write_text(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
