"""Contact parameters between particles, and between particles and walls.

Every node is a contact sphere of radius rho_i = contact_radius_factor x h_i / 2 (h_i: its
particle's mesh size), reaching the particle's surface (a node that lies on the surface, a
mesh's or grid's boundary vertex, has its sphere centred rho_i inside it). Two nodes interact
when they are closer than Rc = rho_i + rho_j and no intact bond joins them (nodes of different
particles, or of fragments of one particle); a node touches a wall closer than rho_i. The
pair force is a spring kn (Rc - R) min(V_i, V_j)^2, a dashpot sized so that two bodies
colliding head-on rebound with the requested coefficient of restitution (acting on both bodies
at the contact point; its damping ratio is fitted to each collision's force-approach law,
which stiffens as a curved grain's contact widens), and Coulomb friction with stick: a
tangential spring per contact (Cundall & Strack), capped at mu F_n, acting on the particles'
surfaces (see cpp/include/granulate/contact/contact_law.hpp for the formulas). Particles of
different sizes meshed with the same nodes per radius collide like equal ones; a particle at
rest sits at its radius.

Defaults: contact_radius_factor 0.95; kn = c / delta, the stiffness of a peridynamic bond one
horizon long (PMB micromodulus c, constant influence) for the harmonic mean of the two moduli:
18 K_eff / (pi delta^5) in 3D and 12 kappa_eff / (pi delta^4) in 2D (kappa: the planar bulk
modulus), with delta the horizon of the finer particle. Both are resolved per pair of particles
in the core (contact::resolve), so particles of any size share one law. This kn keeps the time
step near the peridynamic one but makes the contact layer softer than the grains; for Hertzian
contacts (the grains' elasticity governing) raise stiffness_factor to about 100: a sphere
squeezed between plates then carries 0.97 of Hertz's force (0.073 with the default; see
ARCHITECTURE.md, "Choosing kn"). Under the surface law a confined compression to a wall stress
sigma wants at least 1000 sigma / K, or its contacts give way (docs/parameters.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from granulate.errors import InputError
from granulate.input_errors import checked_arguments


@checked_arguments
@dataclass(frozen=True)
class Contact:
    """Contact parameters.

    Attributes:
        restitution: coefficient of restitution e of a head-on collision, in (0, 1].
        friction: Coulomb friction coefficient mu >= 0.
        contact_radius_factor: each node's contact radius is factor x h / 2 of its own
            particle (default 0.95), so a node pair's Rc is factor x (h_i + h_j) / 2.
        contact_radius: absolute Rc [m] of a node pair (each node's radius Rc / 2);
            overrides the factor.
        normal_stiffness: absolute kn [N/m^7 in 3D, N/m^6 in 2D]; overrides the default.
        stiffness_factor: multiplies the default kn. A run warns when bodies press into each
            other by half their contact radius (the layer too soft for the impacts; nodes may
            pass through each other), and again past the whole radius (the contact gave way):
            raise it then.
        tangential_stiffness_ratio: kt / kn of the friction spring of each contact (Cundall &
            Strack), in (0, 1]; default 2/7.
        rolling_friction: coefficient of rolling resistance mu_r >= 0 (default 0: none), for
            calibrations in the habits of rigid-grain DEM (LIGGGHTS' coefficientRollingFriction;
            the elastic-plastic spring-dashpot of Ai et al. 2011, model C): per pair of touching
            bodies, a spring on their relative rolling rotation, k_r = kt R*^2, whose torque is
            capped at mu_r R* F_n (R* the effective rolling radius, from each body's centre to
            the contact point; F_n the normal force), and a dashpot while it holds. A disc at
            rest on a slope of tan(a) <= mu_r does not roll; above, it rolls down at
            g (sin a - mu_r cos a) / (1 + I / (m R^2)) (a coarse sphere, resting on one node,
            still creeps slowly: ARCHITECTURE.md). Deformable grains already resist rolling a
            little through their flattened contacts; mu_r adds to that.
        rolling_damping: eta_r in [0, 1], the rolling dashpot's share of its critical damping
            2 sqrt(I_r k_r) (default 0.3; it damps a grain rocking on a contact of few nodes).
            Only with rolling_friction > 0.
        friction_law: "coulomb" (default: the friction spring), or "peridem": PeriDEM's
            friction, mu |F_n| along the slip velocity (it speeds sliding up instead of
            resisting it); for comparisons with PeriDEM only.
        pair_law: "surface" (default: each surface node probes the other particle's smooth
            surface, from its surface points, normals and curvatures, and walls see a round
            particle on its circle: no node-scale bumps or gaps, so rotated lattices and grains
            of different mesh sizes collide as round grains do; see ARCHITECTURE.md),
            "granulate" (every node a sphere of its own contact radius, springs
            kn min(V_i, V_j)^2: 1.6-2.8 times cheaper in the contact phase, for assemblies where
            sideways kicks of 10-30 % of an impact's speed and rolling on the nodes' polygon do
            not matter, and the law of earlier versions), or "peridem": PeriDEM's node-pair
            law, one Rc per pair of particles (factor x the finer mesh size, also against
            walls) and springs kn V_i V_j; for comparisons with PeriDEM only (set by
            --peridem-compat).
    """

    restitution: float = 1.0
    friction: float = 0.0
    contact_radius_factor: float = 0.95
    contact_radius: float | None = None
    normal_stiffness: float | None = None
    stiffness_factor: float = 1.0
    tangential_stiffness_ratio: float = 2.0 / 7.0
    rolling_friction: float = 0.0
    rolling_damping: float = 0.3
    friction_law: str = "coulomb"
    pair_law: str = "surface"

    def __post_init__(self) -> None:
        if self.pair_law not in ("granulate", "surface", "peridem"):
            raise InputError(
                f"pair_law must be 'granulate', 'surface' or 'peridem', got {self.pair_law!r}"
            )
        if self.friction_law not in ("coulomb", "peridem"):
            raise InputError(
                f"friction_law must be 'coulomb' or 'peridem', got {self.friction_law!r}"
            )
        if not 0 < self.restitution <= 1:
            raise InputError(f"restitution must be in (0, 1], got {self.restitution}")
        for name in ("friction", "rolling_friction"):
            value = getattr(self, name)
            if not (value >= 0 and math.isfinite(value)):
                raise InputError(f"{name} must be a non-negative number, got {value}")
        if not 0 <= self.rolling_damping <= 1:
            raise InputError(f"rolling_damping must be in [0, 1], got {self.rolling_damping}")
        if not 0 < self.tangential_stiffness_ratio <= 1:
            raise InputError(
                "tangential_stiffness_ratio must be in (0, 1], got "
                f"{self.tangential_stiffness_ratio}"
            )
        for name in ("contact_radius_factor", "stiffness_factor"):
            value = getattr(self, name)
            if not (value > 0 and math.isfinite(value)):
                raise InputError(f"{name} must be positive, got {value}")
        for name in ("contact_radius", "normal_stiffness"):
            value = getattr(self, name)
            if value is not None and not (value > 0 and math.isfinite(value)):
                raise InputError(f"{name} must be positive, got {value}")
