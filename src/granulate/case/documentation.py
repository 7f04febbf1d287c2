"""The case-file schema as JSON Schema (for editors) and as a readable reference."""

from __future__ import annotations

import json
from typing import Any

from pydantic import BaseModel

from granulate.case import particle_specs, run_specs, shape_specs
from granulate.case.run_specs import CaseSpec
from granulate.case.spec_types import Spec
from granulate.materials import Material

#: Every section's spec class, in the order the modules define them, and Material (for the
#: closest-key suggestions of input_errors.describe).
ALL_SPECS: list[type[BaseModel]] = [
    m
    for module in (shape_specs, particle_specs, run_specs)
    for name, m in vars(module).items()
    if isinstance(m, type)
    and issubclass(m, Spec)
    and m.__module__ == module.__name__
    and not name.startswith("_")
] + [Material]


def schema() -> dict[str, Any]:
    """The JSON Schema of case files (for editors)."""
    return CaseSpec.model_json_schema()


def reference() -> str:
    """A readable reference of every key, with types, defaults and units."""
    out = ["granulate case file reference (SI units)", ""]
    document = schema()
    definitions = document.get("$defs", {})

    def describe_type(prop: dict[str, Any]) -> str:
        if "$ref" in prop:
            return prop["$ref"].split("/")[-1].removesuffix("Spec")
        if "anyOf" in prop:
            return " | ".join(describe_type(p) for p in prop["anyOf"])
        if "oneOf" in prop:
            return " | ".join(describe_type(p) for p in prop["oneOf"])
        if "enum" in prop:
            return " | ".join(map(repr, prop["enum"]))
        if "const" in prop:
            return repr(prop["const"])
        if prop.get("type") == "array":
            return f"list of {describe_type(prop.get('items', {}))}"
        if prop.get("type") == "object" and "additionalProperties" in prop:
            return f"mapping of name -> {describe_type(prop['additionalProperties'])}"
        return str(prop.get("type", "any"))

    def section(name: str, body: dict[str, Any]) -> None:
        out.append(
            f"{name}:"
            + (f"  {body['description'].splitlines()[0]}" if body.get("description") else "")
        )
        required = set(body.get("required", []))
        for key, prop in body.get("properties", {}).items():
            line = f"  {key}: {describe_type(prop)}"
            if key in required:
                line += " (required)"
            elif "default" in prop:
                line += f" = {json.dumps(prop['default'])}"
            if prop.get("description"):
                line += f"  -- {prop['description']}"
            out.append(line)
        out.append("")

    section("case", document)
    for name, body in definitions.items():
        section(name.removesuffix("Spec"), body)
    return "\n".join(out)
