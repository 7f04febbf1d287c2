// Node-to-node (and node-to-wall) contact: normal spring, damping, Coulomb friction with stick.
//
// Each node i has a contact radius rho_i = factor h_i / 2 (h_i: its particle's mesh size), so its
// contact sphere reaches the particle's surface (a lattice's or ring discretisation's outer nodes
// lie h/2 inside it; a node that lies on the surface, a mesh's or grid's boundary vertex, has
// its sphere centred rho_i below it, see surface_anchors.hpp). Two nodes i, j interact when
// R = |x_j - x_i| < Rc = rho_i + rho_j and no intact bond joins them; a node touches a wall when
// its distance D to the surface is < rho_i.
// With n = (x_j - x_i)/R and the overlap delta = Rc - R, the contact is the sum of three
// sub-models:
//   normal:   F_n = k_ij delta on each node pair along -n, k_ij = kn min(V_i, V_j)^2 [N/m; N/m^2
//             per unit thickness in 2D]: a fine particle's surface node meets about one node of a
//             coarse particle, so the contact is as stiff per unit area whatever the two meshes.
//             Per pair of bodies, the resultant of these springs is turned into the surfaces'
//             normal by rigid-body loads that do no work (ContactModel::slot_redirects).
//   damping:  one dashpot per pair of touching bodies, F_d = 2 zeta sqrt(M K_s) dx/dt along the
//             mean contact normal m, acting at the collision's contact point p (the spring-weighted
//             mean of the node pairs' contact points) on each body as a rigid-body load: every
//             node of the body gets rho_i (F / M + alpha x (x_i - c)), alpha = I^-1 (p - c) x F,
//             with c, M, I the body's centre, mass and inertia tensor. The two bodies get equal
//             and opposite forces at one point, so linear and angular momentum are conserved to
//             round-off. dx/dt is the bodies' approach speed at p along m (their rigid-body
//             velocities there, rotation included), M their reduced mass (a particle's own mass
//             against a wall), K_s = F / x the secant stiffness of the collision (total spring
//             force over the approach x since the bodies touched; at most the sum K of the
//             springs). As the bodies part, F_d is clipped at -F (the springs' force): the
//             contact never pulls them together. A collision lasts until x is back to 0,
//             through the gaps where chattering surface nodes part for a few steps. zeta gives
//             the requested coefficient of restitution e for the collision's force law F ~ x^p,
//             p = F x / W - 1 measured from the springs' work W while the bodies approach,
//             clipped force and all (power_law_damping.hpp; unclipped, linear springs would
//             have zeta = -ln e / sqrt(pi^2 + ln^2 e)). PeriDEM's node-pair law
//             (--peridem-compat) keeps that zeta, unclipped. Acting on the bodies rather than
//             on the contact nodes, the dashpot dissipates c (dx/dt)^2 whatever the bodies'
//             deformation, so a collision of deformable bodies rebounds with e (checked in
//             tests/validation).
//             Fragments of one particle are damped node pair by node pair instead
//             (c_ij = 2 zeta k_ij sqrt(M / K), force clipped at zero).
//   friction: Cundall & Strack (1979): a tangential spring kt = ratio x k_ij on the tangential
//             displacement xi of the contact point since the pair touched, capped at mu F_n (then
//             xi is shortened: sliding). The contact point is the middle of the overlap,
//             p = x_i + (rho_i - delta / 2) n, on the particles' surfaces: its slip is the nodes'
//             relative velocity plus each body's rotation times the node's lever to p, and the
//             force acts there (the node gets it, its body the couple (p - x_i) x F_t as a
//             rigid-body load), so a disc rolls on its radius and both bodies are pushed at one
//             point (no torque on the pair). xi is kept per node pair (and per node-wall entry)
//             across neighbour-list rebuilds and checkpoints. Law::peridem_friction gives
//             PeriDEM's +mu F_n v_t / |v_t| instead (comparisons only).
//   rolling:  optional rolling resistance (mu_r > 0), the elastic-plastic spring-dashpot of
//             Ai et al. (2011, Powder Technol. 206:269, model C) with the spring of Iwashita &
//             Oda (1998, EPSD2): per pair of touching bodies, the relative rolling rotation
//             theta accumulates (omega_p - omega_q) dt, turned into the plane normal to the
//             collision's normal (torsion excluded); the torque on p is M = -k_r theta - C_r
//             omega_roll, k_r = k_t R*^2 (k_t = ratio x the sum K of the pair's springs), the
//             spring capped at mu_r R* F_n (then theta shrinks and the dashpot is off: the
//             bodies roll against a constant torque). C_r = 2 eta_r sqrt(I_r k_r), with 1/I_r =
//             sum over the bodies of 1 / (I + m r^2) (I about the rolling axis). R* = r_p r_q /
//             (r_p + r_q), r the distance from each body's centre to the contact point (r_p
//             against a wall); F_n the sum of the pair's spring forces. p gets M and q -M as
//             rigid-body couples, so angular momentum is conserved to round-off. A body
//             without rotational inertia (a one-node fragment) takes none. theta is kept per
//             pair of bodies across list rebuilds, the gaps of a collision and checkpoints, and
//             reset when they part.
// The force density on node i is F / V_i. Every term comes in equal and opposite pairs, so
// Newton's third law holds to round-off.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include "granulate/types.hpp"

