"""The Contact block (a law per pair of zones: Rc, kn, e, mu, Copy_Contact_Data links followed)
and the Neighbor block (noted, not read)."""

from __future__ import annotations

import math
from typing import Any

from granulate.peridem.deck import Deck
from granulate.peridem.keys import CONTACT_KEYS


def translate_contact(d: Deck) -> None:
    """Contact: one contact_pairs entry per pair of zones (none between two walls)."""
    contact_block = d.block("Contact")
    if d.single or not contact_block:
        if not d.single and len(d.zone_of) > 1:
            d.problems.add("Contact: missing; give Contact.Zone_<a><b> for every pair of zones")
        return
    keys = {f"Zone_{a}{b}": (a, b) for a in d.zones for b in d.zones if a <= b}
    d.problems.unknown("Contact", contact_block, set(keys))

    def pair_key(other: Any) -> str | None:
        if not (isinstance(other, list) and len(other) == 2):
            return None
        key = f"Zone_{min(other)}{max(other)}"
        return key if key in keys else None

    h_min = _smallest_spacing(d)
    used = {"friction": False, "damping": False}
    for key, (a, b) in keys.items():
        materials = [f"zone_{a}", f"zone_{b}"]
        if a in d.walls and b in d.walls:
            d.pairs.append({"materials": materials, "contact": None})
            continue
        info = d.problems.copied(
            contact_block,
            key,
            "Copy_Contact_Data",
            pair_key,
            "Contact",
            f"zones {a} and {b} may touch",
        )
        if info:
            _pair(d, f"Contact.{key}", info, materials, h_min, used)
    _contact_notes(d, h_min, used)


def _smallest_spacing(d: Deck) -> float:
    """The smallest node spacing over all particles (zone mesh size x particle scale) [m]."""
    scales = {entry["name"]: entry.get("scale", 1.0) for entry in d.particles}
    return min(
        (d.zone_mesh_size[z] * scales.get(f"p{k}", 1.0) for k, z in enumerate(d.zone_of)),
        default=math.inf,
    )


def _pair(
    d: Deck,
    where: str,
    info: dict[str, Any],
    materials: list[str],
    h_min: float,
    used: dict[str, bool],
) -> None:
    """One pair's law, appended to d.pairs (no contact for Kn = 0); `used` notes damping and
    friction."""
    problems = d.problems
    problems.unknown(where, info, CONTACT_KEYS)
    spec: dict[str, Any] = {}
    if "Contact_Radius" in info:
        spec["contact_radius"] = problems.number(
            info["Contact_Radius"], f"{where}.Contact_Radius", positive=True
        )
    else:
        factor = problems.number(
            info.get("Contact_Radius_Factor", 0.95), f"{where}.Contact_Radius_Factor", positive=True
        )
        spec["contact_radius"] = factor * h_min
    kn_factor = problems.number(info.get("Kn_Factor", 1.0), f"{where}.Kn_Factor")
    if "Kn" in info:
        kn = problems.number(info["Kn"], f"{where}.Kn") * kn_factor
        if kn == 0:
            d.pairs.append({"materials": materials, "contact": None})
            return
        if kn < 0:
            problems.add(f"{where}.Kn: must not be negative, got {info['Kn']}")
            return
        spec["normal_stiffness"] = kn
    else:
        spec["stiffness_factor"] = kn_factor
        d.notes.append(
            f"{where}: no Kn, granulate's default kn (see granulate.contact) x Kn_Factor"
        )
    if not _damping(d, where, info, materials, spec, used):
        return
    if info.get("Friction_On", True):
        spec["friction"] = problems.number(
            info.get("Friction_Coeff", 0.0), f"{where}.Friction_Coeff"
        )
        used["friction"] = used["friction"] or spec["friction"] > 0
        if d.compat:
            spec["friction_law"] = "peridem"
    if d.compat:  # one Rc per particle pair, springs kn V_i V_j
        spec["pair_law"] = "peridem"
    d.pairs.append({"materials": materials, "contact": spec})


def _damping(
    d: Deck,
    where: str,
    info: dict[str, Any],
    materials: list[str],
    spec: dict[str, Any],
    used: dict[str, bool],
) -> bool:
    """The pair's restitution (or, with --peridem-compat, PeriDEM's centre damping); False for
    an Epsilon out of range (reported)."""
    beta_factor = d.problems.number(info.get("Beta_n_Factor", 1.0), f"{where}.Beta_n_Factor")
    if not (info.get("Damping_On", True) and beta_factor > 1e-8):
        spec["restitution"] = 1.0
        return True
    epsilon = d.problems.number(info.get("Epsilon", 1.0), f"{where}.Epsilon")
    if not 0 < epsilon <= 1:
        d.problems.add(f"{where}.Epsilon: must be in (0, 1], got {epsilon}")
        return False
    used["damping"] = used["damping"] or epsilon < 1
    if d.compat:  # PeriDEM's centre damping instead of granulate's dashpot
        spec["restitution"] = 1.0
        d.peridem_pairs.append(
            {"materials": list(materials), "epsilon": epsilon, "beta_factor": beta_factor}
        )
    else:
        spec["restitution"] = epsilon
    return True


def _contact_notes(d: Deck, h_min: float, used: dict[str, bool]) -> None:
    """What granulate's contact does differently from PeriDEM's, said once."""
    d.notes.append(
        f"contact radius: Contact_Radius_Factor x the smallest node spacing of all particles "
        f"({h_min:.6g} m)"
    )
    if not d.compat:
        d.notes.append(
            "contact surface: a mesh vertex on a particle's surface has its contact sphere "
            "centred Rc/2 inside it, so particles touch where their meshes' surfaces meet "
            "(PeriDEM centres it on the vertex, so its particles touch Rc apart; "
            "--peridem-compat does too)"
        )
    if used["damping"]:
        d.notes.append(
            "contact damping: --peridem-compat: PeriDEM's particle-centre damping "
            "(Epsilon, Beta_n_Factor), which does not give the restitution Epsilon names"
            if d.compat
            else "contact damping: granulate's dashpot gives the restitution Epsilon asks "
            "for; PeriDEM's particle-centre damping (Beta_n_Factor) does not "
            "(--peridem-compat reproduces it)"
        )
    if used["friction"]:
        d.notes.append(
            "friction: "
            + (
                "--peridem-compat: PeriDEM's sign (friction speeds sliding up)"
                if d.compat
                else "Coulomb friction opposes sliding (PeriDEM's has the wrong sign and "
                "speeds sliding up; --peridem-compat reproduces it)"
            )
        )
    d.notes.append(
        "fragments of one particle are bodies in contact after it breaks (PeriDEM repels "
        "only the node pairs whose bond broke, and lets other nodes of its fragments pass "
        "through each other)"
    )
    if d.walls:
        d.notes.append(
            "walls are particles with every node constrained; the force on them is the "
            "reaction of the grains (history.csv <name>_fx, _fy). PeriDEM computes no "
            "contact force on wall nodes, so the force it reports on a wall is its weight"
        )


def translate_neighbor(d: Deck) -> None:
    """Neighbor: granulate's lists rebuild by displacement, so its keys are checked and noted."""
    neighbor = d.block("Neighbor")
    d.problems.unknown(
        "Neighbor", neighbor, {"Search_Factor", "Search_Interval", "Update_Criteria"}
    )
    if neighbor:
        d.notes.append(
            "Neighbor: not read; granulate rebuilds its contact lists whenever a node has moved "
            "half the skin, so no contact is missed (PeriDEM's fixed Search_Interval can miss some)"
        )
