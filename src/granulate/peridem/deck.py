"""What the block translators of a PeriDEM deck share: the deck, its folder, the problem
collector and the notes, and what each block found for the blocks after it."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from granulate.peridem.problems import Problems


@dataclass
class Deck:
    """A deck being translated. The translators (granulate.peridem.BLOCKS) fill the fields of
    their block in deck order; `case_data` assembles the native case from them."""

    data: dict[str, Any]
    source: Path
    compat: bool
    #: The folder the case's file paths are made relative to (the deck's folder if None).
    output: Path | None
    problems: Problems
    notes: list[str] = field(default_factory=list)
    # Model
    dimension: int = 2
    final_time: float = math.nan
    steps: int = 1
    single: bool = False  #: Particle_Sim_Type: Single_Particle
    seed: Any = 1
    # Zone, Particle, Mesh, Wall
    zones: list[int] = field(default_factory=list)
    particle_block: dict[str, Any] = field(default_factory=dict)
    material_block: dict[str, Any] = field(default_factory=dict)
    test: str = ""  #: Particle.Test_Name
    walls: set[int] = field(default_factory=set)
    geometry_particle: set[int] = field(default_factory=set)  #: zones placed as meshed
    constrained: set[int] = field(default_factory=set)  #: zones with every node fixed
    zone_extent: dict[int, np.ndarray] = field(default_factory=dict)  #: of a zone placed once [m]
    zone_mesh_size: dict[int, float] = field(default_factory=dict)
    zone_radius: dict[int, float] = field(default_factory=dict)  #: reference radius [m]
    bodies: list[dict[str, Any]] = field(default_factory=list)  #: {zone, body} of built meshes
    grains: dict[str, Any] = field(default_factory=dict)
    # Material
    materials: dict[str, Any] = field(default_factory=dict)
    plane: str = "strain"
    # Particle_Generation
    particles: list[dict[str, Any]] = field(default_factory=list)
    zone_of: list[int] = field(default_factory=list)  #: each particle p<i>'s zone
    # Contact
    pairs: list[dict[str, Any]] = field(default_factory=list)
    peridem_pairs: list[dict[str, Any]] = field(default_factory=list)
    # Displacement_BC, Force_BC, IC
    loading: list[dict[str, Any]] = field(default_factory=list)
    gravity: list[float] | None = None
    # Output, Restart
    every: int = 1  #: Output_Interval
    output_spec: dict[str, Any] | None = None
    stop: dict[str, Any] | None = None
    restart_spec: dict[str, Any] | None = None

    @property
    def folder(self) -> Path:
        return self.source.parent

    def file_ref(self, name: str) -> str:
        """A file beside the deck, as the case names it."""
        return os.path.relpath(self.folder / name, (self.output or self.folder).resolve())

    def block(self, key: str, where: str = "deck", parent: dict[str, Any] | None = None):
        """The block `key` of `parent` (the deck's top level by default)."""
        return self.problems.block(self.data if parent is None else parent, key, where)

    @property
    def deck_bodies(self) -> dict[int, dict[str, Any]]:
        """The bodies of PeriDEM's built-in meshes by zone (the entries of `bodies`)."""
        return {b["zone"]: b["body"] for b in self.bodies}

    @property
    def numbered(self) -> bool:
        """Every zone has its particles (a zone whose mesh failed has none, so later ids do
        not resolve: consequences of a reported problem, not problems of their own)."""
        bodies = self.deck_bodies
        return all(f"zone_{z}" in self.grains or z in bodies for z in self.zones)

    @property
    def named(self) -> set[str]:
        """The particle names p<i>."""
        return {f"p{k}" for k in range(len(self.zone_of))}

    @property
    def wall_particles(self) -> list[int]:
        """The walls' particle ids, by wall number (the older format's Wall_List, Wall_Id:
        0, 1, ... in zone order)."""
        return [k for k, z in enumerate(self.zone_of) if z in self.walls]
