"""The Particle_Generation block: particles p<i> (PeriDEM's global ids) placed from the
particle-location CSV, zone by zone, and the zones placed once as meshed."""

from __future__ import annotations

from typing import Any

import numpy as np

from granulate.errors import InputError
from granulate.peridem.deck import Deck


def translate_particles(d: Deck) -> None:
    """Particle_Generation: the CSV's rows as particles; every zone's particles named in order."""
    generation = d.block("Particle_Generation")
    d.problems.unknown("Particle_Generation", generation, {"From_File", "File_Data_Type"})
    placed_zones = [z for z in d.zones if z not in d.geometry_particle]
    rows, rotations = _read_rows(d, generation, placed_zones) if placed_zones else (None, None)
    for z in d.zones:
        _zone_particles(d, z, rows, rotations)
    if rows is not None:
        unknown = sorted({int(v) + 1 for v in rows[:, 0]} - set(placed_zones))
        if unknown:
            d.problems.add(
                f"Particle_Generation.From_File: rows name zone ids {[u - 1 for u in unknown]} "
                "(0-based) that are not particle zones"
            )


def _read_rows(
    d: Deck, generation: dict[str, Any], placed_zones: list[int]
) -> tuple[np.ndarray | None, Any]:
    """The CSV's rows [zone - 1, x, y, z, r] and the particles' rotations; (None, None) if
    there is none to read."""
    csv_name = generation.get("From_File")
    if not csv_name:
        d.problems.add(
            f"Particle_Generation.From_File: zones {placed_zones} are placed from a "
            "particle-location CSV; name it"
        )
        return None, None
    from granulate.packing import read_placements

    rows: np.ndarray | None = None
    rotations: Any = None
    try:
        placements = read_placements(d.folder / str(csv_name), dimension=d.dimension, seed=d.seed)
        rows = np.column_stack([placements.kinds, placements.positions, placements.radii])
        rotations = placements.rotations
    except InputError as error:
        d.problems.add(f"Particle_Generation.From_File: {error}")
    kind = generation.get("File_Data_Type", "loc_rad")
    if kind not in ("loc_rad", "loc_rad_orient"):
        d.problems.add(
            f"Particle_Generation.File_Data_Type: {kind!r}; expected loc_rad or loc_rad_orient"
        )
    elif rows is not None and kind == "loc_rad":
        two_particles = "two_particle" in d.test
        d.notes.append(
            "loc_rad: random orientations from granulate's generator (seed "
            f"{d.seed}); PeriDEM draws other ones"
            + (", and turns particle i of a two-particle test by i pi" if two_particles else "")
        )
        if two_particles:
            rotations = np.pi * np.arange(len(rows))
    return rows, rotations


def _zone_particles(d: Deck, z: int, rows: np.ndarray | None, rotations: Any) -> None:
    """Zone z's particles, named p<i> in turn: its built body, its one particle placed as
    meshed, or its rows of the CSV."""
    name = f"zone_{z}"
    bodies = d.deck_bodies
    if z in bodies:
        bodies[z]["name"] = f"p{len(d.zone_of)}"
        d.zone_of.append(z)
        return
    if name not in d.grains:
        return
    if z in d.geometry_particle:
        position = [0.0] * d.dimension
        d.particles.append({"name": f"p{len(d.zone_of)}", "grain": name, "position": position})
        d.zone_of.append(z)
        return
    if rows is None:
        return
    for k in np.flatnonzero(rows[:, 0] == z - 1):
        rotation = rotations[k]
        d.particles.append(
            {
                "name": f"p{len(d.zone_of)}",
                "grain": name,
                "position": [float(v) for v in rows[k, 1 : 1 + d.dimension]],
                "scale": float(rows[k, 4] / d.zone_radius[z]),
                "rotation": float(rotation) if d.dimension == 2 else [float(v) for v in rotation],
            }
        )
        d.zone_of.append(z)
