"""The distributed benchmark: ``mpiexec -n K granulate bench --ranks [--case NAME] [--grains N]
[--steps S] [--collect-every N] [--load-balance KEY=VALUE,...] [--json]``, per rank its speed and
the shares of its time spent communicating (granulate.parallel; benchmarks/distributed.py runs
the same).

Cases:

======  ======================================================================================
pile3d  (default; 1,000 grains, 258,624 nodes) spheres and cubes of radius 0.98-1 mm (R/h = 4)
        on a cubic lattice 2 mm apart, 10 x 10 columns, on a floor, under gravity
pile    (400 grains) compression-like, at rest: discs and hexagons of radius 0.98-1 mm (R/h = 5)
        on a hexagonal lattice 2 mm apart, touching their neighbours, under gravity on a floor
        between two side walls
drum    (300 grains) drum-like, flowing: the same grains on a hexagonal lattice inside a drum
        turning at 20 rad/s, each thrown at 2 m/s in a random direction, so that the ranks
        migrate grains every few dozen steps
fine2d  (200 grains, 149,127 nodes) the pile at R/h = 16 (horizon three mesh sizes): grains of
        many nodes, of whose ghosts each step sends only the caps within reach
shatter (400 grains) fracture: the pile's grains, brittle (fracture energy 0.5 J/m^2), each
        thrown at 8 m/s in a random direction into its neighbours, so that they break from the
        first steps (the bonds broken in the timed steps are counted)
block   one body cut at node level (granulate.parallel.node_split): a notched LPS block of
        glass, 60 x 30 x 30 nodes (53,400; 14 x 7 x 7 with --quick), stretched along its length
        at 60/s from the start until it cracks; nothing touches. Per rank its own and halo
        nodes, its node-steps/s and the share of its time in the two halo exchanges (waits for
        the other ranks included; of that, waiting for the halo after the inner blocks'
        passes); --grains does not apply
======  ======================================================================================

Each rank runs one thread unless ``granulate --threads N`` says otherwise. After 20 untimed
steps (lists built, caches warm) the ranks' clocks start together and run the steps. Rank 0
prints a table: per rank the grains and nodes it owns at the end, its work then (nodes, bond
copies and contact list entries weighted: granulate/parallel/work_load.py), the ghost nodes it
holds besides and those it received a step on average (the caps), the surface normals it
received a step on average (of the caps' nodes within the normal reach), its owned node-steps
per second, and the shares of its wall-clock time spent in the ghost exchange (and of that,
waiting for the step's messages after the bond forces it evaluates while they travel: what the
overlap did not hide), in the checks (a reduction after each step, and one within each step
whose caps leave ghost nodes out), in picking the caps anew, in migrations and, with
``--collect-every N``, in making an output step every N steps: the step made of the ranks'
measures of their grains or nodes (DistributedRun.step_data, NodeSplitRun.step_data, as a run
with frames in pieces or no frames does at its output steps); nothing is written, and no row is
computed from it; then the migrations (and the steps the ranks rebalanced before, under
``--load-balance``'s settings, gr.LoadBalance.from_text, how many times the ranks compared their
work and the most loaded rank's over the mean at the last comparison) and grains handed over,
the ghost and cap margins and how often the caps were picked anew. With ``--json``, one JSON
object instead. On fewer cores than ranks (oversubscribed) the shares include waiting for the
other ranks and are an upper bound.
"""

from __future__ import annotations

import json
import time
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np

import granulate as gr
from granulate.errors import InputError

RADIUS = 1e-3
ROCK = gr.Material(
    density=1200, bulk_modulus=2.16e7, shear_modulus=1.296e7, fracture_energy=50, horizon=0.6e-3
)
SHARES = ("exchange", "check", "caps", "migrate", "collect")


