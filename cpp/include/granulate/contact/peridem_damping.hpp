// PeriDEM's contact damping, reproduced for comparisons with PeriDEM (--peridem-compat).
//
// It is not granulate's damping: it acts between particle centres, and it does not give the
// restitution its epsilon names (measured with PeriDEM's two-disc deck: epsilon 0.5 / 0.8 / 0.95
// gave e = 0.34 / 0.72 / 0.93 with Beta_n_Factor 100 and the lower disc held). This reproduction
// gives e = 0.66 / 0.86 / 0.955 there, for reasons not found yet, but follows PeriDEM's rebound
// in the deck itself (epsilon 0.9) within 7 um (tests/test_peridem.py). Formulas, from DEMModel
// (computeContactForces, setupContact), for a particle P that is not a wall, with centre node c_P
// (position x_P, velocity v_P), bounding radius R_P, density rho_P and A_P = pi R_P^2 (PeriDEM
// uses this area as the particle's volume in 2D and 3D):
//   betan_PQ = Beta_n_Factor * (-2 ln eps) / sqrt(pi^2 + ln^2 eps),
//   kappa_PQ = 2 K_P K_Q / (K_P + K_Q) (PeriDEM's "equivalent mass" is this harmonic mean),
//   particle Q (not a wall) with |x_Q - x_P| < R_P + R_Q + 1.01 Rc_PQ:
//     m_eq = 2 m_P m_Q / (m_P + m_Q), m = rho A;  beta = betan sqrt(kappa Rc m_eq);
//     n = (x_Q - x_P) / |x_Q - x_P|;  f_P += beta min(0, (v_Q - v_P).n) n / A_P
//   each node k of a wall within Rc of a node of P (counted once):
//     m_eq = rho_P A_P;  n = (x_k - x_P) / |x_k - x_P|;  f_P += beta min(0, (v_k - v_P).n) n / A_P
//   f_P, a force density [N/m^3], is added to every node of P.
// The particles Q are summed in particle order and the wall nodes in node order, so a
// distributed run's part, which holds a subset of the particles in the same order, sums its
// own particles' terms as the whole run does (PeriDEM sums in its search's order).
#pragma once

#include <cstdint>
#include <vector>

#include "granulate/model.hpp"
#include "granulate/state.hpp"

namespace granulate::contact {

struct PeridemParticle {
  index_t center = 0;  ///< global id of the centre node
  real radius = 0;     ///< bounding radius R [m]
  bool wall = false;   ///< a wall (PeriDEM's Is_Wall zone): damps particles through its nodes
};

struct PeridemPair {
  real betan = 0;           ///< dimensionless; 0: no damping between these materials
  real kappa = 0;           ///< 2 K_a K_b / (K_a + K_b) [Pa]
  real contact_radius = 0;  ///< Rc [m]
};

class PeridemDamping {
 public:
  /// One entry per particle of the model; pairs: material x material (row-major).
  void configure(const Model& model, std::vector<PeridemParticle> particles, std::vector<PeridemPair> pairs);
  bool active() const { return !particles_.empty(); }
  /// The particles whose damping is not computed (a distributed run's ghosts: their owners
  /// compute it); they still damp the others. Flags per particle, or empty for none.
  void set_ghost_particles(std::vector<std::uint8_t> ghost) { ghost_ = std::move(ghost); }
  /// Adds the damping force densities to state.forces (deterministic for any thread count).
  void add_forces(const Model& model, State& state) const;

 private:
  std::vector<PeridemParticle> particles_;
  std::vector<PeridemPair> pairs_;
  index_t material_count_ = 0;
  real max_radius_ = 0;
  real max_contact_radius_ = 0;
  std::vector<index_t> wall_nodes_;
  std::vector<index_t> centers_;          // centre nodes of the particles that are not walls
  std::vector<index_t> center_particle_;  // node -> particle, read at centre nodes only
  std::vector<std::uint8_t> ghost_;       // per particle, or empty: none
};

}  // namespace granulate::contact
