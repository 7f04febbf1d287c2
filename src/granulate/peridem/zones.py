"""The Model block and the zones (Zone, Particle, Mesh and the older format's Wall blocks): each
zone a grain of its mesh (or a body of PeriDEM's built-in uniform mesh), walls and constrained
zones noted for the blocks after."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from granulate.errors import InputError
from granulate.peridem.deck import Deck
from granulate.peridem.keys import MODEL_KEYS, PARTICLE_ZONE_KEYS
from granulate.peridem.problems import Problems


def translate_model(d: Deck) -> None:
    """Model: dimension, final time and steps, the time scheme (noted), simulation type, seed."""
    model = d.block("Model")
    d.problems.unknown("Model", model, MODEL_KEYS)
    dimension = model.get("Dimension")
    if dimension not in (2, 3):
        d.problems.add(f"Model.Dimension: expected 2 or 3, got {dimension!r}")
        dimension = 2
    d.dimension = dimension
    d.final_time = d.problems.number(model.get("Final_Time"), "Model.Final_Time", positive=True)
    steps = model.get("Time_Steps")
    if not (isinstance(steps, int) and steps > 0):
        d.problems.add(f"Model.Time_Steps: expected a positive integer, got {steps!r}")
        steps = 1
    d.steps = steps
    scheme = d.block("Discretization_Type", "Model", model).get("Time", "central_difference")
    if scheme not in ("central_difference", "velocity_verlet"):
        d.problems.add(
            f"Model.Discretization_Type.Time: {scheme!r}; PeriDEM knows central_difference "
            "and velocity_verlet"
        )
    d.notes.append(
        f"time integration: granulate uses velocity Verlet (PeriDEM's {scheme} "
        + (
            "is semi-implicit Euler: the same trajectories to first order in dt)"
            if scheme == "central_difference"
            else "is the same scheme)"
        )
    )
    for key in ("Horizon", "Mesh_Size", "Horizon_h_Ratio"):
        if key in model:
            d.notes.append(f"Model.{key}: not read (PeriDEM ignores it; materials set the horizon)")
    d.single = model.get("Particle_Sim_Type") == "Single_Particle"
    d.seed = model.get("Seed", 1)


def translate_zones(d: Deck) -> None:
    """Zone, Particle, Mesh (and the older format's Wall): one grain or body per zone."""
    zone_block, particle_block = d.block("Zone"), d.block("Particle")
    wall_block, mesh_block = d.block("Wall"), d.block("Mesh")
    material_block = d.material_block = d.block("Material")
    count = zone_block.get("Zones", 1)
    if not (isinstance(count, int) and count > 0):
        d.problems.add(f"Zone.Zones: expected a positive integer, got {count!r}")
        count = 1
    d.zones = list(range(1, count + 1))
    zone_keys = {f"Zone_{z}" for z in d.zones}
    d.problems.unknown("Zone", zone_block, {"Zones"} | zone_keys)
    d.problems.unknown(
        "Particle",
        particle_block,
        {"Test_Name", "Compressive_Test", "Two_Particle_Test"} | zone_keys,
    )
    d.problems.unknown("Mesh", mesh_block, zone_keys)
    d.problems.unknown("Material", material_block, zone_keys)
    d.particle_block = particle_block
    d.test = particle_block.get("Test_Name", "")
    older_walls = False
    for z in d.zones:
        zk = f"Zone_{z}"
        zinfo = d.block(zk, "Zone", zone_block)
        pinfo = d.block(zk, "Particle", particle_block)
        if zk in wall_block and not pinfo:  # the older format: the Wall block says what it is
            pinfo = _older_wall_zone(zk, zinfo, wall_block, d.problems)
            older_walls = True
        _zone(d, z, zinfo, pinfo, mesh_block)
    if wall_block and not older_walls:  # beside Particle entries, as PeriDEM reads it: ignored
        d.notes.append("Wall: not read (PeriDEM does not use it to run either)")


def _zone(
    d: Deck, z: int, zinfo: dict[str, Any], pinfo: dict[str, Any], mesh_block: dict[str, Any]
) -> None:
    zk = f"Zone_{z}"
    d.problems.unknown(f"Zone.{zk}", zinfo, {"Is_Wall", "Type", "Parameters"})
    d.problems.unknown(f"Particle.{zk}", pinfo, PARTICLE_ZONE_KEYS)
    if zinfo.get("Is_Wall", pinfo.get("Is_Wall", False)):
        d.walls.add(z)
    if pinfo.get("Create_Particle_Using_ParticleZone_GeomObject", False) or d.single:
        d.geometry_particle.add(z)
    if pinfo.get("All_Dofs_Constrained", False):
        d.constrained.add(z)
    kind = str(pinfo.get("Type", ""))
    parameters = d.problems.numbers(pinfo.get("Parameters", []), f"Particle.{zk}.Parameters")
    minfo = d.block(zk, "Mesh", mesh_block)
    d.problems.unknown(f"Mesh.{zk}", minfo, {"File", "CreateMesh", "Mesh_Size"})
    create = d.block("CreateMesh", f"Mesh.{zk}", minfo)
    if create.get("Flag", False):
        _built_mesh(d, z, kind, parameters, minfo, create)
    elif "File" in minfo:
        _mesh_file(d, z, kind, parameters, str(minfo["File"]).strip())
    else:
        d.problems.add(f"Mesh.{zk}: give File (a gmsh mesh) or CreateMesh with Mesh_Size")


def _built_mesh(
    d: Deck,
    z: int,
    kind: str,
    parameters: list[float],
    minfo: dict[str, Any],
    create: dict[str, Any],
) -> None:
    """PeriDEM's built-in uniform mesh of a rectangle: a body on a grid."""
    zk = f"Zone_{z}"
    h = d.problems.number(minfo.get("Mesh_Size"), f"Mesh.{zk}.Mesh_Size", positive=True)
    if create.get("Info", "uniform") != "uniform" or kind != "rectangle" or len(parameters) < 6:
        d.problems.add(
            f"Mesh.{zk}.CreateMesh: granulate builds PeriDEM's uniform mesh of a "
            "rectangle [x1, y1, z1, x2, y2, z2] only"
        )
        return
    shape = (
        {"type": "rectangle", "lower": parameters[0:2], "upper": parameters[3:5]}
        if d.dimension == 2
        else {"type": "box", "lower": parameters[0:3], "upper": parameters[3:6]}
    )
    name = f"zone_{z}"
    body = {"name": "", "shape": shape, "material": name, "mesh_size": h, "discretization": "grid"}
    d.bodies.append({"zone": z, "body": body})
    d.zone_mesh_size[z] = h
    d.zone_extent[z] = np.subtract(shape["upper"], shape["lower"])


def _mesh_file(d: Deck, z: int, kind: str, parameters: list[float], file: str) -> None:
    """A zone meshed in a file: a grain, centred on the zone's geometry and scaled by its
    reference radius unless the zone is one particle placed as meshed."""
    from granulate.meshes import read_mesh

    zk = f"Zone_{z}"
    try:
        mesh = read_mesh(str(d.folder / file), dimension=d.dimension)
    except InputError as error:
        d.problems.add(f"Mesh.{zk}.File: {error}")
        return
    h = smallest_spacing(mesh.positions)
    d.zone_mesh_size[z] = h
    if z in d.geometry_particle:
        d.zone_extent[z] = np.ptp(mesh.positions[:, : d.dimension], axis=0)
    name = f"zone_{z}"
    grain: dict[str, Any] = {"material": name}
    grain["mesh"] = {"file": d.file_ref(file), "dimension": d.dimension, "mesh_size": h}
    if z not in d.geometry_particle:
        center = _center(kind, parameters)
        grain["mesh"]["center"] = center[: d.dimension] if d.dimension == 2 else center
        if not parameters or not parameters[0] > 0:
            d.problems.add(
                f"Particle.{zk}.Parameters: the reference radius Parameters[0] is needed "
                "to scale the particles placed from the CSV"
            )
            return
        d.zone_radius[z] = parameters[0]
        grain["reference_radius"] = parameters[0]
    d.grains[name] = grain


def smallest_spacing(positions: np.ndarray) -> float:
    """Smallest distance between two nodes (PeriDEM's mesh size h), by a sweep along x."""
    points = positions[np.argsort(positions[:, 0])]
    best = math.inf
    for k in range(1, len(points)):
        gap = points[k:, 0] - points[:-k, 0]
        if gap.min() >= best:
            break
        d = np.sqrt(np.einsum("ij,ij->i", points[k:] - points[:-k], points[k:] - points[:-k]))
        best = min(best, float(d.min()))
    return best


def _center(kind: str, parameters: list[float]) -> list[float]:
    """The centre of a zone's reference geometry (the origin of its particles' local frame)."""
    if kind in ("rectangle", "cuboid", "cube") and len(parameters) >= 6:
        return [0.5 * (parameters[k] + parameters[k + 3]) for k in range(3)]
    if kind == "drum2d" and len(parameters) >= 5:
        return parameters[2:5]
    if len(parameters) >= 4:
        return parameters[1:4]
    return [0.0, 0.0, 0.0]


def _older_wall_zone(
    zk: str,
    zinfo: dict[str, Any],
    wall_block: dict[str, Any],
    problems: Problems,
) -> dict[str, Any]:
    """The Particle.Zone_k entry that PeriDEM's older format's wall zone means (KEYS.md): the
    zone's mesh is one wall placed as meshed, every node fixed if All_Dofs_Constrained."""
    winfo = problems.block(wall_block, zk, "Wall")
    problems.unknown(f"Wall.{zk}", winfo, {"Type", "All_Dofs_Constrained", "Mesh"})
    if not zinfo.get("Is_Wall", False):
        problems.add(f"Wall.{zk}: zone {zk} is not a wall (Zone.{zk}.Is_Wall is not true)")
    if winfo.get("Type", "flexible") != "flexible" or winfo.get("Mesh", True) is not True:
        problems.add(
            f"Wall.{zk}: granulate reads meshed (Type: flexible, Mesh: true) walls, got "
            f"Type {winfo.get('Type')!r}, Mesh {winfo.get('Mesh')!r}"
        )
    return {
        "Type": zinfo.get("Type", ""),
        "Parameters": zinfo.get("Parameters", []),
        "All_Dofs_Constrained": bool(winfo.get("All_Dofs_Constrained", False)),
        "Create_Particle_Using_ParticleZone_GeomObject": True,
    }
