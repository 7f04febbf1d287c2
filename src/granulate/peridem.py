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
"""

from __future__ import annotations

import difflib
import math
import os
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from granulate.errors import InputError
from granulate.io.files import read_text
from granulate.yaml_input import load_yaml

#: Sections of a deck and the keys granulate reads in each (Zone_<k> / Set_<s> blocks apart).
SECTIONS = (
    "Model",
    "Zone",
    "Particle",
    "Particle_Generation",
    "Mesh",
    "Material",
    "Contact",
    "Neighbor",
    "Force_BC",
    "Displacement_BC",
    "IC",
    "Output",
    "Restart",
    "Wall",
)
#: Top-level keys PeriDEM does not read (or that only describe the set-up).
IGNORED_SECTIONS = ("HPX", "Policy", "Container", "State_Potential")

_MODEL_KEYS = {
    "Dimension",
    "Discretization_Type",
    "Final_Time",
    "Time_Steps",
    "Particle_Sim_Type",
    "Seed",
    "Horizon",
    "Mesh_Size",
    "Horizon_h_Ratio",
}
_PARTICLE_ZONE_KEYS = {
    "Type",
    "Parameters",
    "Is_Wall",
    "All_Dofs_Constrained",
    "Create_Particle_Using_ParticleZone_GeomObject",
    "Vec_Type",
    "Vec_Flag",
}
_MATERIAL_KEYS = {
    "Type",
    "Density",
    "Horizon",
    "Horizon_Mesh_Ratio",
    "Compute_From_Classical",
    "E",
    "K",
    "G",
    "Poisson_Ratio",
    "Gc",
    "KIc",
    "Influence_Function",
    "Copy_Material_Data",
    "Is_Plane_Strain",
}
_CONTACT_KEYS = {
    "Contact_Radius_Factor",
    "Contact_Radius",
    "Kn",
    "Kn_Factor",
    "Damping_On",
    "Epsilon",
    "Beta_n_Factor",
    "Friction_On",
    "Friction_Coeff",
    "Copy_Contact_Data",
}
_SET_KEYS = {
    "Particle_List",
    "Wall_List",
    "Particle_Exclude_List",
    "Region",
    "Direction",
    "Zero_Displacement",
    "Time_Function",
    "Spatial_Function",
}
_OUTPUT_KEYS = {
    "Path",
    "Tags",
    "Output_Interval",
    "Test_Output_Interval",
    "Perform_Out",
    "Perform_FE_Out",
    "Output_Criteria",
    "Compress_Type",
    "File_Format",
    "Debug",
    "Tag_PP",
}
#: PeriDEM output tags -> granulate output fields.
TAGS = {
    "Displacement": "Displacement",
    "Velocity": "Velocity",
    "Force": "Force",
    "Force_Density": "Force_Density",
    "Damage_Z": "Damage_Z",
    "Damage": "Damage",
    "Nodal_Volume": "Nodal_Volume",
    "Particle_ID": "Particle_ID",
    "Fixity": "Fixity",
    "Theta": "Dilatation",
}
#: Tags granulate does not write (reported, the run goes on).
UNWRITTEN_TAGS = (
    "Contact_Data",
    "Zone_ID",
    "Force_Fixity",
    "Contact_Nodes",
    "No_Fail_Node",
    "Boundary_Node_Flag",
    "Strain_Stress",
    "Particle_Locations",
)


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


class _Problems:
    """Collects every problem of a deck, so the user sees them all at once."""

    def __init__(self, source: Path) -> None:
        self.source = source
        self.errors: list[str] = []

    def add(self, message: str) -> None:
        self.errors.append(message)

    def unknown(self, where: str, keys: Any, known: set[str]) -> None:
        for key in keys:
            if key not in known:
                match = difflib.get_close_matches(str(key), sorted(known), n=1)
                hint = f"; did you mean {match[0]!r}?" if match else ""
                self.add(f"{where}: unknown key {key!r}{hint}")

    def raise_if_any(self) -> None:
        if self.errors:
            listed = "\n  - ".join(self.errors)
            raise InputError(
                f"{self.source}: {len(self.errors)} problem(s) in the PeriDEM deck:\n  - {listed}"
            )


def _number(value: Any, where: str, problems: _Problems, *, positive: bool = False) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        problems.add(f"{where}: expected a number, got {value!r}")
        return math.nan
    if not math.isfinite(x) or (positive and x <= 0):
        problems.add(f"{where}: expected a {'positive ' if positive else ''}number, got {value!r}")
    return x


def _numbers(value: Any, where: str, problems: _Problems) -> list[float]:
    if not isinstance(value, list):
        problems.add(f"{where}: expected a list of numbers, got {value!r}")
        return []
    return [_number(v, f"{where}[{k}]", problems) for k, v in enumerate(value)]


def _block(data: dict[str, Any], key: str, where: str, problems: _Problems) -> dict[str, Any]:
    value = data.get(key, {})
    if value is None:
        return {}
    if not isinstance(value, dict):
        problems.add(f"{where}.{key}: expected a block of keys, got {value!r}")
        return {}
    return value


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


def _region(geometry: Any, where: str, dimension: int, problems: _Problems, notes: list[str]):
    """A PeriDEM Region.Geometry as a granulate shape spec."""
    if not isinstance(geometry, dict):
        problems.add(f"{where}: expected a block with Type and Parameters")
        return None
    kind = geometry.get("Type")
    p = _numbers(geometry.get("Parameters"), f"{where}.Parameters", problems)
    if kind == "rectangle" and dimension == 2:
        if len(p) == 6:  # corners [x1, y1, z1, x2, y2, z2]
            lower, upper = p[0:2], p[3:5]
        elif len(p) == 5:  # PeriDEM's other form: lengths and centre [Lx, Ly, cx, cy, cz]
            lower = [p[2] - 0.5 * p[0], p[3] - 0.5 * p[1]]
            upper = [p[2] + 0.5 * p[0], p[3] + 0.5 * p[1]]
            notes.append(
                f"{where}: a rectangle of 5 parameters is PeriDEM's [Lx, Ly, cx, cy, cz]: "
                f"x in [{lower[0]:.6g}, {upper[0]:.6g}], y in [{lower[1]:.6g}, {upper[1]:.6g}]"
            )
        else:
            problems.add(
                f"{where}: a rectangle takes [x1, y1, z1, x2, y2, z2] or [Lx, Ly, cx, cy, cz], "
                f"got {p}"
            )
            return None
        return {"type": "rectangle", "lower": lower, "upper": upper}
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


def _time_function(
    spec: Any, where: str, problems: _Problems, *, force: bool = False
) -> dict[str, Any] | None:
    """PeriDEM's Time_Function as a granulate function spec of u(t) (or of a force factor)."""
    if spec is None:
        return {"type": "constant", "value": 1.0} if force else None
    kind = spec.get("Type") if isinstance(spec, dict) else None
    p = _numbers(spec.get("Parameters", []), f"{where}.Parameters", problems) if kind else []
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
    deck = read_deck(source)
    folder = source.parent
    relative_to = (output or folder).resolve()
    problems = _Problems(source)
    notes: list[str] = []

    def file_ref(name: str) -> str:
        return os.path.relpath(folder / name, relative_to)

    problems.unknown("deck", deck, set(SECTIONS) | set(IGNORED_SECTIONS))
    for key in IGNORED_SECTIONS:
        if key in deck:
            notes.append(f"{key}: not read (PeriDEM does not use it to run either)")

    # ---------------------------------------------------------------- Model
    model = _block(deck, "Model", "deck", problems)
    problems.unknown("Model", model, _MODEL_KEYS)
    dimension = model.get("Dimension")
    if dimension not in (2, 3):
        problems.add(f"Model.Dimension: expected 2 or 3, got {dimension!r}")
        dimension = 2
    final_time = _number(model.get("Final_Time"), "Model.Final_Time", problems, positive=True)
    steps = model.get("Time_Steps")
    if not (isinstance(steps, int) and steps > 0):
        problems.add(f"Model.Time_Steps: expected a positive integer, got {steps!r}")
        steps = 1
    scheme = _block(model, "Discretization_Type", "Model", problems).get(
        "Time", "central_difference"
    )
    if scheme not in ("central_difference", "velocity_verlet"):
        problems.add(
            f"Model.Discretization_Type.Time: {scheme!r}; PeriDEM knows central_difference "
            "and velocity_verlet"
        )
    notes.append(
        f"time integration: granulate uses velocity Verlet (PeriDEM's {scheme} "
        + (
            "is semi-implicit Euler: the same trajectories to first order in dt)"
            if scheme == "central_difference"
            else "is the same scheme)"
        )
    )
    for key in ("Horizon", "Mesh_Size", "Horizon_h_Ratio"):
        if key in model:
            notes.append(f"Model.{key}: not read (PeriDEM ignores it; materials set the horizon)")
    single = model.get("Particle_Sim_Type") == "Single_Particle"
    seed = model.get("Seed", 1)

    # ---------------------------------------------------------------- zones
    zone_block = _block(deck, "Zone", "deck", problems)
    particle_block = _block(deck, "Particle", "deck", problems)
    wall_block = _block(deck, "Wall", "deck", problems)
    older_walls = False
    mesh_block = _block(deck, "Mesh", "deck", problems)
    material_block = _block(deck, "Material", "deck", problems)
    count = zone_block.get("Zones", 1)
    if not (isinstance(count, int) and count > 0):
        problems.add(f"Zone.Zones: expected a positive integer, got {count!r}")
        count = 1
    zones = list(range(1, count + 1))
    problems.unknown("Zone", zone_block, {"Zones"} | {f"Zone_{z}" for z in zones})
    problems.unknown(
        "Particle",
        particle_block,
        {"Test_Name", "Compressive_Test", "Two_Particle_Test"} | {f"Zone_{z}" for z in zones},
    )
    problems.unknown("Mesh", mesh_block, {f"Zone_{z}" for z in zones})
    problems.unknown("Material", material_block, {f"Zone_{z}" for z in zones})
    test = particle_block.get("Test_Name", "")

    materials: dict[str, Any] = {}
    grains: dict[str, Any] = {}
    walls: set[int] = set()
    geometry_particle: set[int] = set()
    zone_extent: dict[int, np.ndarray] = {}  # of a zone placed once, as meshed [m]
    constrained: set[int] = set()
    zone_mesh_size: dict[int, float] = {}
    zone_radius: dict[int, float] = {}
    bodies: list[dict[str, Any]] = []
    from granulate.meshes import read_mesh

    for z in zones:
        zk = f"Zone_{z}"
        zinfo = _block(zone_block, zk, "Zone", problems)
        pinfo = _block(particle_block, zk, "Particle", problems)
        if zk in wall_block and not pinfo:  # the older format: the Wall block says what it is
            pinfo = _older_wall_zone(zk, zinfo, wall_block, problems)
            older_walls = True
        problems.unknown(f"Zone.{zk}", zinfo, {"Is_Wall", "Type", "Parameters"})
        problems.unknown(f"Particle.{zk}", pinfo, _PARTICLE_ZONE_KEYS)
        if zinfo.get("Is_Wall", pinfo.get("Is_Wall", False)):
            walls.add(z)
        if pinfo.get("Create_Particle_Using_ParticleZone_GeomObject", False) or single:
            geometry_particle.add(z)
        if pinfo.get("All_Dofs_Constrained", False):
            constrained.add(z)
        kind = str(pinfo.get("Type", ""))
        parameters = _numbers(pinfo.get("Parameters", []), f"Particle.{zk}.Parameters", problems)
        minfo = _block(mesh_block, zk, "Mesh", problems)
        problems.unknown(f"Mesh.{zk}", minfo, {"File", "CreateMesh", "Mesh_Size"})
        name = f"zone_{z}"
        grain: dict[str, Any] = {"material": name}
        create = _block(minfo, "CreateMesh", f"Mesh.{zk}", problems)
        if create.get("Flag", False):
            h = _number(minfo.get("Mesh_Size"), f"Mesh.{zk}.Mesh_Size", problems, positive=True)
            if (
                create.get("Info", "uniform") != "uniform"
                or kind != "rectangle"
                or len(parameters) < 6
            ):
                problems.add(
                    f"Mesh.{zk}.CreateMesh: granulate builds PeriDEM's uniform mesh of a "
                    "rectangle [x1, y1, z1, x2, y2, z2] only"
                )
                continue
            shape = (
                {"type": "rectangle", "lower": parameters[0:2], "upper": parameters[3:5]}
                if dimension == 2
                else {"type": "box", "lower": parameters[0:3], "upper": parameters[3:6]}
            )
            body = {
                "name": "",
                "shape": shape,
                "material": name,
                "mesh_size": h,
                "discretization": "grid",
            }
            bodies.append({"zone": z, "body": body})
            zone_mesh_size[z] = h
            zone_extent[z] = np.subtract(shape["upper"], shape["lower"])
        elif "File" in minfo:
            mesh_file = folder / str(minfo["File"]).strip()
            try:
                mesh = read_mesh(str(mesh_file), dimension=dimension)
            except InputError as error:
                problems.add(f"Mesh.{zk}.File: {error}")
                continue
            h = smallest_spacing(mesh.positions)
            zone_mesh_size[z] = h
            if z in geometry_particle:
                zone_extent[z] = np.ptp(mesh.positions[:, :dimension], axis=0)
            grain["mesh"] = {
                "file": file_ref(str(minfo["File"]).strip()),
                "dimension": dimension,
                "mesh_size": h,
            }
            if z not in geometry_particle:
                center = _center(kind, parameters)
                grain["mesh"]["center"] = center[:dimension] if dimension == 2 else center
                if not parameters or not parameters[0] > 0:
                    problems.add(
                        f"Particle.{zk}.Parameters: the reference radius Parameters[0] is needed "
                        "to scale the particles placed from the CSV"
                    )
                    continue
                zone_radius[z] = parameters[0]
                grain["reference_radius"] = parameters[0]
            grains[name] = grain
        else:
            problems.add(f"Mesh.{zk}: give File (a gmsh mesh) or CreateMesh with Mesh_Size")
            continue

    if wall_block and not older_walls:  # beside Particle entries, as PeriDEM reads it: ignored
        notes.append("Wall: not read (PeriDEM does not use it to run either)")

    # ---------------------------------------------------------------- materials
    for z in zones:
        info = _copied(
            material_block,
            f"Zone_{z}",
            "Copy_Material_Data",
            lambda other: f"Zone_{other}" if other in zones else None,
            "Material",
            "every zone needs a material",
            problems,
        )
        if not info:
            continue
        where = f"Material.Zone_{z}"
        problems.unknown(where, info, _MATERIAL_KEYS)
        kind = info.get("Type", "PDState")
        spec: dict[str, Any] = {}
        if kind == "PDState":
            spec["model"] = "lps"
        elif kind == "PMBBond":
            spec["model"] = "pmb"
        elif kind == "PDElasticBond":
            spec["model"] = "pmb"
            spec["fracture"] = False
        else:
            problems.add(
                f"{where}.Type: {kind!r} is not supported; granulate has PDState (LPS), "
                "PMBBond and PDElasticBond"
            )
            continue
        if not info.get("Compute_From_Classical", True):
            problems.add(
                f"{where}.Compute_From_Classical: false (peridynamic constants given directly) "
                "is not supported; give two of E, K, G, Poisson_Ratio and Gc or KIc"
            )
            continue
        spec["density"] = _number(info.get("Density"), f"{where}.Density", problems, positive=True)
        if "Horizon" in info:
            spec["horizon"] = _number(info["Horizon"], f"{where}.Horizon", problems, positive=True)
        elif "Horizon_Mesh_Ratio" in info:
            spec["horizon_factor"] = _number(
                info["Horizon_Mesh_Ratio"], f"{where}.Horizon_Mesh_Ratio", problems, positive=True
            )
        else:
            problems.add(f"{where}: give Horizon [m] or Horizon_Mesh_Ratio")
        for key, ours in (
            ("E", "youngs_modulus"),
            ("K", "bulk_modulus"),
            ("G", "shear_modulus"),
            ("Poisson_Ratio", "poisson_ratio"),
        ):
            if key in info and _number(info[key], f"{where}.{key}", problems) > 0:
                spec[ours] = float(info[key])
        if spec.get("fracture", True):
            if "Gc" in info and _number(info["Gc"], f"{where}.Gc", problems) > 0:
                spec["fracture_energy"] = _number(info["Gc"], f"{where}.Gc", problems)
            elif "KIc" in info:
                e = _youngs(spec, where, problems)
                kic = _number(info["KIc"], f"{where}.KIc", problems, positive=True)
                if e is not None:
                    spec["fracture_energy"] = kic * kic / e
                    notes.append(f"{where}: Gc = KIc^2 / E = {kic * kic / e:.6g} J/m^2 (PeriDEM's)")
            else:
                problems.add(f"{where}: give Gc or KIc")
        influence = _block(info, "Influence_Function", where, problems).get("Type", 0)
        names = {0: "constant", 1: "linear", 2: "gaussian"}
        if influence not in names:
            problems.add(f"{where}.Influence_Function.Type: expected 0, 1 or 2, got {influence!r}")
        else:
            spec["influence"] = names[influence]
        if compat:
            spec["break_in_compression"] = True
        materials[f"zone_{z}"] = spec
    if not compat:
        notes.append(
            "bonds break in tension only (s > s0); PeriDEM also breaks them in compression "
            "(|s| > s0); --peridem-compat does too"
        )
    plane = "strain"
    if dimension == 2:
        if compat:
            plane = "peridem"
            notes.append(
                "--peridem-compat: 2D LPS with PeriDEM's 3D constants (theta = 3/m sum, K, 15 G, "
                "3D critical stretch)"
            )
        else:
            notes.append(
                "2D LPS uses the plane-strain constants (K + G/3, 8 G, the 2D critical stretch); "
                "PeriDEM uses the 3D ones in 2D, which gives other moduli and fracture energy "
                "(--peridem-compat reproduces them)"
            )

    # ---------------------------------------------------------------- particles
    particles: list[dict[str, Any]] = []
    zone_of: list[int] = []
    generation = _block(deck, "Particle_Generation", "deck", problems)
    problems.unknown("Particle_Generation", generation, {"From_File", "File_Data_Type"})
    rows: np.ndarray | None = None
    placed_zones = [z for z in zones if z not in geometry_particle]
    if placed_zones:
        csv_name = generation.get("From_File")
        if not csv_name:
            problems.add(
                f"Particle_Generation.From_File: zones {placed_zones} are placed from a "
                "particle-location CSV; name it"
            )
        else:
            from granulate.packing import read_placements

            try:
                placements = read_placements(folder / str(csv_name), dimension=dimension, seed=seed)
                rows = np.column_stack([placements.kinds, placements.positions, placements.radii])
                rotations = placements.rotations
            except InputError as error:
                problems.add(f"Particle_Generation.From_File: {error}")
            kind = generation.get("File_Data_Type", "loc_rad")
            if kind not in ("loc_rad", "loc_rad_orient"):
                problems.add(
                    f"Particle_Generation.File_Data_Type: {kind!r}; expected loc_rad or "
                    "loc_rad_orient"
                )
            elif rows is not None and kind == "loc_rad":
                notes.append(
                    "loc_rad: random orientations from granulate's generator (seed "
                    f"{seed}); PeriDEM draws other ones"
                    + (
                        ", and turns particle i of a two-particle test by i pi"
                        if "two_particle" in test
                        else ""
                    )
                )
                if "two_particle" in test:
                    rotations = np.pi * np.arange(len(rows))
    deck_bodies = {b["zone"]: b["body"] for b in bodies}
    for z in zones:
        name = f"zone_{z}"
        if z in deck_bodies:
            body = deck_bodies[z]
            body["name"] = f"p{len(zone_of)}"
            zone_of.append(z)
            continue
        if name not in grains:
            continue
        if z in geometry_particle:
            particles.append(
                {"name": f"p{len(zone_of)}", "grain": name, "position": [0.0] * dimension}
            )
            zone_of.append(z)
            continue
        if rows is None:
            continue
        mine = np.flatnonzero(rows[:, 0] == z - 1)
        for k in mine:
            scale = float(rows[k, 4] / zone_radius[z])
            rotation = rotations[k]
            entry = {
                "name": f"p{len(zone_of)}",
                "grain": name,
                "position": [float(v) for v in rows[k, 1 : 1 + dimension]],
                "scale": scale,
                "rotation": float(rotation) if dimension == 2 else [float(v) for v in rotation],
            }
            particles.append(entry)
            zone_of.append(z)
    # A zone whose mesh failed has no particles, so later particle ids do not resolve: those
    # are consequences of the reported problem, not problems of their own.
    numbered = all(f"zone_{z}" in grains or z in deck_bodies for z in zones)
    if rows is not None:
        unknown = sorted({int(v) + 1 for v in rows[:, 0]} - set(placed_zones))
        if unknown:
            problems.add(
                f"Particle_Generation.From_File: rows name zone ids {[u - 1 for u in unknown]} "
                "(0-based) that are not particle zones"
            )

    # ------------------------------------------------------------- contact
    scales = {entry["name"]: entry.get("scale", 1.0) for entry in particles}
    h_min = min(
        (zone_mesh_size[z] * scales.get(f"p{k}", 1.0) for k, z in enumerate(zone_of)),
        default=math.inf,
    )
    contact_block = _block(deck, "Contact", "deck", problems)
    pairs: list[dict[str, Any]] = []
    contact = None  # every pair of zones is set below; a deck has no default contact
    peridem_pairs: list[dict[str, Any]] = []
    if single or not contact_block:
        if not single and len(zone_of) > 1:
            problems.add("Contact: missing; give Contact.Zone_<a><b> for every pair of zones")
    else:
        keys = {f"Zone_{a}{b}": (a, b) for a in zones for b in zones if a <= b}
        problems.unknown("Contact", contact_block, set(keys))

        def pair_key(other: Any) -> str | None:
            if not (isinstance(other, list) and len(other) == 2):
                return None
            key = f"Zone_{min(other)}{max(other)}"
            return key if key in keys else None

        friction_used = False
        damping_used = False
        for key, (a, b) in keys.items():
            if a in walls and b in walls:
                pairs.append({"materials": [f"zone_{a}", f"zone_{b}"], "contact": None})
                continue
            info = _copied(
                contact_block,
                key,
                "Copy_Contact_Data",
                pair_key,
                "Contact",
                f"zones {a} and {b} may touch",
                problems,
            )
            if not info:
                continue
            where = f"Contact.{key}"
            problems.unknown(where, info, _CONTACT_KEYS)
            spec: dict[str, Any] = {}
            if "Contact_Radius" in info:
                spec["contact_radius"] = _number(
                    info["Contact_Radius"], f"{where}.Contact_Radius", problems, positive=True
                )
            else:
                factor = _number(
                    info.get("Contact_Radius_Factor", 0.95),
                    f"{where}.Contact_Radius_Factor",
                    problems,
                    positive=True,
                )
                spec["contact_radius"] = factor * h_min
            kn_factor = _number(info.get("Kn_Factor", 1.0), f"{where}.Kn_Factor", problems)
            if "Kn" in info:
                kn = _number(info["Kn"], f"{where}.Kn", problems) * kn_factor
                if kn == 0:
                    pairs.append({"materials": [f"zone_{a}", f"zone_{b}"], "contact": None})
                    continue
                if kn < 0:
                    problems.add(f"{where}.Kn: must not be negative, got {info['Kn']}")
                    continue
                spec["normal_stiffness"] = kn
            else:
                spec["stiffness_factor"] = kn_factor
                notes.append(
                    f"{where}: no Kn, granulate's default kn (see granulate.contact) x Kn_Factor"
                )
            beta_factor = _number(
                info.get("Beta_n_Factor", 1.0), f"{where}.Beta_n_Factor", problems
            )
            if info.get("Damping_On", True) and beta_factor > 1e-8:
                epsilon = _number(info.get("Epsilon", 1.0), f"{where}.Epsilon", problems)
                if not 0 < epsilon <= 1:
                    problems.add(f"{where}.Epsilon: must be in (0, 1], got {epsilon}")
                    continue
                damping_used = damping_used or epsilon < 1
                if compat:  # PeriDEM's centre damping instead of granulate's dashpot
                    spec["restitution"] = 1.0
                    peridem_pairs.append(
                        {
                            "materials": [f"zone_{a}", f"zone_{b}"],
                            "epsilon": epsilon,
                            "beta_factor": beta_factor,
                        }
                    )
                else:
                    spec["restitution"] = epsilon
            else:
                spec["restitution"] = 1.0
            if info.get("Friction_On", True):
                spec["friction"] = _number(
                    info.get("Friction_Coeff", 0.0), f"{where}.Friction_Coeff", problems
                )
                friction_used = friction_used or spec["friction"] > 0
                if compat:
                    spec["friction_law"] = "peridem"
            if compat:  # one Rc per particle pair, springs kn V_i V_j
                spec["pair_law"] = "peridem"
            pairs.append({"materials": [f"zone_{a}", f"zone_{b}"], "contact": spec})
        notes.append(
            f"contact radius: Contact_Radius_Factor x the smallest node spacing of all particles "
            f"({h_min:.6g} m)"
        )
        if not compat:
            notes.append(
                "contact surface: a mesh vertex on a particle's surface has its contact sphere "
                "centred Rc/2 inside it, so particles touch where their meshes' surfaces meet "
                "(PeriDEM centres it on the vertex, so its particles touch Rc apart; "
                "--peridem-compat does too)"
            )
        if damping_used:
            notes.append(
                "contact damping: --peridem-compat: PeriDEM's particle-centre damping "
                "(Epsilon, Beta_n_Factor), which does not give the restitution Epsilon names"
                if compat
                else "contact damping: granulate's dashpot gives the restitution Epsilon asks "
                "for; PeriDEM's particle-centre damping (Beta_n_Factor) does not "
                "(--peridem-compat reproduces it)"
            )
        if friction_used:
            notes.append(
                "friction: "
                + (
                    "--peridem-compat: PeriDEM's sign (friction speeds sliding up)"
                    if compat
                    else "Coulomb friction opposes sliding (PeriDEM's has the wrong sign and "
                    "speeds sliding up; --peridem-compat reproduces it)"
                )
            )
        notes.append(
            "fragments of one particle are bodies in contact after it breaks (PeriDEM repels "
            "only the node pairs whose bond broke, and lets other nodes of its fragments pass "
            "through each other)"
        )
        if walls:
            notes.append(
                "walls are particles with every node constrained; the force on them is the "
                "reaction of the grains (history.csv <name>_fx, _fy). PeriDEM computes no "
                "contact force on wall nodes, so the force it reports on a wall is its weight"
            )

    # --------------------------------------------------------------- neighbor
    neighbor = _block(deck, "Neighbor", "deck", problems)
    problems.unknown("Neighbor", neighbor, {"Search_Factor", "Search_Interval", "Update_Criteria"})
    if neighbor:
        notes.append(
            "Neighbor: not read; granulate rebuilds its contact lists whenever a node has moved "
            "half the skin, so no contact is missed (PeriDEM's fixed Search_Interval can miss some)"
        )

    # ---------------------------------------------------------------- loading
    loading: list[dict[str, Any]] = []
    named = {f"p{k}" for k in range(len(zone_of))}

    # Walls by number (the older format's Wall_List, Wall_Id): 0, 1, ... in zone order.
    wall_particles = [k for k, z in enumerate(zone_of) if z in walls]

    def wall_ids(value: Any, where: str) -> list[int] | None:
        if not isinstance(value, list) or any(
            not isinstance(w, int) or not 0 <= w < len(wall_particles) for w in value
        ):
            problems.add(
                f"{where}: {value!r} names walls that do not exist (walls are numbered 0 .. "
                f"{len(wall_particles) - 1} in zone order)"
            )
            return None
        return [wall_particles[w] for w in value]

    def select(info: dict[str, Any], where: str) -> dict[str, Any] | None:
        out: dict[str, Any] = {}
        ids = info.get("Particle_List")
        if "Wall_List" in info:
            by_wall = wall_ids(info["Wall_List"], f"{where}.Wall_List")
            if by_wall is None:
                return None
            ids = [*(ids if isinstance(ids, list) else []), *by_wall]
        if ids is not None:
            if not isinstance(ids, list) or any(f"p{i}" not in named for i in ids):
                if numbered or not isinstance(ids, list):
                    problems.add(
                        f"{where}.Particle_List: {ids!r} names particles that do not exist (ids "
                        f"are 0-based, 0 .. {len(zone_of) - 1})"
                    )
                return None
            out["body"] = [f"p{i}" for i in ids]
        excluded = info.get("Particle_Exclude_List")
        if excluded:
            if not isinstance(excluded, list) or any(f"p{i}" not in named for i in excluded):
                problems.add(f"{where}.Particle_Exclude_List: {excluded!r} are not particle ids")
                return None
            out["exclude"] = [f"p{i}" for i in excluded]
        if "Region" in info:
            region = _region(
                _block(info, "Region", where, problems).get("Geometry"),
                f"{where}.Region.Geometry",
                dimension,
                problems,
                notes,
            )
            if region is None:
                return None
            out["region"] = region
        if not out or out.keys() == {"exclude"}:
            problems.add(f"{where}: select nodes by Particle_List and/or Region")
            return None
        return out

    def directions(info: dict[str, Any], where: str) -> list[int]:
        dirs = info.get("Direction", [])
        if (
            not isinstance(dirs, list)
            or not dirs
            or any(d not in range(1, dimension + 1) for d in dirs)
        ):
            problems.add(f"{where}.Direction: expected a list of 1..{dimension}, got {dirs!r}")
            return []
        return sorted(set(dirs))

    def bc_sets(
        name: str, block: dict[str, Any], other_keys: set[str]
    ) -> Iterator[tuple[str, dict[str, Any], dict[str, Any] | None, list[int]]]:
        """The Set_k blocks of a Displacement_BC or Force_BC block, checked: (where, the
        block, its nodes, its directions)."""
        count = block.get("Sets", 0) or 0
        problems.unknown(
            name, block, other_keys | {"Sets"} | {f"Set_{s}" for s in range(1, count + 1)}
        )
        for s in range(1, count + 1):
            where = f"{name}.Set_{s}"
            info = _block(block, f"Set_{s}", name, problems)
            problems.unknown(where, info, _SET_KEYS)
            yield where, info, select(info, where), directions(info, where)

    moved: dict[str, set[int]] = {}
    displacement = _block(deck, "Displacement_BC", "deck", problems)
    for where, info, nodes, dirs in bc_sets("Displacement_BC", displacement, set()):
        if nodes is None or not dirs:
            continue
        axes = "".join("xyz"[d - 1] for d in dirs)
        function = info.get("Time_Function")
        spatial = _block(info, "Spatial_Function", where, problems).get("Type", "constant")
        for body in nodes.get("body", []):
            if "region" not in nodes:
                moved.setdefault(body, set()).update(dirs)
        if info.get("Zero_Displacement", False):
            loading.append({"type": "fix", "nodes": nodes, "components": axes})
            continue
        if isinstance(function, dict) and function.get("Type") == "rotation":
            p = _numbers(
                function.get("Parameters", []), f"{where}.Time_Function.Parameters", problems
            )
            if len(p) < 3:
                problems.add(f"{where}.Time_Function: rotation takes [omega, x0, y0, z0]")
                continue
            loading.append(
                {
                    "type": "rotation",
                    "nodes": nodes,
                    "center": (p[1:4] + [0.0] * 3)[:3],
                    "angle": {"type": "linear", "rate": p[0]},
                }
            )
            continue
        if spatial != "constant":
            problems.add(
                f"{where}.Spatial_Function: {spatial!r}; displacement sets take a constant "
                "spatial function (or rotation with a rotation time function)"
            )
            continue
        fn = _time_function(function, f"{where}.Time_Function", problems)
        if fn is None:
            continue
        direction = [1.0 if k + 1 in dirs else 0.0 for k in range(dimension)]
        loading.append(
            {
                "type": "displacement",
                "nodes": nodes,
                "direction": direction,
                "function": fn,
                "components": axes,
            }
        )
    for index, z in enumerate(zone_of):
        if z in constrained:
            free = set(range(1, dimension + 1)) - moved.get(f"p{index}", set())
            if free:
                loading.append(
                    {
                        "type": "fix",
                        "nodes": {"body": f"p{index}"},
                        "components": "".join("xyz"[d - 1] for d in sorted(free)),
                    }
                )

    force_bc = _block(deck, "Force_BC", "deck", problems)
    gravity = None
    if force_bc.get("Gravity") is not None:
        g = _numbers(force_bc["Gravity"], "Force_BC.Gravity", problems)
        gravity = g[:dimension] if len(g) >= dimension else None
        if gravity is None:
            problems.add(f"Force_BC.Gravity: expected {dimension} or 3 components")
    for where, info, nodes, dirs in bc_sets("Force_BC", force_bc, {"Gravity"}):
        spatial = _block(info, "Spatial_Function", where, problems).get("Type", "constant")
        if spatial != "constant":
            problems.add(
                f"{where}.Spatial_Function: {spatial!r} force densities are not supported "
                "(constant only)"
            )
            continue
        fn = _time_function(
            info.get("Time_Function"), f"{where}.Time_Function", problems, force=True
        )
        if nodes is None or not dirs or fn is None:
            continue
        # f = g(t) along each listed direction: the function carries the magnitude.
        vector = [1.0 if k + 1 in dirs else 0.0 for k in range(dimension)]
        loading.append({"type": "force_density", "nodes": nodes, "vector": vector, "function": fn})

    ic = _block(deck, "IC", "deck", problems)
    problems.unknown("IC", ic, {"Constant_Velocity"})
    if "Constant_Velocity" in ic:
        info = _block(ic, "Constant_Velocity", "IC", problems)
        problems.unknown("IC.Constant_Velocity", info, {"Velocity_Vector", "Particle_List"})
        v = _numbers(info.get("Velocity_Vector"), "IC.Constant_Velocity.Velocity_Vector", problems)
        for i in info.get("Particle_List", []) or []:
            target = next((p for p in particles if p["name"] == f"p{i}"), None)
            body = next((b for b in deck_bodies.values() if b["name"] == f"p{i}"), None)
            if target is None and body is None:
                if numbered:
                    problems.add(f"IC.Constant_Velocity.Particle_List: no particle {i}")
            else:
                (target or body)["velocity"] = v[:dimension]  # type: ignore[index]

    # ----------------------------------------------------------------- output
    out = _block(deck, "Output", "deck", problems)
    problems.unknown("Output", out, _OUTPUT_KEYS)
    every = out.get("Output_Interval", steps)
    if not (isinstance(every, int) and every > 0):
        problems.add(f"Output.Output_Interval: expected a positive integer, got {every!r}")
        every = steps
    test_every = out.get("Test_Output_Interval") or max(1, every // 10)
    tags = out.get("Tags") or list(TAGS)
    fields = [TAGS[t] for t in tags if t in TAGS]
    unwritten = [t for t in tags if t not in TAGS]
    strange = [t for t in unwritten if t not in UNWRITTEN_TAGS]
    if strange:
        problems.add(
            f"Output.Tags: unknown tags {strange}; PeriDEM's are {[*TAGS, *UNWRITTEN_TAGS]}"
        )
    elif unwritten:
        notes.append(f"Output.Tags: {', '.join(unwritten)} are not written by granulate")
    if out.get("Perform_FE_Out"):
        notes.append(
            "Output.Perform_FE_Out: granulate writes the nodes as points, not the mesh cells"
        )
    stop: dict[str, Any] | None = None
    criteria = _block(out, "Output_Criteria", "Output", problems)
    if criteria:
        if criteria.get("Type") == "max_node_dist":
            d = _numbers(criteria.get("Parameters"), "Output.Output_Criteria.Parameters", problems)
            if d:
                stop = {"node_distance": d[0], "check_every": test_every}
        else:
            problems.add(
                f"Output.Output_Criteria.Type: {criteria.get('Type')!r}; granulate reads "
                "max_node_dist"
            )
    track = [f"p{k}" for k, z in enumerate(zone_of) if z in walls]
    if "two_particle" in test:
        track = [f"p{k}" for k in range(len(zone_of))]
    compressive = particle_block.get("Compressive_Test") or {}
    wall_id = compressive.get("Particle_Id")
    if "Wall_Id" in compressive:
        by_wall = wall_ids([compressive["Wall_Id"]], "Particle.Compressive_Test.Wall_Id")
        wall_id = by_wall[0] if by_wall else None
    if wall_id is not None and f"p{wall_id}" in named and f"p{wall_id}" not in track:
        track.append(f"p{wall_id}")
    track_areas = {}
    if wall_id is not None and f"p{wall_id}" in track:
        area = _loaded_area(compressive, zone_extent.get(zone_of[wall_id]), dimension, problems)
        if area is None and zone_of[wall_id] not in zone_extent:
            notes.append(
                f"Compressive_Test: p{wall_id} is placed from the particle file; its area is not "
                "known here, so history.csv records its force, not its stress"
            )
        if area is not None:
            track_areas[f"p{wall_id}"] = area
            notes.append(
                f"Compressive_Test: history.csv records p{wall_id}_stress, the force on the "
                f"loaded wall over its extent across the loading direction ({area:.6g} "
                f"{'m' if dimension == 2 else 'm^2'}); PeriDEM reports the force alone"
            )
    directory = default_output_directory(folder)
    if "Path" in out:
        notes.append(
            f"Output.Path {out['Path']!r} is PeriDEM's, relative to the deck's folder; the output "
            f"goes to {directory} in the working directory instead (choose with --out)"
        )
    output_spec: dict[str, Any] | None = {
        "directory": directory,
        "every": every,
        "fields": fields,
        "history_every": test_every if track else every,
        "track": track,
        "track_areas": track_areas,
    }
    if out.get("Perform_Out", True) is False:
        output_spec = None
        notes.append("Output.Perform_Out is false: no output is written")

    restart_spec: dict[str, Any] | None = None
    restart = _block(deck, "Restart", "deck", problems)
    if restart:
        problems.unknown("Restart", restart, {"File", "Step"})
        step = restart.get("Step")
        if not isinstance(restart.get("File"), str) or not (isinstance(step, int) and step >= 0):
            problems.add("Restart: give File (a VTU output of the run) and Step (its step)")
        else:
            restart_spec = {"file": file_ref(restart["File"]), "step": step}
            notes.append(
                f"Restart: positions and velocities from {restart['File']} at step {step}; bonds "
                "start intact, as in PeriDEM (granulate's checkpoints keep them: --resume)"
            )

    problems.raise_if_any()
    case: dict[str, Any] = {
        "dimension": dimension,
        "plane": plane,
        "materials": materials,
        "grains": grains,
    }
    if bodies:
        case["bodies"] = [b["body"] for b in bodies]
    if particles:
        case["particles"] = particles
    case["contact"] = contact
    if pairs:
        case["contact_pairs"] = pairs
    if peridem_pairs:
        case["peridem_damping"] = {
            "pairs": peridem_pairs,
            "walls": [f"p{k}" for k, z in enumerate(zone_of) if z in walls],
        }
    if loading:
        case["loading"] = loading
    if gravity is not None and any(gravity):
        case["gravity"] = gravity
    if steps < every:
        # PeriDEM's paper decks say Time_Steps: 1, a run shorter than one output interval.
        notes.append(
            f"Model.Time_Steps: {steps} is fewer than Output.Output_Interval ({every}), which no "
            "run means (PeriDEM's paper decks carry this slip): granulate runs to Final_Time at "
            "its default time step; the output intervals count its steps"
        )
        case["time"] = {"end": final_time}
    else:
        case["time"] = {"dt": final_time / steps, "steps": steps}
    if output_spec is not None:
        case["output"] = output_spec
    if stop is not None:
        case["stop"] = stop
    if restart_spec is not None:
        case["restart"] = restart_spec
    return Translation(case, source, notes)


def _copied(
    block: dict[str, Any],
    key: str,
    copy_key: str,
    target: Any,
    section: str,
    missing: str,
    problems: _Problems,
) -> dict[str, Any]:
    """The block ``section.key``, following ``copy_key`` links (``target(value)``: the key a
    link names, or None when it names nothing); {} with a problem reported for a missing block,
    a bad link or a cycle."""
    seen: list[str] = []
    while True:
        info = block.get(key)
        if not isinstance(info, dict):
            problems.add(f"{section}.{key}: missing ({missing})")
            return {}
        if copy_key not in info:
            return info
        seen.append(key)
        other = target(info[copy_key])
        if other is None or other in seen:
            problems.add(f"{section}.{key}.{copy_key}: nothing to copy at {info[copy_key]!r}")
            return {}
        key = other


def _youngs(spec: dict[str, Any], where: str, problems: _Problems) -> float | None:
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


#: Folder names that say nothing about a deck (PeriDEM's examples keep decks in ``inp/``).
_GENERIC_FOLDERS = {"inp", "input", "inputs", "deck", "decks"}


def _loaded_area(
    compressive: dict[str, Any], extent: np.ndarray | None, dimension: int, problems: _Problems
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


def _older_wall_zone(
    zk: str,
    zinfo: dict[str, Any],
    wall_block: dict[str, Any],
    problems: _Problems,
) -> dict[str, Any]:
    """The Particle.Zone_k entry that PeriDEM's older format's wall zone means (KEYS.md): the
    zone's mesh is one wall placed as meshed, every node fixed if All_Dofs_Constrained."""
    winfo = _block(wall_block, zk, "Wall", problems)
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
