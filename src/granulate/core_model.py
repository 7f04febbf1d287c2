"""An Assembly turned into the core's frozen Model: one core material per Material, one core
shape per reference shape (and per body not a translated copy of an earlier one), each
particle placed with its own horizon; the memory check before any bond is built; and
pre-cracks, bonds broken across a plane once the bonds exist."""

from __future__ import annotations

import functools
import weakref
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from granulate import _core, resources
from granulate.assembly import Assembly, Body
from granulate.errors import InputError
from granulate.materials import Material
from granulate.reference_shapes import ReferenceShape
from granulate.shape_sharing import TranslatedShapes
from granulate.shapes import Shape

#: The most horizon / mesh size accepted: peridynamic horizons are 3-4 mesh sizes; at 20 a node
#: has about 1,300 bonds in 2D and 34,000 in 3D.
MOST_HORIZON_FACTOR = 20.0


#: The most forward bonds of a particle the bond passes evaluate whole, None for the core's
#: default (16,384); a larger one is cut into ranges that threads share
#: (_core.Model.set_whole_particle_bonds). Lower it to spread a small body over threads; the
#: forces' bits follow it, never the other particles held.
WHOLE_PARTICLE_BONDS: int | None = None


def build_model(
    assembly: Assembly, plane: str, outer_layers: bool
) -> tuple[_core.Model, list[Material]]:
    """The finalized core model and its materials, in core order. Each particle carries its own
    horizon (absolute, or horizon_factor times its mesh size), so particles of any size share
    one material. With `outer_layers` (the surface law), lattices' and conforming
    discretisations' outer layers carry surface points (the node-sphere law sees those nodes at
    themselves: no anchors)."""
    model = _core.Model(assembly.dimension, getattr(_core.PlaneMode, plane))
    if WHOLE_PARTICLE_BONDS is not None:
        model.set_whole_particle_bonds(WHOLE_PARTICLE_BONDS)
    sources = _shape_sources(assembly, outer_layers)
    _require_memory_for_model(assembly, plane, {b: source.key for b, source in sources.items()})
    material_ids: dict[int, int] = {}
    core_materials: list[Material] = []
    shape_ids: dict[int, int] = {}
    shape_of_source: dict[int, int] = {}  # bodies without a reference shape
    for body, positions in zip(assembly.bodies, assembly.positions, strict=True):
        horizon = body.material.resolved_horizon(body.mesh_size)
        key = id(body.material)
        if key not in material_ids:
            material_ids[key] = model.add_material(body.material.core_params(body.mesh_size))
            core_materials.append(body.material)
        if body.reference is None:
            source = sources[body.index]
            if source.key not in shape_of_source:
                shape_of_source[source.key] = model.add_shape(
                    source.positions, source.volumes, source.mesh_size, *source.surface
                )
            model.place_shape(
                shape_of_source[source.key], material_ids[key], positions, 1.0, horizon
            )
            continue
        reference = body.reference
        if id(reference) not in shape_ids:
            shape_ids[id(reference)] = model.add_shape(
                reference.positions,
                reference.volumes,
                reference.mesh_size,
                *_surface_arrays(reference, outer_layers),
            )
        model.place_shape(
            shape_ids[id(reference)], material_ids[key], positions, body.scale, horizon
        )
    model.finalize()
    return model, core_materials


def materials_in_core_order(bodies: list[Body]) -> list[Material]:
    """The materials of `bodies` in the order they first use them: the order build_model adds
    them to the core (its core_materials), known without building."""
    materials: dict[int, Material] = {}
    for body in bodies:
        materials.setdefault(id(body.material), body.material)
    return list(materials.values())


@dataclass(frozen=True)
class _ShapeSource:
    """The nodes a body's core shape is made from: its own, or those of the earlier body it is
    a translated copy of (shape_sharing.py). ``key``: that body's index in the assembly, or in
    its parent for a subset (Assembly.subset), so that a subset's grains share the shapes of
    the whole assembly's and so its bond lengths, to the last bit."""

    key: int
    positions: NDArray[np.float64]
    volumes: NDArray[np.float64]
    mesh_size: float
    surface: tuple[NDArray[np.float64], NDArray[np.float64]]


def _shape_sources(assembly: Assembly, outer_layers: bool) -> dict[int, _ShapeSource]:
    """Per body without a reference shape, the nodes of its core shape."""
    home, index = assembly.parent or (assembly, np.arange(len(assembly.bodies)))
    copy_of = _translated_copies(home, outer_layers)
    sources = {}
    for body in assembly.bodies:
        if body.reference is not None:
            continue
        donor = copy_of.get(int(index[body.index]), int(index[body.index]))
        sources[body.index] = _ShapeSource(
            donor,
            home.positions[donor],
            home.volumes[donor],
            home.bodies[donor].mesh_size,
            _surface_arrays(home.surfaces[donor], outer_layers),
        )
    return sources


# Translated copies found in an assembly, by the assembly and (outer_layers, bodies): a
# distributed run builds many subsets of one assembly and looks them up there each time.
_COPIES: weakref.WeakKeyDictionary[Assembly, dict[tuple[bool, int], dict[int, int]]] = (
    weakref.WeakKeyDictionary()
)


