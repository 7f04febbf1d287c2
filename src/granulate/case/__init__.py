"""YAML case files: a whole simulation described as data, mapping one-to-one onto the Python API.

    granulate check case.yaml          # validate and summarise
    granulate run case.yaml            # run it
    granulate schema                   # the reference of every key (units included)

A case is validated up front (pydantic): an error names the key path, what was expected, what
was found, and for a misspelt key the closest valid one. File paths (meshes, STL surfaces,
placement CSVs) are relative to the case file's folder. SI units throughout. Example::

    dimension: 2
    materials:
      rock: {density: 2600, youngs_modulus: 5.0e+9, poisson_ratio: 0.25, fracture_energy: 20}
    grains:
      pebble: {shape: {type: disc, radius: 1.0e-3}, material: rock, mesh_size: 2.0e-4,
               sizes: {distribution: uniform, low: 0.8e-3, high: 1.2e-3}}
    packings:
      - {container: {type: rectangle, lower: [0, 0], upper: [0.02, 0.02]}, grains: [pebble],
         count: 40, seed: 1}
    walls:
      - {name: box, surfaces: [{type: container, shape: {type: rectangle, lower: [0, 0],
                                                         upper: [0.02, 0.02]}}]}
    gravity: [0, -9.81]
    contact: {restitution: 0.5, friction: 0.4}
    time: {end: 0.01}
    output: {directory: out/pile, every: 500}

The package's rooms: the schema (spec_types.py, the base and number types; shape_specs.py;
particle_specs.py: time functions, sizes, grains, bodies, particles, packings; run_specs.py:
contact, walls, loading, time, output, stop and CaseSpec), the builder (builder.py: Case,
CaseContext), the schema's documentation (documentation.py) and, here, reading a file. Error
messages for invalid input are formatted by granulate.input_errors.
"""

from __future__ import annotations

from pathlib import Path

from pydantic import ValidationError

from granulate.case.builder import Case, CaseContext
from granulate.case.documentation import ALL_SPECS, reference, schema
from granulate.case.run_specs import CaseSpec
from granulate.errors import InputError
from granulate.input_errors import describe
from granulate.io.files import read_text
from granulate.yaml_input import load_yaml

__all__ = ["Case", "CaseContext", "CaseSpec", "load_case", "parse_case", "reference", "schema"]


def load_case(path: str | Path, *, peridem_compat: bool = False) -> Case:
    """Read and validate a YAML case file (InputError with every problem found). A PeriDEM
    input deck is recognised and translated (granulate.peridem); ``peridem_compat`` selects
    PeriDEM's formulas where granulate has them. It is refused for a native case."""
    source = Path(path)
    text = read_text(source, "case file")
    data = load_yaml(text, source)
    from granulate import peridem

    if peridem.is_deck(data):
        translation = peridem.translate(source, compat=peridem_compat)
        case = parse_case(peridem.to_yaml(translation, peridem_compat), source)
        case.text = text + "\n---\n" + case.text
        case.notes = translation.notes
        return case
    if peridem_compat:
        raise InputError(
            f"{source} is a granulate case, not a PeriDEM deck: --peridem-compat applies to "
            "decks (a case sets plane: peridem and friction_law: peridem itself)"
        )
    return parse_case(text, source)


def parse_case(text: str, source: Path = Path("case.yaml")) -> Case:
    data = load_yaml(text, source)
    if not isinstance(data, dict):
        raise InputError(
            f"{source}: a case file is a mapping of keys (dimension, materials, ...), got "
            f"{type(data).__name__}"
        )
    try:
        spec = CaseSpec.model_validate(data)
    except ValidationError as error:
        raise InputError(f"{source}: " + describe(error, data, ALL_SPECS)) from None
    return Case(spec, source.resolve(), text)