def pile(
    grains: int, material: gr.Material = ROCK, mesh: float = RADIUS / 5, speed: float = 0.0
) -> gr.Simulation:
    """`grains` grains in rows of 20 on a hexagonal lattice, in a box open at the top, of
    `material` meshed at `mesh` [m], each thrown at `speed` [m/s] in a random direction."""
    rng = np.random.default_rng(3)
    throws = np.random.default_rng(7).uniform(0, 2 * np.pi, grains)
    spacing, columns = 2.0 * RADIUS, 20
    sim = gr.Simulation(2, gravity=(0, -9.81, 0))
    sim.contact = gr.Contact(restitution=0.5, friction=0.5)
    for k in range(grains):
        row, column = divmod(k, columns)
        centre = (spacing * (column + 0.5 * (row % 2)), spacing * np.sqrt(3) / 2 * row)
        radius = RADIUS * rng.uniform(0.98, 1.0)
        shape = (
            gr.RegularPolygon(centre, radius, 6, angle=0.3 * k)
            if k % 3 == 0
            else gr.Disc(centre, radius)
        )
        velocity = (speed * np.cos(throws[k]), speed * np.sin(throws[k]))
        sim.add_body(shape, material, mesh, velocity=velocity)
    width = spacing * (columns + 0.5)
    sim.add_wall(gr.Wall(gr.Plane((0, -0.99 * RADIUS, 0), (0, 1, 0))), name="floor")
    sim.add_wall(gr.Wall(gr.Plane((-0.99 * RADIUS, 0, 0), (1, 0, 0))), name="left")
    sim.add_wall(gr.Wall(gr.Plane((width - RADIUS, 0, 0), (-1, 0, 0))), name="right")
    return sim


def fine2d(grains: int) -> gr.Simulation:
    """The pile's layout at 16 nodes per radius (horizon three mesh sizes): grains of many
    nodes, whose ghosts' caps are a part of them."""
    h = RADIUS / 16
    fine_rock = gr.Material(
        density=1200, bulk_modulus=2.16e7, shear_modulus=1.296e7, fracture_energy=50, horizon=3 * h
    )
    return pile(grains, fine_rock, h)


def shatter(grains: int) -> gr.Simulation:
    """The pile's grains made brittle (fracture energy 0.5 J/m^2) and each thrown at 8 m/s in
    a random direction into its touching neighbours: they crack and split from the first
    steps, and their fragments' surfaces change where the contact sees them."""
    brittle = ROCK.model_copy(update={"fracture_energy": 0.5})
    return pile(grains, brittle, RADIUS / 5, speed=8.0)


def drum(grains: int) -> gr.Simulation:
    """`grains` grains on a hexagonal lattice inside a turning drum, thrown at 2 m/s."""
    rng = np.random.default_rng(5)
    spacing = 2.0 * RADIUS
    size = int(np.ceil(np.sqrt(grains / 0.9 * 2 / np.sqrt(3)))) + 2
    sites = [
        (
            spacing * (column + 0.5 * (row % 2) - size / 2),
            spacing * np.sqrt(3) / 2 * (row - size / 2),
        )
        for row in range(size)
        for column in range(size)
    ]
    sites.sort(key=lambda site: (np.hypot(*site), site))
    sim = gr.Simulation(2, gravity=(0, -9.81, 0))
    sim.contact = gr.Contact(restitution=0.5, friction=0.5)
    for k, centre in enumerate(sites[:grains]):
        radius = RADIUS * rng.uniform(0.98, 1.0)
        shape = (
            gr.RegularPolygon(centre, radius, 6, angle=0.3 * k)
            if k % 3 == 0
            else gr.Disc(centre, radius)
        )
        angle = rng.uniform(0, 2 * np.pi)
        velocity = (2.0 * np.cos(angle), 2.0 * np.sin(angle))
        sim.add_body(shape, ROCK, RADIUS / 5, velocity=velocity)
    reach = max(np.hypot(*site) for site in sites[:grains]) + 2 * RADIUS
    rotation = gr.Rotation.steady(20.0)
    sim.add_wall(gr.Wall(gr.CircleContainer((0, 0), reach), motion=rotation), name="drum")
    return sim


