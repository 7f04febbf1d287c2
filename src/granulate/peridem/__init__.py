"""PeriDEM input decks: recognise one, translate it into a granulate case, report what differs.

A PeriDEM deck is a YAML file (``Model``, ``Zone``, ``Particle``, ``Particle_Generation``,
``Mesh``, ``Material``, ``Contact``, ``Neighbor``, ``Force_BC``, ``Displacement_BC``, ``IC``,
``Output``, ``Restart``) with gmsh meshes and a particle-location CSV beside it; file paths are
relative to the deck's folder. ``translate`` turns it into the data of a native case file (the
schema of granulate.case), so a deck runs through exactly the code path of a case file and
``granulate convert`` can write that case out:

- a zone becomes a grain (its mesh, centred on the zone's geometry centre, reference radius
  ``Parameters[0]``) and a material ``zone_<k>``; particles are placed from the CSV (scale
  r / Parameters[0], rotation o about z) and named ``p<i>`` with PeriDEM's global particle id i
  (zone by zone, CSV row order within a zone; a wall zone is one particle);
- walls are particles with every node constrained, as in PeriDEM; PeriDEM's older deck format
  (its paper's decks) says the same with a wall zone (``Zone.Zone_k.Is_Wall`` with ``Type`` and
  ``Parameters``) meshed by a ``Wall.Zone_k`` block, ``Displacement_BC`` sets that select walls by
  ``Wall_List`` (walls numbered 0, 1, ... in zone order) and ``Compressive_Test.Wall_Id``;
- contact is set per zone pair: Rc = Contact_Radius, or Contact_Radius_Factor x the smallest
  node spacing over all particles; kn = Kn x Kn_Factor; e = Epsilon when Damping_On; mu =
  Friction_Coeff when Friction_On; no contact between two walls (PeriDEM skips wall pairs);
- displacement sets, force sets, gravity and initial velocities become loading entries;
- Restart {File, Step} starts from a VTU frame's displacements and velocities (bonds intact);
- Output_Interval sets the frames; the walls (and the particles of a two-particle test) are
  tracked in history.csv every Test_Output_Interval steps (the compressive-test report: the
  force on each wall against its displacement).

Where PeriDEM's physics is a known defect, the translation runs granulate's physics and says so
in ``Translation.notes``; ``compat=True`` (``--peridem-compat``) reproduces PeriDEM's formulas
where granulate has them: the 3D LPS constants in 2D, bonds that also break in compression,
PeriDEM's friction sign and PeriDEM's particle-centre damping (contact/peridem_damping.hpp).
Keys granulate cannot honour stop the translation with one InputError listing them all; keys
PeriDEM itself ignores are listed in the notes.

The translation is a table of block translators (BLOCKS), one module per block family, run in
deck order on one shared Deck (deck.py) that collects every problem (problems.py) and the
notes; adding a key touches the translator of its block:

- zones.py: Model; Zone, Particle, Mesh and the older format's Wall;
- materials.py: Material;
- particles.py: Particle_Generation;
- contact_pairs.py: Contact, Neighbor;
- loading.py: Displacement_BC, Force_BC, IC;
- output.py: Output, Restart;
- keys.py: the keys each block may hold, and the output tags.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from granulate.errors import InputError
from granulate.io.files import read_text
from granulate.peridem.contact_pairs import translate_contact, translate_neighbor
from granulate.peridem.deck import Deck
from granulate.peridem.keys import IGNORED_SECTIONS, SECTIONS
from granulate.peridem.loading import (
    translate_displacements,
    translate_forces,
    translate_initial_velocities,
)
from granulate.peridem.materials import translate_materials
from granulate.peridem.output import default_output_directory, translate_output, translate_restart
from granulate.peridem.particles import translate_particles
from granulate.peridem.problems import Problems
from granulate.peridem.zones import smallest_spacing, translate_model, translate_zones
from granulate.yaml_input import load_yaml

__all__ = [
    "BLOCKS",
    "Translation",
    "default_output_directory",
    "is_deck",
    "read_deck",
    "smallest_spacing",
    "to_yaml",
    "translate",
]


@dataclass
class Translation:
    """A deck translated: the native case data, and what the log must say once."""

    case: dict[str, Any]
    source: Path
    notes: list[str] = field(default_factory=list)


def is_deck(data: Any) -> bool:
    """Whether parsed YAML is a PeriDEM deck (capitalised sections, a ``Model`` block) rather
    than a granulate case."""
    return isinstance(data, dict) and "Model" in data and "dimension" not in data


def read_deck(path: str | Path) -> dict[str, Any]:
    source = Path(path)
    data = load_yaml(read_text(source, "deck"), source)
    if not is_deck(data):
        raise InputError(f"{source} is not a PeriDEM deck (it has no Model block)")
    return data


def _sections(d: Deck) -> None:
    """The deck's top-level keys: unknown ones reported, ignored ones noted."""
    d.problems.unknown("deck", d.data, set(SECTIONS) | set(IGNORED_SECTIONS))
    for key in IGNORED_SECTIONS:
        if key in d.data:
            d.notes.append(f"{key}: not read (PeriDEM does not use it to run either)")


