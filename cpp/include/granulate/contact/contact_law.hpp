// Node-to-node (and node-to-wall) contact: normal spring, damping, Coulomb friction.
//
// Two nodes i, j interact when R = |x_j - x_i| < Rc and no intact bond joins them. With
// n = (x_j - x_i)/R, overlap delta_n = Rc - R and node volumes V_i, V_j, the contact between two
// bodies is the sum of three sub-models:
//   normal:   F_n = k_ij delta_n on each node pair, k_ij = kn V_i V_j [N; N/m in 2D], along -n.
//   damping:  one dashpot per pair of touching bodies, F_d = 2 zeta sqrt(M K_s) dx/dt along the
//             mean contact normal, applied to each body as a uniform acceleration. dx/dt is the
//             approach speed of the bodies, M their reduced mass (a particle's own mass against a
//             wall), K_s = F / x the secant stiffness of the collision (total spring force over the
//             approach x since the bodies touched; at most the sum K of the springs). A collision
//             lasts until x is back to 0, through the gaps where chattering surface nodes part for
//             a few steps (contacts much stiffer than the material). zeta follows
//             from the requested coefficient of restitution of a linear spring-dashpot:
//             zeta = -ln e / sqrt(pi^2 + ln^2 e). Acting on the bodies rather than on the contact
//             nodes, the dashpot dissipates c (dx/dt)^2 whatever the bodies' deformation, so a
//             collision of deformable bodies rebounds with e (checked in tests/validation).
//             Fragments of one particle are damped node pair by node pair instead
//             (c_ij = 2 zeta k_ij sqrt(M / K), force clipped at zero).
//   friction: F_t = -mu F_n min(1, |v_t| / v_slip) v_t / |v_t| on each node pair, v_t the
//             tangential velocity of i relative to j (regularised Coulomb: no chatter near zero slip).
//             Law::peridem_friction gives PeriDEM's +mu F_n v_t / |v_t| instead (comparisons only).
// The force density on node i is F / V_i. Every term comes in equal and opposite pairs, so
// Newton's third law holds to round-off.
#pragma once

#include <cmath>
#include <numbers>

#include "granulate/types.hpp"

namespace granulate::contact {

/// Contact parameters of a pair of materials (or of a material and a wall), SI units. The
/// contact radius and the normal stiffness are either absolute or relative to the two particles
/// in contact (see resolve), so one law serves particles of every size.
struct Law {
  real contact_radius = 0;         ///< Rc [m]; 0: contact_radius_factor x the finer mesh size
  real contact_radius_factor = 0;  ///< Rc / h, used when contact_radius is 0
  real normal_stiffness = 0;       ///< kn [N/m^7 in 3D; N/m^6 in 2D]; 0: stiffness_factor x default
  real stiffness_factor = 0;       ///< multiplies the default kn, used when normal_stiffness is 0
  real damping_ratio = 0;          ///< zeta, from the restitution coefficient
  real friction = 0;               ///< mu
  real slip_velocity = 1e-4;       ///< v_slip [m/s] of the friction regularisation
  /// PeriDEM's friction, for comparisons only: mu F_n along +v_t (it speeds sliding up), not
  /// regularised. See friction_force.
  bool peridem_friction = false;
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
};

/// The finer of two particles (smaller h; on a tie, the smaller horizon), so laws are symmetric.
inline const ContactSide& finer(const ContactSide& a, const ContactSide& b) {
  if (a.mesh_size != b.mesh_size) return a.mesh_size < b.mesh_size ? a : b;
  return a.horizon <= b.horizon ? a : b;
}

/// Rc of a law between particles a and b: absolute, or factor x the finer mesh size.
inline real resolve_contact_radius(const Law& law, const ContactSide& a, const ContactSide& b) {
  return law.contact_radius > 0 ? law.contact_radius : law.contact_radius_factor * finer(a, b).mesh_size;
}

/// Rc and kn of a law between particles a and b (a particle and a wall: pass it twice). The
/// default kn is the stiffness of a peridynamic bond one horizon long (PMB micromodulus,
/// constant influence) for the harmonic mean of the moduli: 18 K_eff / (pi delta^5) in 3D,
/// 12 kappa_eff / (pi delta^4) in 2D, K_eff = 2 K_a K_b / (K_a + K_b), delta the finer
/// particle's horizon.
inline PairLaw resolve(const Law& law, const ContactSide& a, const ContactSide& b, int dimension) {
  PairLaw out;
  out.contact_radius = resolve_contact_radius(law, a, b);
  if (law.normal_stiffness > 0) {
    out.normal_stiffness = law.normal_stiffness;
  } else {
    const real effective = 2 * a.modulus * b.modulus / (a.modulus + b.modulus);
    const real delta = finer(a, b).horizon;
    const real delta4 = delta * delta * delta * delta;
    out.normal_stiffness =
        law.stiffness_factor * (dimension == 3 ? 18 * effective / (std::numbers::pi * delta4 * delta)
                                               : 12 * effective / (std::numbers::pi * delta4));
  }
  return out;
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

/// Friction sub-model: tangential force [N] on i, written into force[3], from the tangential
/// velocity of i relative to j and the (non-negative) normal force.
inline void friction_force(const Law& law, real normal, const real tangential_velocity[3], real force[3]) {
  const real speed = std::sqrt(tangential_velocity[0] * tangential_velocity[0] +
                               tangential_velocity[1] * tangential_velocity[1] +
                               tangential_velocity[2] * tangential_velocity[2]);
  if (!(speed > 0) || law.friction == 0 || normal == 0) {
    force[0] = force[1] = force[2] = 0;
    return;
  }
  if (law.peridem_friction) {  // PeriDEM's sign: along the slip, full mu F_n at any speed
    for (int k = 0; k < 3; ++k) force[k] = law.friction * normal * tangential_velocity[k] / speed;
    return;
  }
  const real magnitude = law.friction * normal * std::min(1.0, speed / law.slip_velocity);
  for (int k = 0; k < 3; ++k) force[k] = -magnitude * tangential_velocity[k] / speed;
}

}  // namespace granulate::contact
