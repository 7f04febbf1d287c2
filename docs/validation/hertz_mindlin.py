"""The rebound of a rigid sphere from a rigid plane under the Hertz-Mindlin contact law of DEM
codes: the reference curve of Chung & Ooi's (2011, Granular Matter 13:643) oblique impact
tests in the sticking regime, where the rigid-body impulse theory has no answer.

The contact (sphere radius R, mass m, inertia 2/5 m R^2; plane rigid):
- normal: Hertz, F_n = k_n d^1.5 with k_n = 4/3 E* sqrt(R), E* = E / (1 - nu^2), plus the
  dashpot of Tsuji, Tanaka & Ishida (1992), alpha sqrt(m k_n) d^0.25 dd/dt, alpha chosen so
  that a normal impact rebounds with the restitution e asked for; the total is kept >= 0;
- tangential: Mindlin's no-slip stiffness k_t = 8 G* a, a = sqrt(R d), G* = G / (2 - nu), on
  the contact point's tangential displacement xi since the touch, F_t = -k_t xi, capped by
  Coulomb, |F_t| <= mu F_n (xi truncated there): the Hertz-Mindlin (no slip) law of LIGGGHTS,
  EDEM and Kratos DEM, which Chung & Ooi's DEM results use. No tangential damping.

In gross sliding this gives the rigid-body impulse theory's rebound; where the contact point
sticks, the elastic tangential spring sends it back (Maw, Barber & Fawcett 1976), by an amount
set by k_t / k_n = 2 (1 - nu) / (2 - nu) at equal approach.

`rebound(...)` integrates one impact (symplectic Euler, 4,000 steps per Hertz contact time).
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Sphere:
    """A sphere of radius [m], density [kg/m^3], Young's modulus [Pa] and Poisson ratio."""

    radius: float
    density: float
    youngs_modulus: float
    poisson_ratio: float

    @property
    def mass(self) -> float:
        return self.density * 4.0 / 3.0 * math.pi * self.radius**3

    @property
    def k_n(self) -> float:
        """Hertz's 4/3 E* sqrt(R) for a sphere on a rigid plane [N/m^1.5]."""
        e_star = self.youngs_modulus / (1 - self.poisson_ratio**2)
        return 4.0 / 3.0 * e_star * math.sqrt(self.radius)

    @property
    def g_star(self) -> float:
        """G / (2 - nu) for a sphere on a rigid plane [Pa]."""
        shear = self.youngs_modulus / (2 * (1 + self.poisson_ratio))
        return shear / (2 - self.poisson_ratio)


def contact_time(sphere: Sphere, v_n: float) -> float:
    """Hertz's duration of an elastic impact, 3.2145 (m / k_n)^0.4 v_n^-0.2 [s]."""
    return 3.2145 * (sphere.mass / sphere.k_n) ** 0.4 * v_n**-0.2


def rebound(
    sphere: Sphere, v_n: float, v_t: float, spin: float, mu: float, alpha: float
) -> tuple[float, float, float]:
    """One impact at normal speed v_n > 0 and tangential speed v_t [m/s], the sphere turning at
    omega R = `spin` (positive rolling forwards, towards +v_t). Returns (e, v_t', omega' R)."""
    m, radius, k_n = sphere.mass, sphere.radius, sphere.k_n
    inertia = 0.4 * m * radius**2
    dt = contact_time(sphere, v_n) / 4000
    depth, speed, tangential, rolling, xi = 0.0, v_n, v_t, spin, 0.0  # speed: d(depth)/dt
    for _ in range(40_000):
        normal = k_n * depth**1.5 + alpha * math.sqrt(m * k_n) * depth**0.25 * speed
        normal = max(normal, 0.0)
        k_t = 8 * sphere.g_star * math.sqrt(radius * depth)
        xi += (tangential - rolling) * dt  # the contact point's slip velocity u = v_t - omega R
        friction = -k_t * xi
        if abs(friction) > mu * normal:
            friction = math.copysign(mu * normal, friction)
            xi = -friction / k_t if k_t > 0 else 0.0
        speed -= normal / m * dt
        tangential += friction / m * dt
        rolling -= friction * radius**2 / inertia * dt
        depth += speed * dt
        if depth <= 0.0:
            return -speed / v_n, tangential, rolling
    raise RuntimeError("the impact did not end within 10 contact times")


def damping_for(sphere: Sphere, v_n: float, restitution: float) -> float:
    """Tsuji's alpha giving a normal impact the restitution asked for (bisection, 1e-4 in e)."""
    low, high = 0.0, 5.0
    for _ in range(40):
        alpha = 0.5 * (low + high)
        e = rebound(sphere, v_n, 0.0, 0.0, 0.0, alpha)[0]
        if abs(e - restitution) < 1e-4:
            return alpha
        low, high = (alpha, high) if e > restitution else (low, alpha)
    return alpha
