"""frames/frame_NNNNNN.vtu, the nodes with the chosen point fields, listed in simulation.pvd.

With Simulation.output(pieces=True) a frame is frames/frame_NNNNNN.pvtu instead, over pieces
frames/frame_NNNNNN/piece_R.vtu: one per rank of a distributed run, written by that rank, of
the nodes of the grains it owns (one piece of every node in a serial run). A piece's nodes
carry their numbers in the whole run (io.vtu.NODE_ID), and Particle_ID and Fragment_ID name
the whole run's particles and fragments, so the pieces joined are the one-file frame.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from granulate import resources
from granulate.errors import InputError
from granulate.io import write_vtu
from granulate.io.vtu import NODE_ID, write_pvtu

if TYPE_CHECKING:
    from granulate.simulation import Simulation
    from granulate.writers.outputs import Outputs
    from granulate.writers.step_data import StepData

#: The point fields a frame can hold (Simulation.output(fields=...)); all by default.
FIELDS = (
    "Displacement",
    "Velocity",
    "Force_Density",
    "Force",
    "Damage",
    "Damage_Z",
    "Dilatation",
    "Particle_ID",
    "Fragment_ID",
    "Fixity",
    "Nodal_Volume",
)
#: Each field's type and number of components, as a frame writes it.
FIELD_TYPES: dict[str, tuple[np.dtype[np.generic], int]] = {
    "Displacement": (np.dtype(np.float64), 3),
    "Velocity": (np.dtype(np.float64), 3),
    "Force_Density": (np.dtype(np.float64), 3),
    "Force": (np.dtype(np.float64), 3),
    "Damage": (np.dtype(np.float64), 1),
    "Damage_Z": (np.dtype(np.float64), 1),
    "Dilatation": (np.dtype(np.float64), 1),
    "Particle_ID": (np.dtype(np.uint32), 1),
    "Fragment_ID": (np.dtype(np.uint32), 1),
    "Fixity": (np.dtype(np.uint8), 1),
    "Nodal_Volume": (np.dtype(np.float64), 1),
}
#: A piece's node numbers in the whole run.
_NODE_ID_TYPE = np.dtype(np.int64)

#: A part's node and particle numbers in the whole run (a distributed run's rank holds a part).
Numbering = tuple[NDArray[np.int64], NDArray[np.int64]]


@dataclass(frozen=True)
class NodeRows:
    """Nodes' positions (n, 3) [m] and point fields (point_fields' arrays), in the order of
    `numbers`, their numbers in the whole run: a rank's rows of a frame, or, put together in
    node order (joined), the rows of a frame of every node."""

    numbers: NDArray[np.int64]
    positions: NDArray[np.float64]
    values: dict[str, NDArray[np.generic]]

    @staticmethod
    def joined(parts: list[NodeRows], node_count: int) -> NodeRows:
        """The rows of every node, in node order, from the parts that hold each once."""
        numbers = np.arange(node_count)
        positions = np.empty((node_count, 3))
        values = {
            name: np.empty((node_count, *field.shape[1:]), field.dtype)
            for name, field in parts[0].values.items()
        }
        for part in parts:
            positions[part.numbers] = part.positions
            for name, field in part.values.items():
                values[name][part.numbers] = field
        return NodeRows(numbers, positions, values)


def frame_bytes(nodes: int, fields: tuple[str, ...]) -> int:
    """A frame's rows of `nodes` nodes with `fields`: positions, the fields and the nodes'
    numbers [bytes]."""
    row = 3 * 8 + _NODE_ID_TYPE.itemsize
    row += sum(FIELD_TYPES[f][0].itemsize * FIELD_TYPES[f][1] for f in fields)
    return nodes * row


def require_room_for_frames(nodes: int, fields: tuple[str, ...]) -> None:
    """Rank 0 of a distributed run writing frames of every node in one file: InputError when
    the ranks' rows it receives and the frame it joins of them (frame_bytes, twice) would not
    fit in the memory free now."""
    resources.require_memory(
        2 * frame_bytes(nodes, fields),
        f"Rank 0's frames of all {nodes:,} nodes in one file",
        "write the frames in pieces, each rank its own nodes (the case's output: {pieces: "
        "true}; Simulation.output(pieces=True)), or fewer fields",
    )


def point_fields(
    sim: Simulation, fields: tuple[str, ...], numbering: Numbering | None = None
) -> dict[str, NDArray[np.generic]]:
    """The point fields `fields` of every node of `sim` (FIELD_TYPES), each made only when
    asked (the damage phi and PeriDEM's Z once, for both: Analysis.damage); `numbering`: how
    the whole run numbers the nodes and particles of `sim` when it is a part (Particle_ID and
    Fragment_ID are the whole run's)."""
    core, model = sim.core, sim.model
    volumes = model.volumes
    damage = functools.cache(sim.analysis.damage)

    def particles() -> NDArray[np.generic]:
        owner = np.asarray(model.node_particle)
        return owner if numbering is None else numbering[1][owner]

    def fragments() -> NDArray[np.generic]:
        labels = sim.analysis.fragment_labels()  # a piece's smallest node, of one particle
        return labels if numbering is None else numbering[0][labels]

    available: dict[str, Callable[[], NDArray[np.generic]]] = {
        "Displacement": lambda: sim.displacements,
        "Velocity": lambda: core.velocities,
        "Force_Density": lambda: core.forces,
        "Force": lambda: core.forces * volumes[:, None],
        "Damage": lambda: damage()[0],
        "Damage_Z": lambda: damage()[1],
        "Dilatation": lambda: core.dilatation,
        "Particle_ID": particles,
        "Fragment_ID": fragments,
        "Fixity": lambda: core.fixity(),
        "Nodal_Volume": lambda: volumes,
    }
    return {f: np.asarray(available[f](), dtype=FIELD_TYPES[f][0]) for f in fields}


def node_rows(
    sim: Simulation,
    fields: tuple[str, ...],
    nodes: NDArray[np.int64] | None = None,
    numbering: Numbering | None = None,
) -> NodeRows:
    """The rows of the nodes `nodes` of `sim` (all when None): their `fields` and their
    numbers in the whole run (`numbering`, for a part of a distributed run)."""
    values = point_fields(sim, fields, numbering)
    if nodes is None and numbering is None:  # every node, as they are
        return NodeRows(np.arange(sim.node_count), np.asarray(sim.core.positions), values)
    chosen = np.arange(sim.node_count) if nodes is None else nodes
    numbers = chosen if numbering is None else numbering[0][chosen]
    rows = {name: field[chosen] for name, field in values.items()}
    return NodeRows(numbers, sim.core.positions[chosen], rows)


def write_piece(
    path: Path,
    sim: Simulation,
    fields: tuple[str, ...],
    nodes: NDArray[np.int64] | None = None,
    numbering: Numbering | None = None,
) -> None:
    """One piece of a frame: node_rows(...) of those arguments, with the nodes' numbers."""
    rows = node_rows(sim, fields, nodes, numbering)
    write_piece_rows(path, rows.positions, rows.values, rows.numbers)


def write_piece_rows(
    path: Path,
    positions: NDArray[np.float64],
    rows: dict[str, NDArray[np.generic]],
    numbers: NDArray[np.int64],
) -> None:
    """A piece of a frame from its nodes' `positions`, their point fields `rows` (as
    point_fields makes them, in the order of the frame's fields) and their numbers in the
    whole run."""
    path.parent.mkdir(parents=True, exist_ok=True)
    write_vtu(path, positions, {**rows, NODE_ID: numbers.astype(_NODE_ID_TYPE)})


class VtuFrame:
    """The node frame: positions and the fields of ``Simulation.output(fields=...)``, in one
    file or in pieces (module docstring)."""

    # It reads StepData's values: in pieces, the ranks write theirs; a frame of every node,
    # the rows the ranks sent (StepData.frame_rows, Outputs.one_file_frame).
    needs_whole_state = False

    def write(self, data: StepData, outputs: Outputs) -> None:
        sim = data.simulation
        name = f"frame_{outputs.frames:06d}"
        frames = outputs.directory / "frames"
        if not outputs.pieces:  # a frame of every node: the ranks' rows, or the simulation's
            rows = data.frame_rows
            if rows is None:
                assert sim is not None
                rows = node_rows(sim, outputs.fields)
            write_vtu(frames / f"{name}.vtu", rows.positions, rows.values)
            outputs.pvd.add(data.time, Path("frames") / f"{name}.vtu")
            return
        if not outputs.piece_ranks:  # a serial run's one piece; else the ranks wrote theirs
            assert sim is not None
            write_piece(frames / name / "piece_0.vtu", sim, outputs.fields)
        count = outputs.piece_ranks or 1
        pieces = [f"piece_{r}.vtu" for r in range(count)]
        _check_pieces(frames / name, pieces)
        for stale in (frames / name).glob("piece_*.vtu"):  # of a run cut short on more ranks
            if stale.name not in pieces:
                stale.unlink()
        arrays = [(f, *FIELD_TYPES[f]) for f in outputs.fields] + [(NODE_ID, _NODE_ID_TYPE, 1)]
        write_pvtu(frames / f"{name}.pvtu", [f"{name}/{piece}" for piece in pieces], arrays)
        outputs.pvd.add(data.time, Path("frames") / f"{name}.pvtu")


def _check_pieces(folder: Path, pieces: list[str]) -> None:
    """InputError unless every rank's piece is in `folder` as this process sees it: the ranks
    of a distributed run on several machines must write into a file system they share."""
    missing = [name for name in pieces if not (folder / name).is_file()]
    if missing:
        raise InputError(
            f"{folder}: {', '.join(missing)} written by the other ranks cannot be seen here: "
            "the output directory must be on a file system every rank shares (on a cluster, "
            "not a node's local disk); choose one with --out"
        )
