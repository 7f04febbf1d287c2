// Linear peridynamic solid (state-based): the per-bond evaluator.
//
// Silling, Epton, Weckner, Xu, Askari, J. Elasticity 88 (2007); 2D constants from
// Le, Silling, Bobaru, Int. J. Numer. Meth. Eng. 98 (2014). With r = |X_j - X_i|,
// e = |x_j - x_i| - r, influence-weighted volume w_ij = J(r/delta) V_j beta_ij (beta: partial
// volume) and m_i = sum_j w_ij r^2:
//   theta_i = (d / m_i) sum_j w_ij r e                                   (dilatation, -)
//   t_ij    = A_i theta_i r + B_i e,  A_i = (d kappa_d - a_d G / d) / m_i,  B_i = a_d G / m_i
//   f_i     = sum_j w_ij (t_ij + t_ji) y / |y|                 (force density, N/m^3)
//   W_i     = kappa_d theta_i^2 / 2 + (a_d G / (2 m_i)) sum_j w_ij (e - theta_i r / d)^2
// which equals t_ij = (d kappa_d theta / m) J r + (a_d G / m) J (e - theta r / d) of DESIGN.md.
// kappa_d and a_d: 3D K and 15; plane strain K + G/3 and 8; plane stress 9KG/(3K+4G) and 8.
// The force loops pass weight = J beta (symmetric in i and j) and multiply by V_j for node i and
// by V_i for node j, so one evaluation of a bond serves both ends (Simulation::compute_forces).
#pragma once

#include "granulate/types.hpp"

namespace granulate::lps {

/// Per-node constants, fixed after Model::finalize().
struct NodeCoefficients {
  real dilatation_scale = 0;      ///< d / m_i                      [1/m^(d+2)]
  real dilatation_coupling = 0;   ///< A_i = (d kappa_d - a_d G/d)/m_i [Pa/m^(d+2)]
  real deviatoric_stiffness = 0;  ///< B_i = a_d G / m_i            [Pa/m^(d+2)]
};

/// One bond's contribution to sum_j w r e (multiply the sum by d/m_i to get theta_i).
inline real dilatation_term(real weight, real length, real extension) {
  return weight * length * extension;
}

/// Scalar pair force density w_ij (t_ij + t_ji) along y/|y|; pressure_k = A_k theta_k.
inline real pair_force(real weight, real length, real extension, real pressure_i, real pressure_j,
                       real deviatoric_i, real deviatoric_j) {
  return weight * ((pressure_i + pressure_j) * length + (deviatoric_i + deviatoric_j) * extension);
}

/// One bond's term of sum_j w (e - theta r / d)^2 in W_i.
inline real deviatoric_energy_term(real weight, real length, real extension, real theta,
                                   real inverse_dimension) {
  const real deviatoric_extension = extension - theta * length * inverse_dimension;
  return weight * deviatoric_extension * deviatoric_extension;
}

}  // namespace granulate::lps
