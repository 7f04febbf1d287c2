"""The Displacement_BC, Force_BC and IC blocks: their Set_k blocks as loading entries (node
selections by particle, wall and region; time functions), gravity and initial velocities."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

from granulate.peridem.deck import Deck
from granulate.peridem.keys import SET_KEYS
from granulate.peridem.problems import Problems

#: A checked Set_k block: where it is, the block, its node selection (None: not usable) and its
#: directions 1..dimension.
BcSet = tuple[str, dict[str, Any], dict[str, Any] | None, list[int]]


def translate_displacements(d: Deck) -> None:
    """Displacement_BC: fixed, rotated and displaced sets; then the constrained zones' fixes
    along the directions no set moves."""
    moved: dict[str, set[int]] = {}
    for where, info, nodes, dirs in _bc_sets(
        d, "Displacement_BC", d.block("Displacement_BC"), set()
    ):
        if nodes is None or not dirs:
            continue
        for body in nodes.get("body", []):
            if "region" not in nodes:
                moved.setdefault(body, set()).update(dirs)
        entry = _displacement_entry(d, where, info, nodes, dirs)
        if entry is not None:
            d.loading.append(entry)
    for index, z in enumerate(d.zone_of):
        if z in d.constrained:
            free = set(range(1, d.dimension + 1)) - moved.get(f"p{index}", set())
            if free:
                d.loading.append(
                    {
                        "type": "fix",
                        "nodes": {"body": f"p{index}"},
                        "components": "".join("xyz"[k - 1] for k in sorted(free)),
                    }
                )


def _displacement_entry(
    d: Deck, where: str, info: dict[str, Any], nodes: dict[str, Any], dirs: list[int]
) -> dict[str, Any] | None:
    """One displacement set as a fix, rotation or displacement entry (None: reported)."""
    axes = "".join("xyz"[k - 1] for k in dirs)
    function = info.get("Time_Function")
    spatial = d.block("Spatial_Function", where, info).get("Type", "constant")
    if info.get("Zero_Displacement", False):
        return {"type": "fix", "nodes": nodes, "components": axes}
    if isinstance(function, dict) and function.get("Type") == "rotation":
        p = d.problems.numbers(function.get("Parameters", []), f"{where}.Time_Function.Parameters")
        if len(p) < 3:
            d.problems.add(f"{where}.Time_Function: rotation takes [omega, x0, y0, z0]")
            return None
        return {
            "type": "rotation",
            "nodes": nodes,
            "center": (p[1:4] + [0.0] * 3)[:3],
            "angle": {"type": "linear", "rate": p[0]},
        }
    if spatial != "constant":
        d.problems.add(
            f"{where}.Spatial_Function: {spatial!r}; displacement sets take a constant "
            "spatial function (or rotation with a rotation time function)"
        )
        return None
    fn = _time_function(function, f"{where}.Time_Function", d.problems)
    if fn is None:
        return None
    direction = [1.0 if k + 1 in dirs else 0.0 for k in range(d.dimension)]
    return {
        "type": "displacement",
        "nodes": nodes,
        "direction": direction,
        "function": fn,
        "components": axes,
    }


def translate_forces(d: Deck) -> None:
    """Force_BC: gravity, and force densities g(t) along each set's directions."""
    force_bc = d.block("Force_BC")
    if force_bc.get("Gravity") is not None:
        g = d.problems.numbers(force_bc["Gravity"], "Force_BC.Gravity")
        d.gravity = g[: d.dimension] if len(g) >= d.dimension else None
        if d.gravity is None:
            d.problems.add(f"Force_BC.Gravity: expected {d.dimension} or 3 components")
    for where, info, nodes, dirs in _bc_sets(d, "Force_BC", force_bc, {"Gravity"}):
        spatial = d.block("Spatial_Function", where, info).get("Type", "constant")
        if spatial != "constant":
            d.problems.add(
                f"{where}.Spatial_Function: {spatial!r} force densities are not supported "
                "(constant only)"
            )
            continue
        fn = _time_function(
            info.get("Time_Function"), f"{where}.Time_Function", d.problems, force=True
        )
        if nodes is None or not dirs or fn is None:
            continue
        # f = g(t) along each listed direction: the function carries the magnitude.
        vector = [1.0 if k + 1 in dirs else 0.0 for k in range(d.dimension)]
        d.loading.append(
            {"type": "force_density", "nodes": nodes, "vector": vector, "function": fn}
        )


