// Prototype microelastic brittle model (bond-based): the per-bond evaluator.
//
// Silling & Askari, Computers & Structures 83 (2005). With stretch s = e / r, influence-weighted
// volume w_ij = J(r/delta) V_j beta_ij and pair micromodulus c_ij = k_i + k_j:
//   f_i = sum_j c_ij w_ij s y/|y|                                (force density)
//   W_i = (1/2) sum_j (c_ij/2) w_ij s^2 r                        (energy density)
// k_i = d^2 kappa_d / mu_i with mu_i = sum_j w_ij r_ij (the node's discrete moment), so that a
// node with a complete family reproduces the classical energy d^2 kappa_d eps^2 / 2 of an
// isotropic expansion exactly (the continuum c = 2 d^2 kappa_d / int J r dV underestimates the
// lattice stiffness by 10-13 % at horizon 3h because of the partial volumes). As for LPS, the
// force loops pass weight = J beta and multiply by the volume of the other end.
#pragma once

#include "granulate/types.hpp"

namespace granulate::pmb {

/// Scalar pair force density along y/|y|.
inline real pair_force(real pair_micromodulus, real weight, real stretch) {
  return pair_micromodulus * weight * stretch;
}

/// One bond's contribution to the energy density W_i.
inline real energy_term(real pair_micromodulus, real weight, real stretch, real length) {
  return 0.25 * pair_micromodulus * weight * stretch * stretch * length;
}

}  // namespace granulate::pmb
