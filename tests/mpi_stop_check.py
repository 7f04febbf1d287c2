"""Run under `mpiexec -n K python tests/mpi_stop_check.py ENGINE STEPS` (tests/test_mpi.py
does): the stop criteria's measures of a distributed run (parallel/run_measures.py) against
the serial run's, bit for bit, and runs that stop on them at the serial run's step.

ENGINE `grains` is the tumbling drum with a grid-meshed brittle grain (tests/assemblies.py,
whole grains per rank); `split` the notched plate pulled apart (tests/assemblies.py, its
one body cut at node level). Rank 0 prints one line per part and the exit status is non-zero
on any difference:
- measures: every 100 steps, the ranks' kinetic energy, farthest node, broken bonds, particles
  that lost every bond and wall displacement, then the same with every bond of the first and
  third bodies broken by hand (the counts of a body cut among ranks included), against the
  serial simulation's;
- stops: Simulation(comm=...).run with a stop criterion whose threshold lies one float past the
  serial run's value at a check (so a value one bit off stops elsewhere), for each criterion
  in turn: the reason and step, and how many times the ranks sent rank 0 their state (once,
  at the end: the checks gather nothing); and a criterion of a user's own reading the
  simulation's velocities (LargestSpeedAt), whose every check gathers it;
- outputs (`grains` only): the drum with frames in pieces and a tracked grain, every 100 steps:
  every file but the frames' pieces and run.json as the serial run's (history.csv but its
  list searches), the state gathered once (at the end: each output step is made of the
  ranks' measures, parallel/step_parts.py); and again with a history section of a user's own
  that reads the simulation's velocities (LargestSpeed), whose every output step gathers it;
  and run with gather=False, which never gathers it, nor checks rank 0's memory for it (the
  check made to fail): rank 0's simulation refuses to give the nodes after, and
  sim.measures() gives the serial run's kinetic energy and broken bonds.
"""

from __future__ import annotations

import shutil
import sys
import tempfile
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from mpi4py import MPI

sys.path.insert(0, str(Path(__file__).parent))
import granulate as gr
from assemblies import pulled, tumbling_drum
from granulate import core_model
from granulate.parallel import DistributedRun
from granulate.parallel.node_split import NodeSplitRun
from granulate.writers import registry
from granulate.writers.step_data import StepData
from rank_zero import on_rank_0, wait_asleep
from run_folders import SEARCHES, history, outputs

CHECK_EVERY = 100
MEASURES = (
    "kinetic_energy",
    "farthest_node_distance",
    "broken_bonds",
    "fully_broken_particles",
)


def set_up(engine: str, comm: MPI.Comm | None = None) -> gr.Simulation:
    """The engine's case, with no outputs, on the ranks of `comm` when given."""
    if engine == "grains":
        return tumbling_drum(Path("unused"), grid=True, comm=comm, outputs=False)
    return pulled("plate", "lps", comm)


def values(measured: gr.stopping.RunMeasures, wall: str | None) -> tuple[float, ...]:
    """Every measure the criteria read, in MEASURES order, then the wall's displacement."""
    row = [float(getattr(measured, name)()) for name in MEASURES]
    return (*row, measured.wall_displacement(wall) if wall else 0.0)