def translate_initial_velocities(d: Deck) -> None:
    """IC.Constant_Velocity: the listed particles' (or built bodies') initial velocity."""
    ic = d.block("IC")
    d.problems.unknown("IC", ic, {"Constant_Velocity"})
    if "Constant_Velocity" not in ic:
        return
    info = d.block("Constant_Velocity", "IC", ic)
    d.problems.unknown("IC.Constant_Velocity", info, {"Velocity_Vector", "Particle_List"})
    v = d.problems.numbers(info.get("Velocity_Vector"), "IC.Constant_Velocity.Velocity_Vector")
    for i in info.get("Particle_List", []) or []:
        target = next((p for p in d.particles if p["name"] == f"p{i}"), None)
        body = next((b for b in d.deck_bodies.values() if b["name"] == f"p{i}"), None)
        if target is None and body is None:
            if d.numbered:
                d.problems.add(f"IC.Constant_Velocity.Particle_List: no particle {i}")
        else:
            (target or body)["velocity"] = v[: d.dimension]  # type: ignore[index]


def wall_ids(d: Deck, value: Any, where: str) -> list[int] | None:
    """Walls by number (0, 1, ... in zone order) as particle ids; None (reported) if any
    number names no wall."""
    walls = d.wall_particles
    if not isinstance(value, list) or any(
        not isinstance(w, int) or not 0 <= w < len(walls) for w in value
    ):
        d.problems.add(
            f"{where}: {value!r} names walls that do not exist (walls are numbered 0 .. "
            f"{len(walls) - 1} in zone order)"
        )
        return None
    return [walls[w] for w in value]


def _bc_sets(d: Deck, name: str, block: dict[str, Any], other_keys: set[str]) -> Iterator[BcSet]:
    """The Set_k blocks of a Displacement_BC or Force_BC block, checked."""
    count = block.get("Sets", 0) or 0
    d.problems.unknown(
        name, block, other_keys | {"Sets"} | {f"Set_{s}" for s in range(1, count + 1)}
    )
    for s in range(1, count + 1):
        where = f"{name}.Set_{s}"
        info = d.block(f"Set_{s}", name, block)
        d.problems.unknown(where, info, SET_KEYS)
        yield where, info, _select(d, info, where), _directions(d, info, where)


def _select(d: Deck, info: dict[str, Any], where: str) -> dict[str, Any] | None:
    """A set's node selection (bodies, excluded bodies, region); None if it selects nothing
    usable (reported, unless it follows from an earlier problem)."""
    out: dict[str, Any] = {}
    ids = info.get("Particle_List")
    if "Wall_List" in info:
        by_wall = wall_ids(d, info["Wall_List"], f"{where}.Wall_List")
        if by_wall is None:
            return None
        ids = [*(ids if isinstance(ids, list) else []), *by_wall]
    named = d.named
    if ids is not None:
        if not isinstance(ids, list) or any(f"p{i}" not in named for i in ids):
            if d.numbered or not isinstance(ids, list):
                d.problems.add(
                    f"{where}.Particle_List: {ids!r} names particles that do not exist (ids "
                    f"are 0-based, 0 .. {len(d.zone_of) - 1})"
                )
            return None
        out["body"] = [f"p{i}" for i in ids]
    excluded = info.get("Particle_Exclude_List")
    if excluded:
        if not isinstance(excluded, list) or any(f"p{i}" not in named for i in excluded):
            d.problems.add(f"{where}.Particle_Exclude_List: {excluded!r} are not particle ids")
            return None
        out["exclude"] = [f"p{i}" for i in excluded]
    if "Region" in info:
        geometry = d.block("Region", where, info).get("Geometry")
        region = _region(geometry, f"{where}.Region.Geometry", d.dimension, d.problems, d.notes)
        if region is None:
            return None
        out["region"] = region
    if not out or out.keys() == {"exclude"}:
        d.problems.add(f"{where}: select nodes by Particle_List and/or Region")
        return None
    return out