def pile3d(grains: int, comm: Any = None, placed: bool = False) -> gr.Simulation:
    """`grains` grains in 10 x 10 columns on a cubic lattice, on a floor (run on the ranks of
    `comm`, given one: Simulation's): every third a cube of half-side 0.8 r, the others
    spheres of radius r, r within 0.98-1 R, each meshed where it stands at R/4, or with
    `placed` placed from two reference shapes (a cube and a sphere of R, meshed at R/4) scaled
    to r, as packings place grains."""
    rng = np.random.default_rng(3)
    sim = gr.Simulation(3, gravity=(0, -9.81, 0), comm=comm)
    sim.contact = gr.Contact(restitution=0.5, friction=0.5)
    shapes = (gr.Box((-0.8 * RADIUS,) * 3, (0.8 * RADIUS,) * 3), gr.Sphere((0, 0, 0), RADIUS))
    references = [gr.ReferenceShape.from_shape(s, RADIUS / 4) for s in shapes] if placed else []
    for k in range(grains):
        layer, rest = divmod(k, 100)
        row, column = divmod(rest, 10)
        centre = (2 * RADIUS * column, 2 * RADIUS * layer, 2 * RADIUS * row)
        scale = rng.uniform(0.98, 1.0)
        radius = RADIUS * scale
        if placed:
            sim.add_particle(references[k % 3 != 0], ROCK, position=centre, scale=scale)
        elif k % 3 == 0:
            half = 0.8 * radius
            shape = gr.Box(tuple(c - half for c in centre), tuple(c + half for c in centre))
            sim.add_body(shape, ROCK, RADIUS / 4)
        else:
            sim.add_body(gr.Sphere(centre, radius), ROCK, RADIUS / 4)
    sim.add_wall(gr.Wall(gr.Plane((0, -0.99 * RADIUS, 0), (0, 1, 0))), name="floor")
    return sim


def block(quick: bool = False, comm: Any = None) -> gr.Simulation:
    """A notched glass block, 30 x 15 x 15 mm at h = 0.5 mm (7 x 3.5 x 3.5 mm with `quick`),
    each node starting at v_x = 60/s (x - c) (c its centre), its ends held at that speed: it
    deforms throughout and cracks from the notch within a hundred steps. No contact. `comm`:
    run it on those MPI ranks (Simulation's comm)."""
    glass = gr.Material(density=2500, youngs_modulus=70e9, poisson_ratio=0.22, fracture_energy=8.0)
    length = 7e-3 if quick else 0.03
    width = length / 2
    sim = gr.Simulation(dimension=3, comm=comm)
    notch = gr.Box((length / 2 - 0.3e-3, 2 / 3 * width, -1), (length / 2 + 0.3e-3, 1, 1))
    sim.add_body(gr.Difference(gr.Box((0, 0, 0), (length, width, width)), notch), glass, 0.5e-3)
    sim.contact = None
    start = np.asarray(sim.reference_positions)
    centre = 0.5 * length
    velocities = np.zeros_like(start)
    velocities[:, 0] = 60.0 * (start[:, 0] - centre)
    sim.start_from(start, velocities)
    for end in (gr.Box((-1, -1, -1), (1e-3, 1, 1)), gr.Box((length - 1e-3, -1, -1), (1, 1, 1))):
        nodes = sim.select(end)
        sim.prescribe_velocity(nodes, (60.0 * (start[nodes, 0].mean() - centre), 0.0, 0.0))
    return sim


#: Cases of one body cut at node level: name: set-up (quick or not).
SPLIT_CASES: dict[str, Callable[[bool], gr.Simulation]] = {"block": block}

#: name: (set-up, default grains, grains with --quick)
CASES: dict[str, tuple[Callable[[int], gr.Simulation], int, int]] = {
    "pile3d": (pile3d, 1000, 200),
    "pile": (pile, 400, 40),
    "drum": (drum, 300, 40),
    "fine2d": (fine2d, 200, 40),
    "shatter": (shatter, 400, 40),
}


