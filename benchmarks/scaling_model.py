"""A weak-scaling model of distributed runs to 1,024 ranks, fed by partitions of a 3D packing
of 100,000 grains (granulate.parallel.partition; no physics is run).

    python benchmarks/scaling_model.py [--nodes-per-rank 50000] [--rate 3.0e6]
                                       [--latency 2e-6] [--bandwidth 1e10]

The packing: spheres of radius 0.98-1 mm on a cubic lattice 2 mm apart (benchmarks/
distributed.py's pile3d, grown to 47 x 47 x 46 sites), each of 4/3 pi (r/h)^3 nodes at
h = 0.25 mm (R/h = 4: about 260 nodes, as pile3d's lattice spheres). For K ranks at a fixed
number of nodes per rank, the first K x (nodes per rank) / (nodes per grain) grains (a box of
the packing, filled layer by layer) are cut by recursive coordinate bisection, and each rank's
ghosts found as a run finds them: grains of other ranks whose bounding spheres come within the
contact lists' cutoff plus the margin (the largest bounding radius, DistributedRun's default)
of its own. The cutoff is pile3d's contact reach, 0.73 mm (core.contact_reach).

The model of one step of the slowest rank, per the engine as built (docs/parallel.md):
  compute   (owned + ghost nodes) / rate: ghosts are stepped in full, then overwritten;
  check     the positions pass after each step, 4.4 % of a step on one rank (measured, pile3d);
  exchange  per neighbouring rank one message each way: latency + 72 bytes per ghost node
            (x, v, f) / bandwidth;
  reduction 2 latency log2 K (the one Allreduce per step).
Efficiency = owned nodes / rate over that time. The last column is the efficiency if ghosts
were not stepped (only moved to their owners' values: not built; their bond states would then
have to travel too), the same messages. `rate` is measured here (pile3d on one rank:
2.96-3.08 M node-steps/s on one core); latency and bandwidth are assumptions for an InfiniBand
cluster (2 us, 10 GB/s), not measurements: this machine has no network. Migrations are not in
the model (their share depends on how fast the grains move: 12-15 % in the drum benchmark,
whose grains are thrown at 2 m/s; none in the pile).
"""

from __future__ import annotations

import argparse

import numpy as np
from numpy.typing import NDArray

from granulate.parallel import bisect, ghosts, near_pairs

SPACING = 2e-3  # m
MESH_SIZE = 0.25e-3  # m: R/h = 4
CUTOFF = 0.73e-3  # m: pile3d's contact_reach (largest pair reach plus skin)
CHECK_SHARE = 0.044
BYTES_PER_GHOST_NODE = 72


def packing(grains: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Centres and radii of `grains` spheres on the cubic lattice, layer by layer."""
    rng = np.random.default_rng(3)
    side = int(np.ceil(np.sqrt(grains / 46)))
    k = np.arange(grains)
    layer, rest = np.divmod(k, side * side)
    row, column = np.divmod(rest, side)
    centres = SPACING * np.column_stack([column, layer, row]).astype(float)
    return centres, rng.uniform(0.98e-3, 1.0e-3, grains)


def rank_loads(
    centres: NDArray[np.float64],
    radii: NDArray[np.float64],
    nodes: NDArray[np.float64],
    ranks: int,
    margin: float,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
    """Per rank: owned nodes, ghost nodes, ranks it receives ghosts from."""
    partition = bisect(centres, nodes, ranks)
    needed = ghosts(partition, near_pairs(centres, radii, CUTOFF + margin))
    owned = partition.loads(nodes)
    ghost_nodes = np.array([nodes[g].sum() for g in needed])
    neighbours = np.array([len(np.unique(partition.owner[g])) for g in needed])
    return owned, ghost_nodes, neighbours


def step_model(
    owned: float, ghost: float, neighbours: int, ranks: int, arguments: argparse.Namespace
) -> dict[str, float]:
    """Seconds of each part of one step of a rank (see the module's docstring)."""
    compute = (owned + ghost) / arguments.rate
    return {
        "compute": compute,
        "check": CHECK_SHARE * compute,
        "exchange": 2 * neighbours * arguments.latency
        + 2 * BYTES_PER_GHOST_NODE * ghost / arguments.bandwidth,
        "reduction": 2 * arguments.latency * np.log2(max(ranks, 2)),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--nodes-per-rank", type=float, default=50_000)
    parser.add_argument("--rate", type=float, default=3.0e6, help="node-steps/s of one core")
    parser.add_argument("--latency", type=float, default=2e-6, help="s per message")
    parser.add_argument("--bandwidth", type=float, default=1e10, help="bytes/s")
    parser.add_argument(
        "--margin", type=float, default=1.0, help="ghost margin in largest grain radii"
    )
    arguments = parser.parse_args()
    total = 100_000
    centres, radii = packing(total)
    nodes = np.round(4 / 3 * np.pi * (radii / MESH_SIZE) ** 3)
    per_grain = float(nodes.mean())
    margin = arguments.margin * float(radii.max())
    print(
        f"packing of {total:,} grains, {per_grain:.0f} nodes per grain; "
        f"{arguments.nodes_per_rank:,.0f} nodes per rank; rate {arguments.rate / 1e6:.2f} M "
        f"node-steps/s; latency {arguments.latency * 1e6:.1f} us; bandwidth "
        f"{arguments.bandwidth / 1e9:.0f} GB/s; ghost margin {margin * 1e3:.2f} mm"
    )
    print(
        "| ranks | grains | ghost/owned nodes (max) | neighbours (max) | compute % | "
        "check % | exchange % | reduction % | efficiency | without stepping ghosts |"
    )
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    measured = None
    for ranks in (2, 4, 8, 16, 32, 64, 128, 256, 512, 1024):
        grains = round(ranks * arguments.nodes_per_rank / per_grain)
        if grains <= total:
            owned, ghost, neighbours = rank_loads(
                centres[:grains], radii[:grains], nodes[:grains], ranks, margin
            )
            slowest = int(np.argmax(owned + ghost))
            measured = (owned[slowest], ghost[slowest], int(neighbours.max()))
            label = f"{grains:,}"
        else:  # beyond the packing: the largest partition's interior rank, reused
            label = f"{grains:,} (model)"
        assert measured is not None
        own, ghost_count, neighbour_count = measured
        parts = step_model(own, ghost_count, neighbour_count, ranks, arguments)
        step = sum(parts.values())
        shares = " | ".join(f"{100 * parts[name] / step:.1f}" for name in parts)
        efficiency = own / arguments.rate / step
        lean = step_model(own, 0.0, neighbour_count, ranks, arguments)
        lean["exchange"] = parts["exchange"]
        print(
            f"| {ranks} | {label} | {ghost_count / own:.2f} | {neighbour_count} | {shares} | "
            f"{efficiency:.2f} | {own / arguments.rate / sum(lean.values()):.2f} |"
        )


if __name__ == "__main__":
    main()
