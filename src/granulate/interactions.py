"""How a simulation's bodies meet each other and the walls: the default contact law, laws per
pair of materials, the walls with their own laws, the neighbour lists' skin, and PeriDEM's
particle-centre damping (for --peridem-compat). They are handed to the core when it is built
(apply); the checks at the start (no particle inside a wall or overlapping another) and the
warning about contacts too deep for their law live here too."""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from typing import Any

import numpy as np

from granulate import _core
from granulate.assembly import Assembly, Body
from granulate.contact import Contact
from granulate.errors import GranulateWarning, InputError
from granulate.materials import Material
from granulate.walls import Surface, Wall


def core_law(contact: Contact) -> _core.ContactLaw:
    """The core law: Rc and kn absolute when given, else relative to the two particles
    (factor x the finer mesh size; factor x the default kn of the finer horizon)."""
    law = _core.ContactLaw()
    law.contact_radius = contact.contact_radius or 0.0
    law.contact_radius_factor = contact.contact_radius_factor
    law.normal_stiffness = contact.normal_stiffness or 0.0
    law.stiffness_factor = contact.stiffness_factor
    law.damping_ratio = _core.damping_ratio_from_restitution(contact.restitution)
    law.friction = contact.friction
    law.tangential_stiffness_ratio = contact.tangential_stiffness_ratio
    law.rolling_friction = contact.rolling_friction
    law.rolling_damping = contact.rolling_damping
    law.peridem_friction = contact.friction_law == "peridem"
    law.node_pair = contact.pair_law == "peridem"
    law.surface = contact.pair_law == "surface"
    return law


#: PeriDEM's damping acts between two particles whose centres are closer than the sum of
#: their radii and this factor times the pair's contact radius (contact/peridem_damping.hpp).
PERIDEM_CENTRE_REACH = 1.01


def _checked_contact(contact: Contact | None) -> Contact | None:
    if contact is not None and not isinstance(contact, Contact):
        raise InputError(
            f"contact must be a granulate.Contact or None, got {type(contact).__name__}"
        )
    return contact


