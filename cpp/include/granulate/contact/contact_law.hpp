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
//             approach since the bodies touched; at most the sum K of the springs). zeta follows
//             from the requested coefficient of restitution of a linear spring-dashpot:
//             zeta = -ln e / sqrt(pi^2 + ln^2 e). Acting on the bodies rather than on the contact
//             nodes, the dashpot dissipates c (dx/dt)^2 whatever the bodies' deformation, so a
//             collision of deformable bodies rebounds with e (checked in tests/validation).
//             Fragments of one particle are damped node pair by node pair instead
//             (c_ij = 2 zeta k_ij sqrt(M / K), force clipped at zero).
//   friction: F_t = -mu F_n min(1, |v_t| / v_slip) v_t / |v_t| on each node pair, v_t the
//             tangential velocity of i relative to j (regularised Coulomb: no chatter near zero slip).
// The force density on node i is F / V_i. Every term comes in equal and opposite pairs, so
// Newton's third law holds to round-off.
#pragma once

#include <cmath>
#include <numbers>

#include "granulate/types.hpp"

namespace granulate::contact {

/// Contact parameters of a pair of materials (or of a material and a wall), SI units.
struct Law {
  real contact_radius = 0;    ///< Rc [m]
  real normal_stiffness = 0;  ///< kn [N/m^7 in 3D; N/m^5 per unit thickness in 2D]
  real damping_ratio = 0;     ///< zeta, from the restitution coefficient
  real friction = 0;          ///< mu
  real slip_velocity = 1e-4;  ///< v_slip [m/s] of the friction regularisation
};

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
  const real magnitude = law.friction * normal * std::min(1.0, speed / law.slip_velocity);
  for (int k = 0; k < 3; ++k) force[k] = -magnitude * tangential_velocity[k] / speed;
}

}  // namespace granulate::contact