def measure(
    case: str,
    grains: int | None,
    steps: int,
    collect_every: int,
    comm: Any,
    quick: bool = False,
    load_balance: gr.LoadBalance | None = None,
) -> dict[str, Any] | None:
    """Run `case` with `grains` grains (None: its default, or its quick size) for `steps` timed
    steps on the ranks of `comm`, gathering the whole state every `collect_every` steps (0:
    never), under `load_balance` (None: the simulation's default). On rank 0 the result (a
    dict, rows per rank); None on the others. Every rank calls it."""
    from granulate.parallel import DistributedRun

    if case in SPLIT_CASES:
        if load_balance is not None:
            raise InputError(
                f"bench --ranks: case {case!r} is one body cut at node level, whose nodes never "
                "change hands; --load-balance does not apply"
            )
        return measure_split(case, grains, steps, collect_every, comm, quick)
    if case not in CASES:
        names = ", ".join([*CASES, *SPLIT_CASES])
        raise InputError(f"unknown distributed benchmark case {case!r}; choose from {names}")
    if steps < 1 or collect_every < 0 or (grains is not None and grains < 1):
        raise InputError(
            "bench --ranks: --steps and --grains must be positive and --collect-every at least 0"
        )
    make, default, small = CASES[case]
    grains = grains or (small if quick else default)
    sim = make(grains)
    if load_balance is not None:
        sim.load_balance = load_balance
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="contact.*bodies pressed")  # placed pressed
        run = DistributedRun(sim, comm)
        run.run(20)  # lists built, caches warm
    migrations, handed, rebalanced = run.migrations, run.handed_over, len(run.rebalance_steps)
    checks = run.balance_checks
    refreshes, received, normals = run.cap_refreshes, run.nodes_received, run.normals_received
    broken = run.broken_bonds()
    wall = _timed(run, steps, collect_every, comm)
    broken = run.broken_bonds() - broken
    row = {
        "grains": len(run.owned),
        "nodes": run.owned_node_count,
        "work": run.owned_work(),
        "ghost_nodes": run.ghost_node_count,
        "exchanged_nodes": (run.nodes_received - received) / steps,
        "exchanged_normals": (run.normals_received - normals) / steps,
        "seconds": wall,
        "node_steps_per_s": run.owned_node_count * steps / wall,
        "wait_share": run.waiting / wall,
    } | {f"{name}_share": run.seconds[name] / wall for name in SHARES}
    rows = comm.gather(row, root=0)
    if rows is None:
        return None
    return {
        "case": case,
        "grains": grains,
        "steps": steps,
        "collect_every": collect_every,
        "ranks": comm.Get_size(),
        "threads": gr.get_num_threads(),
        "rows": rows,
        "migrations": run.migrations - migrations,
        "load_balance": sim.load_balance.as_text(),
        "rebalance_steps": run.rebalance_steps[rebalanced:],
        "balance_checks": run.balance_checks - checks,
        "work_imbalance": run.work_imbalance,
        "handed_over": run.handed_over - handed,
        "margin": run.margin,
        "margin_widenings": run.margin_widenings,
        "cap_margin": run.cap_margin,
        "cap_refreshes": run.cap_refreshes - refreshes,
        "cap_margin_widenings": run.cap_margin_widenings,
        "bonds_broken": broken,
    }


def measure_split(
    case: str, grains: int | None, steps: int, collect_every: int, comm: Any, quick: bool
) -> dict[str, Any] | None:
    """measure for a case of one body cut at node level (SPLIT_CASES; NodeSplitRun): per rank
    its own and halo nodes, node-steps/s and shares of its time exchanging and collecting."""
    from granulate.parallel import NodeSplitRun

    if grains is not None:
        raise InputError(f"bench --ranks: case {case!r} is one body; --grains does not apply")
    run = NodeSplitRun(SPLIT_CASES[case](quick), comm)
    run.run(1)  # caches warm
    broken = run.broken_bonds()
    wall = _timed(run, steps, collect_every, comm)
    row = {
        "nodes": len(run.own),
        "halo_nodes": run.halo_nodes,
        "seconds": wall,
        "node_steps_per_s": len(run.own) * steps / wall,
        "exchange_share": run.seconds["exchange"] / wall,
        "wait_share": run.waiting / wall,
        "collect_share": run.seconds["collect"] / wall,
    }
    rows = comm.gather(row, root=0)
    broken = run.broken_bonds() - broken
    if rows is None:
        return None
    return {
        "case": case,
        "steps": steps,
        "collect_every": collect_every,
        "ranks": comm.Get_size(),
        "threads": gr.get_num_threads(),
        "rows": rows,
        "bonds_broken": broken,
    }