def _directions(d: Deck, info: dict[str, Any], where: str) -> list[int]:
    dirs = info.get("Direction", [])
    if (
        not isinstance(dirs, list)
        or not dirs
        or any(k not in range(1, d.dimension + 1) for k in dirs)
    ):
        d.problems.add(f"{where}.Direction: expected a list of 1..{d.dimension}, got {dirs!r}")
        return []
    return sorted(set(dirs))


def _region(geometry: Any, where: str, dimension: int, problems: Problems, notes: list[str]):
    """A PeriDEM Region.Geometry as a granulate shape spec."""
    if not isinstance(geometry, dict):
        problems.add(f"{where}: expected a block with Type and Parameters")
        return None
    kind = geometry.get("Type")
    p = problems.numbers(geometry.get("Parameters"), f"{where}.Parameters")
    if kind == "rectangle" and dimension == 2:
        return _rectangle(p, where, problems, notes)
    if kind in ("cuboid", "cube", "rectangle") and dimension == 3 and len(p) == 6:
        return {"type": "box", "lower": p[0:3], "upper": p[3:6]}
    if kind == "circle" and len(p) >= 3:
        return {"type": "disc", "center": p[1:3], "radius": p[0]}
    if kind == "sphere" and len(p) >= 4:
        return {"type": "sphere", "center": p[1:4], "radius": p[0]}
    problems.add(
        f"{where}: region type {kind!r} with {len(p)} parameters is not supported; use a "
        "rectangle/cuboid [x1, y1, z1, x2, y2, z2], circle or sphere [r, x, y, z]"
    )
    return None


def _rectangle(p: list[float], where: str, problems: Problems, notes: list[str]):
    """A 2D rectangle region from corners [x1, y1, z1, x2, y2, z2] or [Lx, Ly, cx, cy, cz]."""
    if len(p) == 6:  # corners
        lower, upper = p[0:2], p[3:5]
    elif len(p) == 5:  # PeriDEM's other form: lengths and centre
        lower = [p[2] - 0.5 * p[0], p[3] - 0.5 * p[1]]
        upper = [p[2] + 0.5 * p[0], p[3] + 0.5 * p[1]]
        notes.append(
            f"{where}: a rectangle of 5 parameters is PeriDEM's [Lx, Ly, cx, cy, cz]: "
            f"x in [{lower[0]:.6g}, {upper[0]:.6g}], y in [{lower[1]:.6g}, {upper[1]:.6g}]"
        )
    else:
        problems.add(
            f"{where}: a rectangle takes [x1, y1, z1, x2, y2, z2] or [Lx, Ly, cx, cy, cz], got {p}"
        )
        return None
    return {"type": "rectangle", "lower": lower, "upper": upper}


def _time_function(
    spec: Any, where: str, problems: Problems, *, force: bool = False
) -> dict[str, Any] | None:
    """PeriDEM's Time_Function as a granulate function spec of u(t) (or of a force factor)."""
    if spec is None:
        return {"type": "constant", "value": 1.0} if force else None
    kind = spec.get("Type") if isinstance(spec, dict) else None
    p = problems.numbers(spec.get("Parameters", []), f"{where}.Parameters") if kind else []
    if kind == "constant":
        return {"type": "constant", "value": p[0] if p else 0.0}
    if kind == "linear" and p:
        return {"type": "linear", "rate": p[0]}
    if kind == "quadratic" and len(p) >= 2:
        return {"type": "quadratic", "a": p[0], "b": p[1]}
    if kind == "sin" and len(p) >= 2:
        return {"type": "sine", "amplitude": p[0], "frequency": 0.5 * p[1]}
    problems.add(
        f"{where}: time function {kind!r} with parameters {p} is not supported here; granulate "
        "reads constant [a], linear [a], quadratic [a, b], sin [a, b]"
        + ("" if force else " and rotation [omega, x0, y0, z0]")
    )
    return None
