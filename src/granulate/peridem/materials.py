"""The Material block: one granulate material zone_<k> per zone (Copy_Material_Data links
followed), and the 2D constants (plane strain, or PeriDEM's 3D ones with --peridem-compat)."""

from __future__ import annotations

from typing import Any

from granulate.peridem.deck import Deck
from granulate.peridem.keys import MATERIAL_KEYS
from granulate.peridem.problems import Problems

#: PeriDEM's material types -> granulate's model (and whether bonds break).
_MODELS = {"PDState": ("lps", True), "PMBBond": ("pmb", True), "PDElasticBond": ("pmb", False)}
_ELASTIC = (
    ("E", "youngs_modulus"),
    ("K", "bulk_modulus"),
    ("G", "shear_modulus"),
    ("Poisson_Ratio", "poisson_ratio"),
)
_INFLUENCE = {0: "constant", 1: "linear", 2: "gaussian"}


def translate_materials(d: Deck) -> None:
    """Material: one spec per zone; the notes on breaking in compression and the 2D constants."""
    for z in d.zones:
        info = d.problems.copied(
            d.material_block,
            f"Zone_{z}",
            "Copy_Material_Data",
            lambda other: f"Zone_{other}" if other in d.zones else None,
            "Material",
            "every zone needs a material",
        )
        if info:
            spec = _material(d, f"Material.Zone_{z}", info)
            if spec is not None:
                d.materials[f"zone_{z}"] = spec
    if not d.compat:
        d.notes.append(
            "bonds break in tension only (s > s0); PeriDEM also breaks them in compression "
            "(|s| > s0); --peridem-compat does too"
        )
    if d.dimension == 2:
        if d.compat:
            d.plane = "peridem"
            d.notes.append(
                "--peridem-compat: 2D LPS with PeriDEM's 3D constants (theta = 3/m sum, K, 15 G, "
                "3D critical stretch)"
            )
        else:
            d.notes.append(
                "2D LPS uses the plane-strain constants (K + G/3, 8 G, the 2D critical stretch); "
                "PeriDEM uses the 3D ones in 2D, which gives other moduli and fracture energy "
                "(--peridem-compat reproduces them)"
            )


def _material(d: Deck, where: str, info: dict[str, Any]) -> dict[str, Any] | None:
    """The granulate material spec of one zone's block; None if it cannot be made."""
    problems = d.problems
    problems.unknown(where, info, MATERIAL_KEYS)
    kind = info.get("Type", "PDState")
    if not (isinstance(kind, str) and kind in _MODELS):
        problems.add(
            f"{where}.Type: {kind!r} is not supported; granulate has PDState (LPS), "
            "PMBBond and PDElasticBond"
        )
        return None
    model, fracture = _MODELS[kind]
    spec: dict[str, Any] = {"model": model} if fracture else {"model": model, "fracture": False}
    if not info.get("Compute_From_Classical", True):
        problems.add(
            f"{where}.Compute_From_Classical: false (peridynamic constants given directly) "
            "is not supported; give two of E, K, G, Poisson_Ratio and Gc or KIc"
        )
        return None
    spec["density"] = problems.number(info.get("Density"), f"{where}.Density", positive=True)
    if "Horizon" in info:
        spec["horizon"] = problems.number(info["Horizon"], f"{where}.Horizon", positive=True)
    elif "Horizon_Mesh_Ratio" in info:
        spec["horizon_factor"] = problems.number(
            info["Horizon_Mesh_Ratio"], f"{where}.Horizon_Mesh_Ratio", positive=True
        )
    else:
        problems.add(f"{where}: give Horizon [m] or Horizon_Mesh_Ratio")
    for key, ours in _ELASTIC:
        if key in info and problems.number(info[key], f"{where}.{key}") > 0:
            spec[ours] = float(info[key])
    if spec.get("fracture", True):
        _fracture_energy(d, where, info, spec)
    influence = problems.block(info, "Influence_Function", where).get("Type", 0)
    if influence not in _INFLUENCE:
        problems.add(f"{where}.Influence_Function.Type: expected 0, 1 or 2, got {influence!r}")
    else:
        spec["influence"] = _INFLUENCE[influence]
    if d.compat:
        spec["break_in_compression"] = True
    return spec


def _fracture_energy(d: Deck, where: str, info: dict[str, Any], spec: dict[str, Any]) -> None:
    """Gc, or KIc^2 / E as PeriDEM derives it."""
    problems = d.problems
    if "Gc" in info and problems.number(info["Gc"], f"{where}.Gc") > 0:
        spec["fracture_energy"] = problems.number(info["Gc"], f"{where}.Gc")
    elif "KIc" in info:
        e = _youngs(spec, where, problems)
        kic = problems.number(info["KIc"], f"{where}.KIc", positive=True)
        if e is not None:
            spec["fracture_energy"] = kic * kic / e
            d.notes.append(f"{where}: Gc = KIc^2 / E = {kic * kic / e:.6g} J/m^2 (PeriDEM's)")
    else:
        problems.add(f"{where}: give Gc or KIc")


def _youngs(spec: dict[str, Any], where: str, problems: Problems) -> float | None:
    """E [Pa] from the two elastic constants of a material spec (granulate.Material derives
    them); None with a problem reported when they are missing or inconsistent."""
    from pydantic import ValidationError

    from granulate.materials import Material

    constants = ("youngs_modulus", "bulk_modulus", "shear_modulus", "poisson_ratio")
    try:
        material = Material(
            density=1.0, fracture=False, **{n: spec[n] for n in constants if n in spec}
        )
        K, G = material.elastic_moduli()
    except (ValidationError, ValueError):
        problems.add(f"{where}: KIc needs two consistent elastic constants to give Gc")
        return None
    return 9 * K * G / (3 * K + G)