#: The block translators, in the order they run (each reads what the ones before found).
BLOCKS: tuple[tuple[str, Callable[[Deck], None]], ...] = (
    ("sections", _sections),
    ("Model", translate_model),
    ("Zone, Particle, Mesh, Wall", translate_zones),
    ("Material", translate_materials),
    ("Particle_Generation", translate_particles),
    ("Contact", translate_contact),
    ("Neighbor", translate_neighbor),
    ("Displacement_BC", translate_displacements),
    ("Force_BC", translate_forces),
    ("IC", translate_initial_velocities),
    ("Output", translate_output),
    ("Restart", translate_restart),
)


def translate(path: str | Path, *, compat: bool = False, output: Path | None = None) -> Translation:
    """Translate the deck at ``path`` (InputError listing every problem). ``compat``: PeriDEM's
    formulas where granulate has them. ``output``: the folder file paths of the case are made
    relative to (default: the deck's folder)."""
    try:
        return _translate(Path(path), compat, output)
    except InputError:
        raise  # already says what is wrong (InputError is a ValueError too)
    except (AttributeError, TypeError, ValueError, KeyError, IndexError) as error:
        # A value of a kind no check above expected (a list where a block belongs, ...).
        raise InputError(
            f"{path}: a deck value has an unexpected kind ({type(error).__name__}: {error}); "
            "check the deck against PeriDEM's keys (granulate's docs: PeriDEM input decks)"
        ) from None


def _translate(path: Path, compat: bool, output: Path | None) -> Translation:
    source = path.resolve()
    d = Deck(read_deck(source), source, compat, output, Problems(source))
    for _block, translator in BLOCKS:
        translator(d)
    d.problems.raise_if_any()
    return Translation(_case_data(d), source, d.notes)


def _case_data(d: Deck) -> dict[str, Any]:
    """The native case the translated blocks describe."""
    case: dict[str, Any] = {
        "dimension": d.dimension,
        "plane": d.plane,
        "materials": d.materials,
        "grains": d.grains,
    }
    if d.bodies:
        case["bodies"] = [b["body"] for b in d.bodies]
    if d.particles:
        case["particles"] = d.particles
    case["contact"] = None  # every pair of zones is set; a deck has no default contact
    if d.pairs:
        case["contact_pairs"] = d.pairs
    if d.peridem_pairs:
        case["peridem_damping"] = {
            "pairs": d.peridem_pairs,
            "walls": [f"p{k}" for k, z in enumerate(d.zone_of) if z in d.walls],
        }
    if d.loading:
        case["loading"] = d.loading
    if d.gravity is not None and any(d.gravity):
        case["gravity"] = d.gravity
    case["time"] = _time(d)
    if d.output_spec is not None:
        case["output"] = d.output_spec
    if d.stop is not None:
        case["stop"] = d.stop
    if d.restart_spec is not None:
        case["restart"] = d.restart_spec
    return case


def _time(d: Deck) -> dict[str, Any]:
    """Model's time: dt = Final_Time / Time_Steps, unless the steps are fewer than one output
    interval (PeriDEM's paper decks say Time_Steps: 1): then to Final_Time at granulate's dt."""
    if d.steps < d.every:
        d.notes.append(
            f"Model.Time_Steps: {d.steps} is fewer than Output.Output_Interval ({d.every}), "
            "which no run means (PeriDEM's paper decks carry this slip): granulate runs to "
            "Final_Time at its default time step; the output intervals count its steps"
        )
        return {"end": d.final_time}
    return {"dt": d.final_time / d.steps, "steps": d.steps}


def to_yaml(translation: Translation, compat: bool) -> str:
    """The translated case as a commented YAML case file."""
    header = [
        f"# granulate case converted from the PeriDEM deck {translation.source}",
        f"# (granulate convert{' --peridem-compat' if compat else ''}). Particles p<i> carry",
        "# PeriDEM's global particle ids; file paths are relative to this file, output.directory",
        "# to the working directory of the run. What differs from PeriDEM:",
    ]
    header += [f"#   - {n}" for n in translation.notes]
    body = yaml.safe_dump(translation.case, sort_keys=False, default_flow_style=None, width=100)
    return "\n".join(header) + "\n" + body
