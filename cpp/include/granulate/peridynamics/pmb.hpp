// Prototype microelastic brittle model (bond-based): the per-bond evaluator.
//
// Silling & Askari, Computers & Structures 83 (2005). With stretch s = e / r, micromodulus c
// and influence-weighted volume w_ij = J(r/delta) V_j beta_ij:
//   f_i = sum_j c w_ij s y/|y|                                   (force density)
//   W_i = (1/2) sum_j (c/2) w_ij s^2 r                           (energy density)
// c = 18 K / int J r dV in 3D and 8 kappa_d / int J r dA in 2D (see material.hpp).
#pragma once

#include "granulate/types.hpp"

namespace granulate::pmb {

/// Scalar pair force density along y/|y|.
inline real pair_force(real micromodulus, real weight, real stretch) {
  return micromodulus * weight * stretch;
}

/// One bond's contribution to the energy density W_i.
inline real energy_term(real micromodulus, real weight, real stretch, real length) {
  return 0.25 * micromodulus * weight * stretch * stretch * length;
}

}  // namespace granulate::pmb