def _translated_copies(assembly: Assembly, outer_layers: bool) -> dict[int, int]:
    """Bodies without a reference shape that are translated copies of an earlier one
    (shape_sharing.py): body index -> the earlier body's index. They share its core shape and
    bond family."""
    known = _COPIES.setdefault(assembly, {})
    key = (outer_layers, len(assembly.bodies))
    if key in known:
        return known[key]
    copies, copy_of = TranslatedShapes(), {}
    for body, surface in zip(assembly.bodies, assembly.surfaces, strict=True):
        if body.reference is not None:  # placed: its nodes are not computed here
            continue
        positions, volumes = assembly.positions[body.index], assembly.volumes[body.index]
        surface_arrays = functools.partial(_surface_arrays, surface, outer_layers, keep=False)
        original = copies.find(positions, volumes, body.mesh_size, surface_arrays)
        if original is None:
            copies.remember(body.index, positions, volumes, body.mesh_size, surface_arrays)
        else:
            copy_of[body.index] = original
    known[key] = copy_of
    return copy_of


def require_memory_for(assembly: Assembly, plane: str, outer_layers: bool) -> None:
    """build_model's memory check of `assembly`'s model, without building it (InputError when
    it would not fit in the memory free now)."""
    _require_memory_for_model(assembly, plane, _translated_copies(assembly, outer_layers))


def _require_memory_for_model(assembly: Assembly, plane: str, shapes: Mapping[int, int]) -> None:
    """InputError before the bonds are built when the model would not fit in memory: every
    node's state, and one bond family per reference shape and horizon ratio (particles placed
    from one shape share it) or per shape of bodies without one (`shapes`: body index -> the
    index of the body whose nodes make its shape)."""
    families: dict[tuple[int, float], float] = {}
    for body in assembly.bodies:
        ratio = body.material.resolved_horizon(body.mesh_size) / body.mesh_size
        _check_material_for(body, ratio * body.mesh_size, assembly.dimension, plane)
        own = -1 - shapes.get(body.index, body.index)
        key = (id(body.reference) if body.reference is not None else own, ratio)
        family = body.node_count * resources.bonds_per_node(assembly.dimension, ratio)
        families[key] = family
    nodes, bonds = float(assembly.node_count), float(sum(families.values()))
    resources.require_memory(
        resources.simulation_bytes(nodes, bonds),
        f"the model ({nodes:,.0f} nodes, about {bonds:,.0f} bonds)",
        "use fewer or coarser particles, or a smaller horizon_factor",
    )


def _check_material_for(body: Body, horizon: float, dimension: int, plane: str) -> None:
    """InputError for a material a body cannot use as given: a horizon far beyond its mesh
    size (an absolute horizon in the wrong unit bonds every node to every other), or PMB with a
    Poisson ratio it cannot have (1/4; 1/3 in plane stress)."""
    ratio = horizon / body.mesh_size
    if ratio > MOST_HORIZON_FACTOR:
        raise InputError(
            f"body {body.name!r}: the horizon {horizon:.4g} m is {ratio:.0f} times its mesh "
            f"size {body.mesh_size:.4g} m (at most {MOST_HORIZON_FACTOR:.0f}; usually "
            "3-4): give horizon_factor, or the horizon in metres"
        )
    material = body.material
    if material.model != "pmb":
        return
    K, G = material.elastic_moduli()
    nu = (3 * K - 2 * G) / (2 * (3 * K + G))
    allowed = 1 / 3 if (dimension == 2 and plane == "stress") else 0.25
    if abs(nu - allowed) > 1e-3:
        raise InputError(
            f"body {body.name!r}: model 'pmb' has Poisson ratio {allowed:.4g} here, but the "
            f"material's constants give {nu:.4g}; use model 'lps', or constants with "
            f"poisson_ratio {allowed:.4g}"
        )


def _surface_arrays(
    reference: ReferenceShape | None, outer_layers: bool, keep: bool = True
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A shape's surface offsets (flat, 3 per node) and depths for the core; empty arrays where
    it has none (all depths 0: empty too). With ``outer_layers`` (the surface law) a lattice's
    or conforming discretisation's outer layer, which only that law uses: kept on the shape
    (ReferenceShape.outer_layer_of), or with `keep` False computed without keeping it where
    the shape does not hold it yet (a copy's, compared once)."""
    if reference is None:
        return np.zeros(0), np.zeros(0)
    layer = None
    if outer_layers:
        layer = reference.outer_layer_of if keep else reference.outer_layer_unkept()
    if layer is not None:
        return np.ascontiguousarray(layer[0]).reshape(-1), np.ascontiguousarray(layer[1])
    if reference.surface is None:
        return np.zeros(0), np.zeros(0)
    return np.ascontiguousarray(reference.surface, dtype=np.float64).reshape(-1), np.zeros(0)


def break_crossing_bonds(
    core: _core.Simulation,
    model: _core.Model,
    point: NDArray[np.float64],
    normal: NDArray[np.float64],
    region: Shape | None,
) -> int:
    """Break the bonds from the side (X - point) . normal < 0 to the other whose midpoint lies
    in `region` (all, when None), in the reference configuration; returns how many broke."""
    X = model.reference_positions
    side = (X - point) @ normal
    offsets = model.bond_offsets
    owner = np.repeat(
        np.arange(len(offsets) - 1, dtype=np.uint32), np.diff(offsets).astype(np.int64)
    )
    neighbor = model.bond_neighbors()
    crossing = (side[owner] < 0) & (side[neighbor] >= 0)
    if region is not None:
        crossing &= region.contains(0.5 * (X[owner] + X[neighbor]))
    pairs = np.ascontiguousarray(
        np.column_stack([owner[crossing], neighbor[crossing]]), dtype=np.uint32
    )
    before = core.broken_bonds()
    core.break_bonds(pairs)
    return core.broken_bonds() - before
