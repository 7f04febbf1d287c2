"""The Output and Restart blocks: frames and their fields, the tracked walls (with the loaded
wall's area of a compressive test), the max_node_dist stop, and a restart from a VTU frame."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from granulate.peridem.deck import Deck
from granulate.peridem.keys import OUTPUT_KEYS, TAGS, UNWRITTEN_TAGS
from granulate.peridem.loading import wall_ids
from granulate.peridem.problems import Problems

#: Folder names that say nothing about a deck (PeriDEM's examples keep decks in ``inp/``).
_GENERIC_FOLDERS = {"inp", "input", "inputs", "deck", "decks"}


def translate_output(d: Deck) -> None:
    """Output: intervals, fields, the stop criterion, tracked bodies and the output folder."""
    out = d.block("Output")
    d.problems.unknown("Output", out, OUTPUT_KEYS)
    every = out.get("Output_Interval", d.steps)
    if not (isinstance(every, int) and every > 0):
        d.problems.add(f"Output.Output_Interval: expected a positive integer, got {every!r}")
        every = d.steps
    d.every = every
    test_every = out.get("Test_Output_Interval") or max(1, every // 10)
    fields = _fields(d, out)
    d.stop = _stop(d, out, test_every)
    track, track_areas = _tracked(d)
    directory = default_output_directory(d.folder)
    if "Path" in out:
        d.notes.append(
            f"Output.Path {out['Path']!r} is PeriDEM's, relative to the deck's folder; the output "
            f"goes to {directory} in the working directory instead (choose with --out)"
        )
    d.output_spec = {
        "directory": directory,
        "every": every,
        "fields": fields,
        "history_every": test_every if track else every,
        "track": track,
        "track_areas": track_areas,
    }
    if out.get("Perform_Out", True) is False:
        d.output_spec = None
        d.notes.append("Output.Perform_Out is false: no output is written")


def _fields(d: Deck, out: dict[str, Any]) -> list[str]:
    """The frames' fields from Output.Tags (PeriDEM's tags granulate does not write noted)."""
    tags = out.get("Tags") or list(TAGS)
    fields = [TAGS[t] for t in tags if t in TAGS]
    unwritten = [t for t in tags if t not in TAGS]
    strange = [t for t in unwritten if t not in UNWRITTEN_TAGS]
    if strange:
        d.problems.add(
            f"Output.Tags: unknown tags {strange}; PeriDEM's are {[*TAGS, *UNWRITTEN_TAGS]}"
        )
    elif unwritten:
        d.notes.append(f"Output.Tags: {', '.join(unwritten)} are not written by granulate")
    if out.get("Perform_FE_Out"):
        d.notes.append(
            "Output.Perform_FE_Out: granulate writes the nodes as points, not the mesh cells"
        )
    return fields


def _stop(d: Deck, out: dict[str, Any], test_every: int) -> dict[str, Any] | None:
    """Output_Criteria max_node_dist as the node_distance stop criterion."""
    criteria = d.block("Output_Criteria", "Output", out)
    if not criteria:
        return None
    if criteria.get("Type") == "max_node_dist":
        distance = d.problems.numbers(
            criteria.get("Parameters"), "Output.Output_Criteria.Parameters"
        )
        return {"node_distance": distance[0], "check_every": test_every} if distance else None
    d.problems.add(
        f"Output.Output_Criteria.Type: {criteria.get('Type')!r}; granulate reads max_node_dist"
    )
    return None


def _tracked(d: Deck) -> tuple[list[str], dict[str, float]]:
    """The bodies history.csv tracks (walls; every particle of a two-particle test; the
    compressive test's loaded particle) and the loaded wall's area, when it is known."""
    track = [f"p{k}" for k, z in enumerate(d.zone_of) if z in d.walls]
    if "two_particle" in d.test:
        track = [f"p{k}" for k in range(len(d.zone_of))]
    compressive = d.particle_block.get("Compressive_Test") or {}
    wall_id = compressive.get("Particle_Id")
    if "Wall_Id" in compressive:
        by_wall = wall_ids(d, [compressive["Wall_Id"]], "Particle.Compressive_Test.Wall_Id")
        wall_id = by_wall[0] if by_wall else None
    if wall_id is not None and f"p{wall_id}" in d.named and f"p{wall_id}" not in track:
        track.append(f"p{wall_id}")
    track_areas = {}
    if wall_id is not None and f"p{wall_id}" in track:
        zone = d.zone_of[wall_id]
        area = _loaded_area(compressive, d.zone_extent.get(zone), d.dimension, d.problems)
        if area is None and zone not in d.zone_extent:
            d.notes.append(
                f"Compressive_Test: p{wall_id} is placed from the particle file; its area is not "
                "known here, so history.csv records its force, not its stress"
            )
        if area is not None:
            track_areas[f"p{wall_id}"] = area
            d.notes.append(
                f"Compressive_Test: history.csv records p{wall_id}_stress, the force on the "
                f"loaded wall over its extent across the loading direction ({area:.6g} "
                f"{'m' if d.dimension == 2 else 'm^2'}); PeriDEM reports the force alone"
            )
    return track, track_areas


def _loaded_area(
    compressive: dict[str, Any], extent: np.ndarray | None, dimension: int, problems: Problems
) -> float | None:
    """The compressive test's wall area across its force direction (1-based, Particle_ or
    Wall_Force_Direction): the product of the wall's extents along the other axes [m^2; m in
    2D]; None for a wall not placed as meshed (its extent is not known here)."""
    key = (
        "Wall_Force_Direction"
        if "Wall_Force_Direction" in compressive
        else "Particle_Force_Direction"
    )
    if key not in compressive:
        return None
    direction = compressive[key]
    if (
        not isinstance(direction, int)
        or isinstance(direction, bool)
        or not 1 <= direction <= dimension
    ):
        problems.add(
            f"Particle.Compressive_Test.{key}: a direction 1 to {dimension}, got {direction!r}"
        )
        return None
    if extent is None:
        return None
    area = float(np.prod(np.delete(extent[:dimension], direction - 1)))
    return area if area > 0 else None


def default_output_directory(folder: Path) -> str:
    """Where a deck's run writes, relative to the working directory: out/<the deck's folder
    name> (its parent's name when the folder is a generic inp/ or input/)."""
    resolved = folder.resolve()
    name = resolved.name
    if name.lower() in _GENERIC_FOLDERS and resolved.parent.name:
        name = resolved.parent.name
    return f"out/{name or 'deck'}"


def translate_restart(d: Deck) -> None:
    """Restart {File, Step}: positions and velocities from a VTU frame, bonds intact."""
    restart = d.block("Restart")
    if not restart:
        return
    d.problems.unknown("Restart", restart, {"File", "Step"})
    step = restart.get("Step")
    if not isinstance(restart.get("File"), str) or not (isinstance(step, int) and step >= 0):
        d.problems.add("Restart: give File (a VTU output of the run) and Step (its step)")
        return
    d.restart_spec = {"file": d.file_ref(restart["File"]), "step": step}
    d.notes.append(
        f"Restart: positions and velocities from {restart['File']} at step {step}; bonds "
        "start intact, as in PeriDEM (granulate's checkpoints keep them: --resume)"
    )
