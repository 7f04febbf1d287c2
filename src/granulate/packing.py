"""Assemblies of particles: placements read from PeriDEM's CSV files, and a packing generator.

A placement puts a *grain* (a reference shape with a material) at a position, with a size and an
orientation. The size of a particle is its bounding radius r (the circumradius of a polygon, the
radius of a disc, PeriDEM's ``r``): the grain's reference shape, discretized once, is scaled by
r / r_ref (mesh size and horizon scale with it), rotated and moved into place.

``pack(container, grains, count)`` fills a container shape (any shape with a signed distance:
Rectangle, Disc, Polygon, Box, Cylinder, ...) with particles whose bounding circles (spheres)
neither overlap each other nor leave the container, so no two particles touch at the start.
Two methods:

- ``"random"``: random sequential addition, largest first, with a cell grid (so 10,000
  particles take seconds). Bounding discs reach about 50 % of the area (RSA jams at 54.7 % for
  equal discs; 38 % for spheres).
- ``"lattice"``: sites of a hexagonal (2D) or face-centred cubic (3D) lattice spaced by the
  largest bounding diameter, filled in random order, each particle shifted at random within the
  slack of its site: denser (up to 90.7 % / 74 % of bounding discs/spheres of one size) and
  regular at the scale of the largest grain.

The packing fraction reported is the grains' exact area (volume) over the container's.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from granulate import resources
from granulate.errors import InputError
from granulate.input_errors import checked_arguments
from granulate.io.table import read_table
from granulate.materials import Material
from granulate.reference_shapes import ReferenceShape
from granulate.shapes import Shape

# The size distributions moved to size_distributions.py; still importable from here.
from granulate.size_distributions import Fixed as Fixed
from granulate.size_distributions import LogNormal as LogNormal
from granulate.size_distributions import Normal as Normal
from granulate.size_distributions import Sieve as Sieve
from granulate.size_distributions import SizeDistribution
from granulate.size_distributions import Uniform as Uniform


# ----------------------------------------------------------------------- grains, placements
@checked_arguments
@dataclass(frozen=True, eq=False)
class Grain:
    """A kind of particle: a shape (discretized once, about its ``origin``) or a ready
    ReferenceShape (e.g. from a mesh), its material, and for packings its sizes and fraction.

    ``mesh_size`` [m] is for the reference size (a Shape needs it); ``reference_radius`` [m]
    defaults to the shape's bounding radius (for a ReferenceShape: the farthest node plus half
    a mesh size). ``fraction`` is this grain's share of the particles (by number or by volume,
    see ``pack``).
    """

    shape: Shape | ReferenceShape
    material: Material
    mesh_size: float | None = None
    sizes: SizeDistribution | None = None
    fraction: float = 1.0
    discretization: str = "lattice"
    reference_radius: float | None = None
    name: str | None = None
    _cache: dict = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        if not isinstance(self.material, Material):
            raise InputError(f"Grain material must be a granulate.Material, got {self.material!r}")
        if isinstance(self.shape, Shape) and not (
            self.mesh_size is not None and self.mesh_size > 0 and np.isfinite(self.mesh_size)
        ):
            raise InputError("a Grain made from a Shape needs a positive mesh_size [m]")
        if not (self.fraction >= 0 and np.isfinite(self.fraction)):
            raise InputError(f"Grain fraction must be non-negative, got {self.fraction}")

    @property
    def dimension(self) -> int:
        return self.shape.dimension

    @property
    def reference(self) -> ReferenceShape:
        """The shape discretized once, centred on its origin."""
        if "reference" not in self._cache:
            if isinstance(self.shape, ReferenceShape):
                self._cache["reference"] = self.shape
            else:
                assert self.mesh_size is not None
                try:
                    self._cache["reference"] = ReferenceShape.from_shape(
                        self.shape,
                        self.mesh_size,
                        discretization=self.discretization,
                        centered=True,
                    )
                except InputError as error:
                    label = f"grain {self.name!r}" if self.name else f"a {_label(self.shape)} grain"
                    raise InputError(f"{label}: {error}") from None
        return self._cache["reference"]

    @property
    def radius(self) -> float:
        """Reference (bounding) radius r_ref [m]; a particle of size r is scaled by r / r_ref."""
        return float(self.reference_radius) if self.reference_radius is not None else self.extent

    @property
    def extent(self) -> float:
        """Radius about the origin that holds the particle at its reference size [m] (for a
        mesh: the farthest node plus half a mesh size, which may exceed ``radius`` when the
        reference radius is given, as PeriDEM's Parameters[0])."""
        if isinstance(self.shape, Shape):
            return self.shape.bounding_radius
        if "extent" not in self._cache:
            reference = self.reference
            farthest = np.linalg.norm(reference.positions, axis=1).max()
            self._cache["extent"] = float(farthest + 0.5 * reference.mesh_size)
        return self._cache["extent"]

    @property
    def measure_at_unit_radius(self) -> float:
        """Area (volume) of a particle of bounding radius 1: |S| / r_ref^d."""
        if isinstance(self.shape, Shape):
            return self.shape.measure / self.radius**self.dimension
        return float(self.reference.volumes.sum()) / self.radius**self.dimension


@dataclass(frozen=True)
class Placements:
    """Where particles go: ``kinds`` (n,) grain (zone) index, ``positions`` (n, 3) [m],
    ``radii`` (n,) bounding radii [m], ``rotations`` (n,) angles [rad] in 2D or (n, 3) rotation
    vectors [rad] in 3D."""

    kinds: NDArray[np.int64]
    positions: NDArray[np.float64]
    radii: NDArray[np.float64]
    rotations: NDArray[np.float64]
    dimension: int

    def __len__(self) -> int:
        return len(self.radii)

    def __repr__(self) -> str:
        kinds = len(set(self.kinds.tolist()))
        return f"Placements({len(self)} particles in {self.dimension}D, {kinds} kinds)"

    def write_csv(self, path: str | Path) -> None:
        """PeriDEM's format: ``i, x, y, z, r, o`` (2D) or ``i, x, y, z, r`` (3D)."""
        from granulate.io.atomic import atomic_write

        lines = ["i, x, y, z, r, o" if self.dimension == 2 else "i, x, y, z, r"]
        for k in range(len(self)):
            x, y, z = self.positions[k]
            row = f"{self.kinds[k]}, {x:.9g}, {y:.9g}, {z:.9g}, {self.radii[k]:.9g}"
            lines.append(row + (f", {self.rotations[k]:.9g}" if self.dimension == 2 else ""))
        atomic_write(Path(path), ("\n".join(lines) + "\n").encode())


def _generator(seed: int) -> np.random.Generator:
    if not (isinstance(seed, int | np.integer) and seed >= 0):
        raise InputError(f"seed must be a non-negative integer, got {seed!r}")
    return np.random.default_rng(seed)


def random_rotations(rng: np.random.Generator, count: int, dimension: int) -> NDArray[np.float64]:
    """Uniform random orientations: angles in [0, 2 pi) (2D) or rotation vectors of uniformly
    distributed rotations (3D, from uniform unit quaternions; Shoemake 1992)."""
    if dimension == 2:
        return rng.uniform(0, 2 * np.pi, count)
    q = rng.normal(size=(count, 4))
    q /= np.linalg.norm(q, axis=1)[:, None]
    q[q[:, 0] < 0] *= -1
    angle = 2 * np.arccos(np.clip(q[:, 0], -1, 1))
    sin_half = np.sqrt(np.clip(1 - q[:, 0] ** 2, 0, None))
    axis = np.where(
        sin_half[:, None] > 1e-12, q[:, 1:] / np.maximum(sin_half, 1e-300)[:, None], 0.0
    )
    return axis * angle[:, None]


def read_placements(path: str | Path, *, dimension: int = 2, seed: int = 0) -> Placements:
    """Read PeriDEM's particle-location CSV: ``i, x, y, z, r`` (random orientations, seeded)
    or ``i, x, y, z, r, o`` (o: rotation about z [rad]); i is the zone (0-based), r the radius.
    A header line is optional."""
    file = Path(path)
    data = read_table(file, what="particles", widths=(5, 6), columns="i, x, y, z, r[, o]")
    zones = data[:, 0]
    if np.any(zones < 0) or np.any(zones != np.round(zones)):
        raise InputError(f"{file}: zone ids (column i) must be non-negative integers")
    radii = data[:, 4]
    bad = np.flatnonzero(~(radii > 0) | ~np.all(np.isfinite(data), axis=1))
    if len(bad):
        raise InputError(
            f"{file}: particle {bad[0]} (line {bad[0] + 2}) has a non-positive radius or a "
            "non-finite value"
        )
    positions = data[:, 1:4].copy()
    if dimension == 2:
        positions[:, 2] = 0.0
    if data.shape[1] == 6:
        if dimension == 3:
            raise InputError(
                f"{file}: an orientation column o is a 2D rotation; 3D takes i,x,y,z,r"
            )
        rotations = data[:, 5].copy()
    else:
        rotations = random_rotations(_generator(seed), len(data), dimension)
    return Placements(zones.astype(np.int64), positions, radii.copy(), rotations, dimension)


# ----------------------------------------------------------------------------- packings
@dataclass(frozen=True)
class Packing(Placements):
    """A generated assembly: placements plus the grains (``kinds`` index them) and the
    container."""

    grains: tuple[Grain, ...] = ()
    container: Shape | None = None

    @property
    def packing_fraction(self) -> float:
        """Exact area (volume) of the grains over the container's."""
        assert self.container is not None
        unit = np.array([g.measure_at_unit_radius for g in self.grains])
        return float(np.sum(unit[self.kinds] * self.radii**self.dimension) / self.container.measure)

    def __repr__(self) -> str:
        return f"Packing({self.summary()})"

    def summary(self) -> str:
        """Counts per grain, sizes and packing fraction, in one line."""
        counts = np.bincount(self.kinds, minlength=len(self.grains))
        parts = ", ".join(
            f"{c} x {g.name or _label(g.shape)}" for c, g in zip(counts, self.grains, strict=True)
        )
        return (
            f"{len(self)} particles ({parts}); radius {self.radii.min():.4g} .. "
            f"{self.radii.max():.4g} m (mean {self.radii.mean():.4g}); packing fraction "
            f"{self.packing_fraction:.3f}"
        )


def _label(shape: Shape | ReferenceShape) -> str:
    sides = getattr(shape, "sides", None)
    names = {3: "triangle", 4: "square", 6: "hexagon"}
    if sides is not None:
        return names.get(sides, f"{sides}-gon")
    return type(shape).__name__


def _grain_counts(
    grains: Sequence[Grain], count: int, by: str, rng: np.random.Generator
) -> NDArray[np.int64]:
    fractions = np.array([g.fraction for g in grains], dtype=float)
    if not fractions.sum() > 0:
        raise InputError("the grains' fractions sum to zero")
    fractions /= fractions.sum()
    if by == "volume":  # numbers ~ volume fraction / mean particle volume
        d = grains[0].dimension
        mean_volume = np.array(
            [g.measure_at_unit_radius * np.mean(g.sizes.sample(rng, 2000) ** d) for g in grains]  # type: ignore[union-attr]
        )
        fractions = fractions / mean_volume
        fractions /= fractions.sum()
    elif by != "number":
        raise InputError(f"fractions are 'number' or 'volume', got {by!r}")
    exact = fractions * count
    counts = np.floor(exact).astype(np.int64)
    remainder = count - counts.sum()
    counts[np.argsort(-(exact - counts), kind="stable")[:remainder]] += 1
    return counts


def pack(
    container: Shape,
    grains: Sequence[Grain],
    count: int,
    *,
    by: str = "number",
    method: str = "random",
    gap: float = 0.0,
    seed: int = 0,
    attempts: int = 2000,
) -> Packing:
    """Fill ``container`` with ``count`` particles of the given grains (see the module
    docstring). ``by``: the grains' fractions count particles ("number") or their volume
    ("volume"). ``gap`` [m]: extra clearance between bounding circles (spheres) and from the
    container walls. ``seed`` makes the packing reproducible. ``attempts``: random positions
    tried per particle before giving up ("random" method).

    Raises InputError, naming how many particles fitted, when the container cannot hold them.
    """
    if not grains:
        raise InputError("pack needs at least one Grain")
    d = container.dimension
    for g in grains:
        if g.dimension != d:
            raise InputError(f"a {g.dimension}D grain cannot fill a {d}D container")
        if g.sizes is None:
            raise InputError("every Grain of a packing needs sizes (e.g. Uniform(0.9e-3, 1.1e-3))")
    if not (isinstance(count, int | np.integer) and count > 0):
        raise InputError(f"count must be a positive number of particles, got {count!r}")
    nodes = max(len(g.reference.volumes) for g in grains)
    resources.require_memory(
        float(count) * (64 + resources.BYTES_PER_NODE * nodes),
        f"a packing of {count:,} grains of up to {nodes:,} nodes each",
        "pack fewer grains, or mesh them more coarsely",
    )
    if not (gap >= 0 and np.isfinite(gap)):
        raise InputError(f"gap must be a non-negative distance, got {gap}")
    rng = _generator(seed)
    counts = _grain_counts(grains, int(count), by, rng)
    kinds = np.repeat(np.arange(len(grains)), counts)
    radii = np.concatenate(
        [g.sizes.sample(rng, int(c)) for g, c in zip(grains, counts, strict=True)]
    )  # type: ignore[union-attr]
    lower, upper = container.bounds()
    # Overlaps are checked on the extent of each particle (its bounding radius at its size).
    extents = radii * np.array([g.extent / g.radius for g in grains])[kinds]
    largest = float(extents.max())
    if 2 * (largest + gap) > float(np.min((upper - lower)[:d])):
        raise InputError(
            f"the largest particle (bounding radius {largest:.4g} m) does not fit in the "
            f"container (smallest extent {float(np.min((upper - lower)[:d])):.4g} m); check the "
            "sizes and the container"
        )
    order = np.argsort(-extents, kind="stable")  # largest first
    kinds, radii, extents = kinds[order], radii[order], extents[order]
    # Nodes stay a mesh size from the container (a contact radius, 0.95 h by default), so no
    # particle presses on a wall at the start: half a mesh size beyond the extent.
    margins = radii * np.array([0.5 * g.reference.mesh_size / g.radius for g in grains])[kinds]
    if method == "random":
        positions = _random_sequential(container, extents, margins, gap, rng, attempts)
    elif method == "lattice":
        positions = _lattice_sites(container, extents, float(margins.max()), gap, rng)
    else:
        raise InputError(f"unknown packing method {method!r}; choose 'random' or 'lattice'")
    rotations = random_rotations(rng, len(radii), d)
    return Packing(kinds, positions, radii, rotations, d, tuple(grains), container)


def _candidates(
    container: Shape, radius: float, margin: float, gap: float, rng, count: int
) -> NDArray[np.float64]:
    lower, upper = container.bounds()
    d = container.dimension
    p = np.zeros((count, 3))
    p[:, :d] = rng.uniform(lower[:d] + radius, upper[:d] - radius, size=(count, d))
    return p[container.signed_distance(p) <= -(radius + margin + gap)]


def _random_sequential(
    container: Shape,
    radii: NDArray[np.float64],
    margins: NDArray[np.float64],
    gap: float,
    rng,
    attempts: int,
) -> NDArray[np.float64]:
    """Random sequential addition of bounding spheres, with a grid of cells of the largest
    diameter holding at most `slots` particle indices each (grown when full)."""
    d = container.dimension
    lower, upper = container.bounds()
    # Cells of at least one bounding diameter (the 3^d neighbourhood then holds every possible
    # overlap), and not many more cells than particles.
    cell = 2 * radii.max() + gap
    while np.prod(np.ceil((upper[:d] - lower[:d]) / cell) + 2) > max(4 * len(radii), 4096):
        cell *= 2
    shape = np.maximum(1, np.ceil((upper[:d] - lower[:d]) / cell).astype(np.int64)) + 2
    slots = 4
    members = np.full((int(np.prod(shape)), slots), -1, dtype=np.int64)
    fill = np.zeros(len(members), dtype=np.int64)
    strides = np.cumprod(np.concatenate([[1], shape[:0:-1]]))[::-1]
    offsets = np.array(np.meshgrid(*[[-1, 0, 1]] * d, indexing="ij")).reshape(d, -1).T @ strides
    positions = np.zeros((len(radii), 3))
    batch = 64
    for k, radius in enumerate(radii):
        placed = False
        tried = 0
        while tried < attempts and not placed:
            tried += batch
            p = _candidates(container, radius, margins[k], gap, rng, batch)
            if len(p) == 0:
                continue
            flat = (np.floor((p[:, :d] - lower[:d]) / cell).astype(np.int64) + 1) @ strides
            first = _first_free(p, flat, members, offsets, positions, radii, radius + gap)
            if first >= 0:
                positions[k] = p[first]
                target = flat[first]
                if fill[target] == members.shape[1]:
                    members = np.concatenate([members, np.full_like(members, -1)], axis=1)
                members[target, fill[target]] = k
                fill[target] += 1
                placed = True
        if not placed:
            raise InputError(
                f"the container holds only {k} of the {len(radii)} particles with the 'random' "
                f"method (no free spot in {attempts} tries for particle {k + 1}, radius "
                f"{radius:.4g} m); ask for fewer particles, a larger container, or "
                "method='lattice' (denser)"
            )
    return positions


def _first_free(
    p: NDArray[np.float64],
    flat: NDArray[np.int64],
    members: NDArray[np.int64],
    offsets: NDArray[np.int64],
    positions: NDArray[np.float64],
    radii: NDArray[np.float64],
    reach: float,
) -> int:
    """The first candidate p[c] (cell flat[c]) at least radii[j] + reach from every placed j in
    its cell's neighbourhood, or -1. Candidates are tested a few at a time: in a loose packing
    the first one is usually free, and the answer is the same as testing them all at once."""
    start, chunk = 0, 4
    while start < len(p):
        stop = min(start + chunk, len(p))
        near = members[flat[start:stop, None] + offsets[None, :]].reshape(stop - start, -1)
        valid = near >= 0
        others = np.where(valid, near, 0)
        distance = np.linalg.norm(positions[others] - p[start:stop, None, :], axis=2)
        free = np.all(~valid | (distance >= radii[others] + reach), axis=1)
        if free.any():
            return start + int(np.argmax(free))
        start, chunk = stop, 4 * chunk
    return -1


def _lattice_sites(
    container: Shape, radii: NDArray[np.float64], margin: float, gap: float, rng
) -> NDArray[np.float64]:
    """Hexagonal (2D) or FCC (3D) sites spaced by the largest bounding diameter plus gap, kept
    where a sphere of half the spacing fits in the container; particles take random sites and a
    random shift within their slack."""
    d = container.dimension
    lower, upper = container.bounds()
    # One bounding diameter apart, or wider when few particles go in a large container.
    spacing = 2 * radii.max() + gap
    while np.prod(np.ceil((upper[:d] - lower[:d]) / spacing) + 1) > max(64 * len(radii), 4096):
        spacing *= 1.5
    if d == 2:
        # The first row and column (just over) half a spacing in, so that they fit in a box.
        inset = (0.5 * spacing + margin + gap) * (1 + 1e-6)
        rows = np.arange(lower[1] + inset, upper[1], spacing * np.sqrt(3) / 2)
        columns = np.arange(lower[0] + inset, upper[0], spacing)
        sites = np.array(
            [
                (x + (0.5 * spacing if r % 2 else 0.0), y, 0.0)
                for r, y in enumerate(rows)
                for x in columns
            ]
        )
    else:
        a = spacing * np.sqrt(2)  # FCC cube edge; nearest neighbours at a / sqrt(2)
        basis = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]]) * a
        inset = (0.5 * spacing + margin + gap) * (1 + 1e-6)
        axes = [np.arange(lower[k] + inset, upper[k], a) for k in range(3)]
        corners = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
        sites = (corners[:, None, :] + basis[None]).reshape(-1, 3)
    sites = sites[container.signed_distance(sites) <= -(0.5 * spacing + margin + gap)]
    if len(sites) < len(radii):
        raise InputError(
            f"the container holds only {len(sites)} lattice sites of spacing {spacing:.4g} m "
            f"for {len(radii)} particles; ask for fewer or smaller particles, or a larger container"
        )
    chosen = sites[rng.permutation(len(sites))[: len(radii)]]
    slack = 0.5 * (spacing - gap) - radii  # moves that keep a gap to every other site
    direction = rng.normal(size=(len(radii), d))
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    shift = direction * (slack * rng.uniform(0, 1, len(radii)) ** (1 / d))[:, None]
    chosen[:, :d] += shift
    return chosen


def grains_by_kind(grains: Sequence[Grain] | Mapping[int, Grain], kinds: ArrayLike) -> list[Grain]:
    """The grain of each placement; every kind must have one."""
    lookup = dict(enumerate(grains)) if isinstance(grains, Sequence) else dict(grains)
    missing = sorted(set(np.unique(np.asarray(kinds)).tolist()) - set(lookup))
    if missing:
        raise InputError(
            f"placements use zone(s) {missing} with no grain given; give a Grain for each zone"
        )
    return [lookup[int(k)] for k in np.asarray(kinds)]