def _timed(run: Any, steps: int, collect_every: int, comm: Any) -> float:
    """The wall-clock seconds of `steps` steps of `run` (a DistributedRun or NodeSplitRun),
    making an output step every `collect_every` (0: never; module docstring); its `seconds`
    and `waiting` count these steps alone."""
    every = collect_every or steps

    def output() -> None:
        run.step_data(())

    if collect_every:
        output()  # once untimed
    run.seconds = dict.fromkeys(run.seconds, 0.0)
    run.waiting = 0.0
    comm.Barrier()  # every rank's clock starts together
    start = time.perf_counter()
    for done in range(0, steps, every):
        run.run(min(every, steps - done))
        if collect_every:
            output()
    return time.perf_counter() - start


def table(result: dict[str, Any]) -> str:
    """The result of `measure` as a Markdown table with a heading and a closing line."""
    if result["case"] in SPLIT_CASES:
        return _split_table(result)
    lines = [
        f"{result['case']}: {result['grains']} grains, {result['steps']} steps, "
        f"{result['ranks']} ranks, {result['threads']} thread(s) each",
        "| rank | grains | nodes | work | ghost nodes | received a step | normals a step "
        "| node-steps/s | exchange % | waiting % | check % | caps % | migrate % | collect % |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for rank, row in enumerate(result["rows"]):
        shares = " | ".join(
            f"{100 * row[f'{name}_share']:.1f}" for name in (SHARES[0], "wait", *SHARES[1:])
        )
        lines.append(
            f"| {rank} | {row['grains']} | {row['nodes']:,} | {row['work']:,.0f} | "
            f"{row['ghost_nodes']:,} | "
            f"{row['exchanged_nodes']:,.0f} | {row['exchanged_normals']:,.0f} | "
            f"{row['node_steps_per_s'] / 1e6:.2f} M | {shares} |"
        )
    lines.append(
        f"{result['migrations']} migrations (for the balance before steps "
        f"{result['rebalance_steps']} under {result['load_balance']}: "
        f"{result['balance_checks']} checks, the most loaded rank "
        f"{result['work_imbalance']:.3f} times the mean at the last), "
        f"{result['handed_over']} grains handed over in the "
        f"timed steps; ghost margin {1e3 * result['margin']:.3g} mm (widened "
        f"{result['margin_widenings']} times); cap margin {1e3 * result['cap_margin']:.3g} mm ("
        f"widened {result['cap_margin_widenings']} times), caps picked anew "
        f"{result['cap_refreshes']} times; {result['bonds_broken']:,} bonds broken"
    )
    return "\n".join(lines)


def _split_table(result: dict[str, Any]) -> str:
    """The result of measure_split as a Markdown table with a heading and a closing line."""
    lines = [
        f"{result['case']}: one body cut at node level, {result['steps']} steps, "
        f"{result['ranks']} ranks, {result['threads']} thread(s) each",
        "| rank | nodes | halo nodes | node-steps/s | exchange % | waiting % | collect % |",
        "|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for rank, row in enumerate(result["rows"]):
        lines.append(
            f"| {rank} | {row['nodes']:,} | {row['halo_nodes']:,} | "
            f"{row['node_steps_per_s'] / 1e6:.2f} M | {100 * row['exchange_share']:.1f} | "
            f"{100 * row['wait_share']:.1f} | {100 * row['collect_share']:.1f} |"
        )
    lines.append(f"{result['bonds_broken']:,} bonds broken")
    return "\n".join(lines)


def main(
    comm: Any,
    case: str | None,
    grains: int | None,
    steps: int | None,
    collect_every: int,
    quick: bool,
    as_json: bool,
    load_balance: gr.LoadBalance | None = None,
) -> int:
    """`granulate bench --ranks`: measure and print on rank 0 (`steps` None: 300, or 20 with
    `quick`; `load_balance` None: the default)."""
    steps = steps if steps is not None else (20 if quick else 300)
    result = measure(case or "pile3d", grains, steps, collect_every, comm, quick, load_balance)
    if result is not None:
        print(json.dumps(result) if as_json else table(result), flush=True)
    return 0