def check_measures(engine: str, steps: int, comm: MPI.Comm) -> tuple[bool, list[tuple[float, ...]]]:
    """The ranks' measures every CHECK_EVERY steps and after breaking bodies 0 and 2 by hand,
    against the serial run's; rank 0 prints them. Whether they agree, and the serial run's
    at each check (rank 0's; none elsewhere)."""
    wall = "drum" if engine == "grains" else None
    chosen = [0, 2] if engine == "grains" else [0]
    expected = on_rank_0(comm, lambda: serial_measures(engine, steps, wall, chosen))
    engines = {"grains": DistributedRun, "split": NodeSplitRun}
    run = engines[engine](set_up(engine), comm)
    held = run.held if isinstance(run, DistributedRun) else np.arange(len(run.local.bodies))
    mine = []
    for _ in range(steps // CHECK_EVERY):
        run.run(CHECK_EVERY)
        mine.append(values(run.measures(), wall))
    _break(run.local, [np.flatnonzero(held == b) for b in chosen])
    mine.append(values(run.measures(), wall))
    if expected is None:
        return True, []
    rows = list(zip(mine, expected, strict=True))
    same = all(a == b for a, b in rows)
    print(
        f"measures {engine} on {comm.Get_size()} ranks: equal {same}; at the end "
        f"{dict(zip(MEASURES, rows[-2][0], strict=False))}; "
        f"{rows[-1][0][3]:.0f} particles fully broken by hand (serially {rows[-1][1][3]:.0f})"
    )
    return same, [row[1] for row in rows[:-1]]


def serial_measures(
    engine: str, steps: int, wall: str | None, chosen: list[int]
) -> list[tuple[float, ...]]:
    """The serial run's measures every CHECK_EVERY steps, then after breaking bodies `chosen`
    by hand."""
    serial = set_up(engine)
    rows = []
    for _ in range(steps // CHECK_EVERY):
        serial.core.run(CHECK_EVERY)
        rows.append(values(serial, wall))
    _break(serial, [np.array([b]) for b in chosen])
    return [*rows, values(serial, wall)]


def _break(sim: gr.Simulation, bodies: list[np.ndarray]) -> None:
    """Every bond copy of the nodes of the local `bodies` of `sim` broken."""
    core, offsets = sim.core, np.asarray(sim.model.bond_offsets)
    intact = np.asarray(core.bond_intact).copy()
    for body in np.concatenate(bodies).astype(int):
        nodes = sim.bodies[body].node_slice
        intact[offsets[nodes.start] : offsets[nodes.stop]] = 0
    core.assign_bonds(intact)


def check_stops(engine: str, steps: int, seen: list[tuple[float, ...]], comm: MPI.Comm) -> bool:
    """For each criterion, its threshold one float past the serial run's value at a check:
    the run on the ranks stops where the serial run does, with its reason, gathering the
    state on rank 0 once (at the end)."""
    thresholds = comm.bcast(_thresholds(seen) if comm.Get_rank() == 0 else None, root=0)
    owner = DistributedRun if engine == "grains" else NodeSplitRun
    same = True
    for criterion in thresholds:
        expected = on_rank_0(comm, lambda: serial_stop(engine, steps, criterion))  # noqa: B023
        with counting(owner) as gathered:
            sim = set_up(engine, comm)
            got = (sim.run(steps, stop=[criterion], check_every=CHECK_EVERY), sim.step)
        if expected is not None:
            print(
                f"stop {engine} on {comm.Get_size()} ranks, {criterion}: {got} "
                f"(serially {expected}), the state gathered {gathered[0]} times"
            )
            checks = got[1] // CHECK_EVERY  # a criterion of one's own gathers at each, and the end
            once = checks + 1 if criterion.needs_whole_state else 1
            same = same and got == expected and got[0] is not None and gathered[0] == once
    return same


@dataclass(frozen=True)
class LargestSpeedAt(gr.stopping.StopCriterion):
    """A stop criterion of a user's own: at `step`, stop and give the largest node speed read
    from the simulation's velocities (so a distributed run gathers the whole state for it)."""

    step: int

    def check(self, run: gr.stopping.RunMeasures) -> str | None:
        sim = run
        assert isinstance(sim, gr.Simulation)
        if sim.step < self.step:
            return None
        speed = float(np.linalg.norm(sim.velocities, axis=1).max())
        return f"largest speed {speed!r} m/s at step {sim.step}"


@contextmanager
def counting(owner: type[DistributedRun] | type[NodeSplitRun]) -> Iterator[list[int]]:
    """[how many times] the ranks sent rank 0 their whole state (owner.collect) within."""
    collect, gathered = owner.collect, [0]

    def counted(run: DistributedRun | NodeSplitRun, measures: bool = True) -> None:
        gathered[0] += 1
        collect(run, measures)  # type: ignore[arg-type]

    owner.collect = counted  # type: ignore[method-assign]
    try:
        yield gathered
    finally:
        owner.collect = collect  # type: ignore[method-assign]


@contextmanager
def no_room_on_root(comm: MPI.Comm, active: bool) -> Iterator[None]:
    """Within, when `active`: rank 0's memory check of the whole model always fails, as for a
    model larger than its memory (a run that never gathers the state does not need it)."""
    check = core_model.require_memory_for

    def full(*_: object) -> None:
        raise gr.InputError("the model would need about 9 TB of memory")

    if active and comm.Get_rank() == 0:
        core_model.require_memory_for = full
    try:
        yield
    finally:
        core_model.require_memory_for = check


class LargestSpeed:
    """A history section of a user's own: it reads the simulation's node velocities, so a
    distributed run gathers the whole state on rank 0 for every output step."""

    def columns(self, data: StepData, outputs: object) -> dict[str, float | int]:
        assert data.simulation is not None
        speeds = np.linalg.norm(data.simulation.velocities, axis=1)
        return {"largest_speed": float(speeds.max())}


def check_outputs(
    steps: int, comm: MPI.Comm, own_section: bool = False, gather: bool = True
) -> bool:
    """The drum's outputs in pieces on the ranks against the serial run's (the module
    docstring), with LargestSpeed registered when `own_section`, run with `gather`; rank 0
    prints what differs."""
    root = Path(comm.bcast(tempfile.mkdtemp() if comm.Get_rank() == 0 else None, root=0))
    sections = list(registry.HISTORY_SECTIONS)
    if own_section:
        registry.register_history_section(LargestSpeed())
    made: dict[str, gr.Simulation] = {}
    with counting(DistributedRun) as gathered, no_room_on_root(comm, not gather):
        for name, ranks in (("serial", None), ("ranks", comm)):
            if ranks is None and comm.Get_rank() != 0:
                continue
            if ranks is not None:
                wait_asleep(comm)  # while rank 0 runs serially
            sim = made[name] = set_up("grains", ranks)
            sim.output(root / name, every=CHECK_EVERY, pieces=True, track=[sim.bodies[3]])
            sim.run(steps, gather=gather)
            gathered[0] = 0 if ranks is None else gathered[0]
    registry.HISTORY_SECTIONS[:] = sections
    after = None if gather else without_gathering(made["ranks"], made.get("serial"))
    if comm.Get_rank() != 0:
        return True
    found = {name: outputs(root / name) for name in ("serial", "ranks")}
    kept = {
        name: {k: v for k, v in files.items() if "/frame_" not in k}
        for name, files in found.items()
    }
    differ = sorted(
        k
        for k in kept["serial"].keys() | kept["ranks"].keys()
        if kept["serial"].get(k) != kept["ranks"].get(k)
    )
    rows = [history(root / name) for name in ("serial", "ranks")]
    for row in (*rows[0], *rows[1]):
        del row[SEARCHES]
    shutil.rmtree(root)
    kind = "with a section of its own" if own_section else "grains"
    kind += "" if gather else " without gathering"
    print(
        f"outputs {kind} on {comm.Get_size()} ranks: {len(kept['serial'])} files but frames, "
        f"differing {differ}; history equal but list searches {rows[0] == rows[1]} "
        f"({len(rows[0])} rows, {len(rows[0][0])} columns); the state gathered {gathered[0]} "
        f"times{'' if after is None else '; ' + after}"
    )
    once_each = len(rows[0]) + 1 if own_section else int(gather)  # every output step, the end
    ok_after = after is None or after.endswith("measured as serially True")
    return not differ and rows[0] == rows[1] and gathered[0] == once_each and ok_after


def without_gathering(sim: gr.Simulation, serial: gr.Simulation | None) -> str | None:
    """After sim.run(..., gather=False) on every rank: on rank 0, what its simulation says
    when asked for the nodes (it holds no state of the run), and whether sim.measures()
    (every rank together) gives the serial run's kinetic energy and broken bonds."""
    measured = sim.measures()
    values = (measured.kinetic_energy(), measured.broken_bonds())
    if serial is None:
        return None
    try:
        np.asarray(sim.positions)
        refused = "rank 0 gave positions"
    except gr.InputError as error:
        refused = str(error)
    same = values == (serial.kinetic_energy(), serial.broken_bonds())
    built = sim._core is not None
    return f"rank 0: {refused!r}, built {built}; measured as serially {same and not built}"


def serial_stop(engine: str, steps: int, criterion: Any) -> tuple[Any, int]:
    """The serial run stopped by `criterion`: its reason and step."""
    serial = set_up(engine)
    return serial.run(steps, stop=[criterion], check_every=CHECK_EVERY), serial.step


def _thresholds(seen: list[tuple[float, ...]]) -> list[gr.stopping.StopCriterion]:
    """Criteria met first at a check of the serial run whose measures at each check were
    `seen`: each threshold one float past the value there."""
    energy = _new_extreme([-row[0] for row in seen])
    farthest = _new_extreme([row[1] for row in seen])
    broken = _new_extreme([row[2] for row in seen])
    return [
        gr.stopping.KineticEnergyBelow(float(np.nextafter(-energy, np.inf))),
        gr.stopping.NodeDistance(float(np.nextafter(farthest, -np.inf))),
        gr.stopping.BrokenBonds(int(broken)),
        LargestSpeedAt(3 * CHECK_EVERY),
    ]


def _new_extreme(row: list[float]) -> float:
    """Of the values above every one before them, the one nearest the middle of `row`."""
    news = [k for k, value in enumerate(row) if all(value > before for before in row[:k])]
    return row[min(news, key=lambda k: abs(k - len(row) // 2))]


def main() -> int:
    warnings.filterwarnings("ignore", message="contact.*bodies pressed")
    engine, steps = sys.argv[1], int(sys.argv[2])
    comm = MPI.COMM_WORLD
    measured, seen = check_measures(engine, steps, comm)
    stopped = check_stops(engine, steps, seen, comm)
    written = engine != "grains" or (
        check_outputs(steps, comm)
        and check_outputs(steps, comm, own_section=True)
        and check_outputs(steps, comm, gather=False)
    )
    return 0 if comm.bcast(measured and stopped and written, root=0) else 1


if __name__ == "__main__":
    code = main()
    wait_asleep(MPI.COMM_WORLD)  # while rank 0 compares
    sys.exit(code)