class Interactions:
    """Contact laws, walls and PeriDEM damping of one simulation (Simulation.contact,
    set_contact, add_wall, set_neighbor_skin, set_peridem_damping, set_peridem_walls)."""

    def __init__(self, assembly: Assembly) -> None:
        self._assembly = assembly
        self.contact: Contact | None = Contact()
        self.pair_contacts: dict[tuple[int, int], Contact | None] = {}
        self.peridem_damping: dict[tuple[int, int], tuple[float, float]] = {}
        self.peridem_walls: list[Body | str] = []
        self.walls: list[tuple[str, Wall]] = []
        self.skin: float | None = None
        self._deep_contact_level = 0  # 1: warned past half of Rc, 2: past Rc
        # PeriDEM damping's contact radius per pair of materials, fixed by the whole assembly
        # for a subset of it (on()); else found from this assembly's bodies (_peridem_radius).
        self._peridem_radii: dict[tuple[int, int], float] = {}

    def on(self, assembly: Assembly) -> Interactions:
        """The same laws, walls, skin and PeriDEM damping for another assembly (a subset of
        this one's, holding the same materials): the damping's contact radii stay the ones
        this assembly gives, its wall bodies the subset's bodies of the same names."""
        other = Interactions(assembly)
        other.contact = self.contact
        other.pair_contacts = dict(self.pair_contacts)
        other.walls = list(self.walls)
        other.skin = self.skin
        other.peridem_damping = dict(self.peridem_damping)
        other._peridem_radii = self._peridem_pair_radii()
        held = {body.name for body in assembly.bodies}
        walls = (self._assembly.body(b).name for b in self.peridem_walls)
        other.peridem_walls = [name for name in walls if name in held]
        return other

    @property
    def wall_names(self) -> list[str]:
        return [name for name, _ in self.walls]

    def set_default(self, contact: Contact | None) -> None:
        self.contact = _checked_contact(contact)

    def set_pair(self, a: Material, b: Material, contact: Contact | None) -> None:
        contact = _checked_contact(contact)
        self.pair_contacts[(id(a), id(b))] = contact
        self.pair_contacts[(id(b), id(a))] = contact

    def law_between(self, a: Material, b: Material) -> Contact | None:
        """The contact between bodies of materials a and b: theirs, else the default."""
        return self.pair_contacts.get((id(a), id(b)), self.contact)

    def set_peridem_damping(
        self, a: Material, b: Material, epsilon: float, beta_factor: float
    ) -> None:
        if not (0 < epsilon <= 1):
            raise InputError(f"epsilon must be in (0, 1], got {epsilon}")
        if not (beta_factor >= 0 and np.isfinite(beta_factor)):
            raise InputError(f"beta_factor must be a non-negative number, got {beta_factor}")
        self.peridem_damping[(id(a), id(b))] = (float(epsilon), float(beta_factor))
        self.peridem_damping[(id(b), id(a))] = (float(epsilon), float(beta_factor))

    def set_skin(self, skin: float) -> None:
        if not (np.isfinite(skin) and skin > 0):
            raise InputError(f"skin must be a positive length, got {skin}")
        self.skin = float(skin)

    def add_wall(self, wall: Wall | Surface, name: str | None, dimension: int) -> str:
        if isinstance(wall, Surface):
            wall = Wall((wall,))
        if not isinstance(wall, Wall):
            raise InputError(
                f"add_wall takes a granulate Wall or surface, got {type(wall).__name__}"
            )
        label = name or wall.name or f"wall{len(self.walls)}"
        if label in self.wall_names:
            raise InputError(f"a wall named {label!r} exists already; give each wall its own name")
        if not label.replace("_", "").isalnum():
            raise InputError(f"wall name {label!r} must be letters, digits and underscores")
        wall.core(label, dimension)  # checks the description now, not at the first run
        self.walls.append((label, wall))
        return label

    def contact_free(self) -> bool:
        """Whether nothing touches anything: no wall, no PeriDEM damping and no contact law
        between the materials of any two bodies (a distributed run may then cut the bodies
        at node level, granulate.parallel.node_split)."""
        materials = list(
            {id(body.material): body.material for body in self._assembly.bodies}.values()
        )
        laws = (self.law_between(a, b) for k, a in enumerate(materials) for b in materials[: k + 1])
        return not self.walls and not self.peridem_damping and all(law is None for law in laws)

    def uses_surface_law(self) -> bool:
        """Whether any contact law (the default, or one set per pair of materials) is the
        surface law."""
        laws = [self.contact, *self.pair_contacts.values()]
        return any(law is not None and law.pair_law == "surface" for law in laws)

    def apply(self, core: _core.Simulation, materials: Sequence[Material]) -> None:
        """Laws for every pair of materials and every (wall, material), the walls, the skin
        and PeriDEM's damping, into the core (`materials` in core order)."""
        for a, material_a in enumerate(materials):
            for b, material_b in enumerate(materials[: a + 1]):
                contact = self.law_between(material_a, material_b)
                if contact is not None:
                    core.set_contact_law(a, b, core_law(contact))
        for name, wall in self.walls:
            index = core.add_wall(wall.core(name, self._assembly.dimension))
            contact = wall.contact or self.contact or Contact()
            for a in range(len(materials)):
                core.set_wall_law(index, a, core_law(contact))
        if self.skin is not None:
            core.set_contact_skin(self.skin)
        if self.peridem_damping:
            self._apply_peridem_damping(core, materials)

    def _apply_peridem_damping(self, core: _core.Simulation, materials: Sequence[Material]) -> None:
        """PeriDEM's damping per pair of core materials: beta_n = factor x (-2 ln e /
        sqrt(pi^2 + ln^2 e)), the harmonic mean of the bulk moduli, the contact radius
        (contact/peridem_damping.hpp)."""
        walls = set(self.peridem_wall_indices())
        centers, radii = self._assembly.centres_and_radii()
        count = len(materials)
        betan, kappa, radius = np.zeros((3, count, count))
        for a, material_a in enumerate(materials):
            for b, material_b in enumerate(materials):
                setting = self.peridem_damping.get((id(material_a), id(material_b)))
                if setting is None:
                    continue
                epsilon, factor = setting
                radius[a, b] = self._peridem_radius(material_a, material_b)
                log_e = np.log(epsilon)
                betan[a, b] = factor * (-2 * log_e / np.sqrt(np.pi**2 + log_e**2))
                k_a, k_b = material_a.elastic_moduli()[0], material_b.elastic_moduli()[0]
                kappa[a, b] = 2 * k_a * k_b / (k_a + k_b)  # PeriDEM's harmonic mean
        bodies = self._assembly.bodies
        core.set_peridem_damping(
            np.asarray(centers, dtype=np.uint32),
            np.asarray(radii),
            np.asarray([1 if k in walls else 0 for k in range(len(bodies))], dtype=np.uint32),
            betan.ravel(),
            kappa.ravel(),
            radius.ravel(),
        )

    def peridem_wall_indices(self) -> list[int]:
        """The bodies PeriDEM's damping takes for walls (set_peridem_walls), by index."""
        return sorted(self._assembly.body(b).index for b in self.peridem_walls)

    def peridem_reach(self) -> float:
        """How far apart PeriDEM's damping acts at most [m], beyond the particles' radii
        between their centre nodes, and between a node and a wall node: 1.01 times the
        largest of its contact radii (contact/peridem_damping.hpp); 0 without it."""
        return PERIDEM_CENTRE_REACH * max(self._peridem_pair_radii().values(), default=0.0)

    def _peridem_pair_radii(self) -> dict[tuple[int, int], float]:
        """PeriDEM damping's contact radius for each pair of materials it is set for whose
        materials this assembly's bodies use (_peridem_radius), keyed as peridem_damping."""
        materials = {id(body.material): body.material for body in self._assembly.bodies}
        return {
            (a, b): self._peridem_radius(materials[a], materials[b])
            for a, b in self.peridem_damping
            if a in materials and b in materials
        }

    def _peridem_radius(self, a: Material, b: Material) -> float:
        """The contact radius PeriDEM's damping uses between materials a and b: the law's, or
        its factor times the smallest mesh size among particles of the two materials."""
        fixed = self._peridem_radii.get((id(a), id(b)))
        if fixed is not None:
            return fixed
        contact = self.law_between(a, b)
        if contact is None:
            raise InputError("PeriDEM damping is set for a pair of materials without contact")
        if contact.contact_radius is not None:
            return contact.contact_radius
        sizes = [
            body.mesh_size
            for body in self._assembly.bodies
            if body.material is a or body.material is b
        ]
        return contact.contact_radius_factor * min(sizes, default=0.0)

    def check_start(self, model: _core.Model, core: _core.Simulation, dimension: int) -> None:
        """Refuse particles that start outside their container (inside an obstacle) or
        overlapping each other by more than half a mesh size."""
        bodies, owner = self._assembly.bodies, model.node_particle
        node, wall = core.first_wall_penetration()
        if node < model.node_count:
            body = bodies[owner[node]]
            where = ", ".join(f"{c:.4g}" for c in model.reference_positions[node][:dimension])
            raise InputError(
                f"{body.name} starts on the wrong side of wall {self.walls[wall][0]!r} (its "
                f"node {node} at ({where})); place it inside the container, or outside the "
                "obstacle"
            )
        i, j = core.first_overlap(0.5)
        if i < model.node_count:
            a, b = bodies[owner[i]], bodies[owner[j]]
            raise InputError(
                f"{a.name} and {b.name} overlap at the start (at nodes {i} and {j}, by more "
                "than half a mesh size); move them apart, or generate the assembly with "
                "granulate.pack, which never overlaps"
            )

    def warn_deep_contact(self, statistics: Any) -> None:
        """Warn when two bodies pressed into each other by more than half their contact radius
        Rc (node spheres: a node pair's overlap; surface law: a probe's depth under the other's
        surface): the contact layer is too soft for the impact or the load, and nodes may pass
        through each other (an impact's overlap falls as 1 / sqrt(stiffness_factor), a steady
        load's as 1 / stiffness_factor); and again, more strongly, past a whole Rc, where the
        contact gives way: node spheres' centres cross, and the surface law's probes reach the
        end of its points' reach (about a mesh size deep: 1.0-1.2 Rc at the default contact
        radius), lose their push and are pulled in. Each warning is given once per run.
        `statistics`: the core's contact_statistics (deepest_overlap, half_overlap_step,
        full_overlap_step), or a distributed run's over its ranks."""
        deepest = statistics.deepest_overlap
        level = 2 if deepest >= 1 else 1 if deepest >= 0.5 else 0
        if level <= self._deep_contact_level:
            return
        self._deep_contact_level = level
        remedy = (
            "Raise Contact(stiffness_factor=...): an impact's overlap falls as 1/sqrt of it (10 "
            "keeps a 10 m/s impact of soft grains to a fifth), a steady load's as 1/its value; a "
            "stiffer contact shortens the time step"
        )
        pressed = f"bodies pressed {deepest:.0%} of their contact radius into each other"
        if level == 2:
            message = (
                f"contact gave way: {pressed} (past 100% at step {statistics.full_overlap_step}), "
                "through the contact layer; their nodes pass into each other, where no contact "
                "holds them, so broken bonds and stresses from then on come from that overlap, not "
                "from the loads. "
            )
        else:
            message = (
                f"contact: {pressed} (past 50% at step {statistics.half_overlap_step}); the "
                "contact layer is too soft for these impacts or loads and nodes may pass through "
                "each other. "
            )
        warnings.warn(message + remedy, GranulateWarning, stacklevel=4)

    def fingerprint_parts(self, materials: Sequence[Material]) -> list[str]:
        """The walls, laws and PeriDEM damping as text for a checkpoint's fingerprint;
        materials named by their core order, not by object identity."""
        order = {id(m): k for k, m in enumerate(materials)}
        pairs = sorted(
            (order[a], order[b], repr(contact))
            for (a, b), contact in self.pair_contacts.items()
            if a in order and b in order
        )
        damping = sorted(
            (order[a], order[b], setting)
            for (a, b), setting in self.peridem_damping.items()
            if a in order and b in order
        )
        walls = self.peridem_wall_indices()
        return [repr(self.walls), repr(self.contact), repr(pairs), repr(damping), repr(walls)]