namespace granulate::contact {

/// Contact parameters of a pair of materials (or of a material and a wall), SI units. The
/// contact radius and the normal stiffness are either absolute or relative to the two particles
/// in contact (see resolve), so one law serves particles of every size.
struct Law {
  real contact_radius = 0;         ///< Rc of a node pair [m]; 0: from contact_radius_factor
  real contact_radius_factor = 0;  ///< each node's contact radius / its mesh size x 2 (see resolve)
  real normal_stiffness = 0;       ///< kn [N/m^7 in 3D; N/m^6 in 2D]; 0: stiffness_factor x default
  real stiffness_factor = 0;       ///< multiplies the default kn, used when normal_stiffness is 0
  real damping_ratio = 0;          ///< zeta, from the restitution coefficient
  real friction = 0;               ///< mu
  real tangential_stiffness_ratio = 2.0 / 7.0;  ///< kt / k_ij of the friction spring
  real rolling_friction = 0;                    ///< mu_r of the rolling resistance (0: none)
  real rolling_damping = 0.3;                   ///< eta_r, the rolling dashpot's damping ratio
  /// PeriDEM's friction, for comparisons only: mu F_n along +v_t (it speeds sliding up), no
  /// stick. See peridem_friction_force.
  bool peridem_friction = false;
  /// PeriDEM's node-pair law (--peridem-compat): one Rc for a pair of particles, factor x the
  /// finer mesh size (also against walls), and pair springs kn V_i V_j. Otherwise each node has
  /// its own contact radius (see resolve) and the pair spring is kn min(V_i, V_j)^2.
  bool node_pair = false;
  /// The surface law (contact/surface_law.hpp): each node on a particle's surface probes the
  /// other particle's smooth surface, built from its surface points, normals and curvatures,
  /// instead of meeting its nodes' spheres. Particles without surface points (meshes without
  /// elements), crack faces and debris still meet as spheres.
  bool surface = false;
};

/// One particle's side of a contact.
struct ContactSide {
  real mesh_size = 0;  ///< h [m]
  real horizon = 0;    ///< delta [m]
  real modulus = 0;    ///< kappa_d [Pa] (K in 3D, the planar bulk modulus in 2D)
};

/// Rc [m] and kn of a law between particles a and b (a particle and a wall: pass it twice).
struct PairLaw {
  real contact_radius = 0;
  real normal_stiffness = 0;
  bool node_pair = false;               ///< PeriDEM's pair spring kn V_i V_j (else kn min(V_i, V_j)^2)
  bool surface = false;                 ///< the surface law (see Law::surface)
  real rolling_friction = 0;            ///< mu_r (see Law::rolling_friction)
  real rolling_damping = 0;             ///< eta_r (see Law::rolling_damping)
  real tangential_stiffness_ratio = 0;  ///< kt / k_ij, for the rolling stiffness
};

/// The finer of two particles (smaller h; on a tie, the smaller horizon), so laws are symmetric.
inline const ContactSide& finer(const ContactSide& a, const ContactSide& b) {
  if (a.mesh_size != b.mesh_size) return a.mesh_size < b.mesh_size ? a : b;
  return a.horizon <= b.horizon ? a : b;
}

/// Contact radius of one node of particle a [m]: factor x h_a / 2. A lattice's or a conforming
/// discretisation's outermost nodes lie h/2 inside the surface, so with the default factor
/// (0.95) a node's contact sphere reaches (almost) to the particle's surface, whatever the mesh
/// size: two particles touch where their surfaces meet, and a particle rests on a wall at its
/// radius. An absolute Rc gives each node Rc / 2.
inline real node_contact_radius(const Law& law, const ContactSide& a) {
  return law.contact_radius > 0 ? 0.5 * law.contact_radius : 0.5 * law.contact_radius_factor * a.mesh_size;
}

/// Rc of a node pair of particles a and b: the sum of the two nodes' contact radii, so a coarse
/// particle's nodes reach as far as its own spacing requires and a fine particle's nodes cannot
/// slip between them (PeriDEM's node-pair law: absolute, or factor x the finer mesh size).
inline real resolve_contact_radius(const Law& law, const ContactSide& a, const ContactSide& b) {
  if (law.node_pair) {
    return law.contact_radius > 0 ? law.contact_radius : law.contact_radius_factor * finer(a, b).mesh_size;
  }
  return node_contact_radius(law, a) + node_contact_radius(law, b);
}

/// Node a's share of a pair's Rc (its contact radius, for the contact point): h_a / (h_a + h_b)
/// of Rc with a relative radius, half of it with an absolute one or PeriDEM's node-pair law.
inline real node_share(const Law& law, const ContactSide& a, const ContactSide& b, real contact_radius) {
  if (law.node_pair || law.contact_radius > 0) return 0.5 * contact_radius;
  return contact_radius * a.mesh_size / (a.mesh_size + b.mesh_size);
}

/// Default kn of a law between particles a and b: the stiffness of a peridynamic bond one horizon
/// long (PMB micromodulus, constant influence) for the harmonic mean of the moduli:
/// 18 K_eff / (pi delta^5) in 3D, 12 kappa_eff / (pi delta^4) in 2D,
/// K_eff = 2 K_a K_b / (K_a + K_b), delta the finer particle's horizon.
inline real resolve_normal_stiffness(const Law& law, const ContactSide& a, const ContactSide& b,
                                     int dimension) {
  if (law.normal_stiffness > 0) return law.normal_stiffness;
  const real effective = 2 * a.modulus * b.modulus / (a.modulus + b.modulus);
  const real delta = finer(a, b).horizon;
  const real delta4 = delta * delta * delta * delta;
  return law.stiffness_factor * (dimension == 3 ? 18 * effective / (std::numbers::pi * delta4 * delta)
                                                : 12 * effective / (std::numbers::pi * delta4));
}

/// A law resolved to contact radius `rc` and stiffness `kn`, with its other terms as given.
inline PairLaw resolved(const Law& law, real rc, real kn, bool surface) {
  return {rc,
          kn,
          law.node_pair,
          surface,
          law.rolling_friction,
          law.rolling_damping,
          law.tangential_stiffness_ratio};
}

/// Rc and kn of a law between particles a and b.
inline PairLaw resolve(const Law& law, const ContactSide& a, const ContactSide& b, int dimension) {
  return resolved(law, resolve_contact_radius(law, a, b), resolve_normal_stiffness(law, a, b, dimension),
                  law.surface);
}

/// Rc of a node of particle a against a rigid wall surface: the node's own contact radius
/// (PeriDEM's node-pair law: the pair Rc).
inline real resolve_wall_contact_radius(const Law& law, const ContactSide& a) {
  return law.node_pair ? resolve_contact_radius(law, a, a) : node_contact_radius(law, a);
}

/// Rc (node to wall surface) and kn of a law between particle a and a rigid wall.
inline PairLaw resolve_wall(const Law& law, const ContactSide& a, int dimension) {
  return resolved(law, resolve_wall_contact_radius(law, a), resolve_normal_stiffness(law, a, a, dimension),
                  false);
}

/// Spring stiffness of a node pair [N/m]: kn min(V_i, V_j)^2, so a fine particle's nodes against
/// a coarse particle's are as stiff per unit of contact area as against nodes of their own size
/// (each fine surface node meets about one coarse node). PeriDEM's node-pair law: kn V_i V_j.
inline real pair_stiffness(const PairLaw& law, real volume_i, real volume_j) {
  if (law.node_pair) return law.normal_stiffness * volume_i * volume_j;
  const real smaller = std::min(volume_i, volume_j);
  return law.normal_stiffness * smaller * smaller;
}

/// zeta of a linear spring-dashpot with restitution e (0 < e <= 1).
inline real damping_ratio_from_restitution(real e) {
  if (e >= 1) return 0;
  const real log_e = std::log(e);
  return -log_e / std::sqrt(std::numbers::pi * std::numbers::pi + log_e * log_e);
}

/// Normal sub-model: spring force magnitude [N] (positive pushes the nodes apart).
inline real normal_force(real pair_stiffness, real overlap) {
  return pair_stiffness * overlap;
}

/// Damping sub-model: dashpot force magnitude [N] for an approach speed (positive when closing).
inline real damping_force(real pair_damping, real approach_speed) {
  return pair_damping * approach_speed;
}

/// PeriDEM's friction (comparisons only): mu F_n along the tangential velocity of i relative to
/// j, written into force[3]; it speeds sliding up instead of resisting it.
inline void peridem_friction_force(real mu, real normal, const real tangential_velocity[3], real force[3]) {
  const real speed = std::sqrt(tangential_velocity[0] * tangential_velocity[0] +
                               tangential_velocity[1] * tangential_velocity[1] +
                               tangential_velocity[2] * tangential_velocity[2]);
  for (int k = 0; k < 3; ++k)
    force[k] = speed > 0 && normal != 0 ? mu * normal * tangential_velocity[k] / speed : 0;
}

/// Friction sub-model (Cundall & Strack 1979): the tangential spring of one contact. `shear` is
/// the contact's tangential displacement xi [m] (i's contact point relative to j's since they
/// touched); it is first turned into the plane normal to the unit `normal` (keeping its length),
/// then advanced by the tangential part of `slip` [m/s] x dt. The force on i is -kt xi, capped at
/// mu F_n (`normal_force`, >= 0): when capped, xi shrinks to the length that carries mu F_n
/// (the contact slides). Writes the force [N] into force[3]; returns whether it was capped. Every
/// operation is odd in (normal, slip, shear), so the pair's other entry computes exactly the
/// opposite force.
inline bool tangential_force(real kt, real mu, real normal_force, const real normal[3], const real slip[3],
                             real dt, real shear[3], real force[3]) {
  const real length = std::sqrt(shear[0] * shear[0] + shear[1] * shear[1] + shear[2] * shear[2]);
  const real along = shear[0] * normal[0] + shear[1] * normal[1] + shear[2] * normal[2];
  for (int k = 0; k < 3; ++k) shear[k] -= along * normal[k];
  const real projected = std::sqrt(shear[0] * shear[0] + shear[1] * shear[1] + shear[2] * shear[2]);
  if (projected > 0) {
    for (int k = 0; k < 3; ++k) shear[k] *= length / projected;
  }
  const real slip_normal = slip[0] * normal[0] + slip[1] * normal[1] + slip[2] * normal[2];
  for (int k = 0; k < 3; ++k) shear[k] += (slip[k] - slip_normal * normal[k]) * dt;
  const real stretched = std::sqrt(shear[0] * shear[0] + shear[1] * shear[1] + shear[2] * shear[2]);
  const real limit = mu * normal_force;
  const bool capped = kt * stretched > limit;
  if (capped) {
    const real scale = stretched > 0 ? limit / (kt * stretched) : 0.0;
    for (int k = 0; k < 3; ++k) shear[k] *= scale;
  }
  for (int k = 0; k < 3; ++k) force[k] = -kt * shear[k];
  return capped;
}

/// Rolling-resistance spring (see the header; the dashpot is added by the caller): advances the relative
/// rolling rotation `rotation` [rad] of a pair of touching bodies by the part of their relative angular
/// velocity `spin` [rad/s] (omega_p - omega_q) normal to `normal`, and writes the torque on p [N m; N m/m in
/// 2D], -k_r rotation capped at mu_r R* F_n, into torque[3]; returns whether it was capped (the bodies roll:
/// no dashpot then). The same spring and cap as the friction spring's (tangential_force), on rotations
/// instead of displacements.
inline bool rolling_torque(real rolling_stiffness, real mu_r, real effective_radius, real normal_force,
                           const real normal[3], const real spin[3], real dt, real rotation[3],
                           real torque[3]) {
  return tangential_force(rolling_stiffness, mu_r * effective_radius, normal_force, normal, spin, dt,
                          rotation, torque);
}

}  // namespace granulate::contact
