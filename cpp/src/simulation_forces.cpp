// The forces of one step (Simulation::compute_forces): the bond passes (dilatation and breaking,
// then the pair forces, over BondSchedule's coloured blocks), body forces and damping, contact,
// nodal force densities.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>

#include "bond_extension.hpp"
#include "granulate/in_parallel.hpp"
#include "granulate/peridynamics/critical_stretch.hpp"
#include "granulate/peridynamics/lps.hpp"
#include "granulate/peridynamics/pmb.hpp"
#include "granulate/simulation.hpp"

namespace granulate {

namespace {

/// Adds V_j J beta r e of node i's forward bonds to i's sum and V_i J beta r e to j's (the sums
/// of w r e in the dilatation); with Gather, of all i's bonds to i's sum only; with ToOwn, of
/// i's forward bonds to the nodes `foreign` does not flag only (i a foreign node). With
/// CanBreak, a bond past the critical stretch breaks instead: its bit at i is cleared and
/// (i, j) is appended to `broken` (by the lower-numbered end only, when both ends evaluate it).
template <bool CanBreak, bool Gather, bool ToOwn = false>
void add_dilatation_terms(index_t i, const NodeBonds& bonds, std::uint8_t* bond_bits,
                          CriticalStretch criterion, const real* x, const real* volumes, real* sums,
                          std::vector<std::array<index_t, 2>>& broken,
                          const std::uint8_t* foreign = nullptr) {
  const real volume_i = volumes[i];
  real sum = 0;
  for (index_t b = Gather ? 0 : bonds.forward; b < bonds.count; ++b) {
    if (!BondStates::intact(bond_bits, b)) continue;
    const index_t j = bonds.neighbor(b);
    if constexpr (ToOwn) {
      if (foreign[j]) continue;
    }
    const real r = bonds.length(b);
    const real e = bond_extension(i, j, r, x);
    if constexpr (CanBreak) {
      if (criterion.breaks(e / r)) [[unlikely]] {
        BondStates::clear(bond_bits, b);
        if (!Gather || j > i) broken.push_back({i, j});
        continue;
      }
    }
    const real term = lps::dilatation_term(bonds.influence_weight(b), r, e);
    sum += volumes[j] * term;
    if constexpr (!Gather) sums[j] += volume_i * term;
  }
  sums[i] += sum;
}

/// Runs body(i) for every node, colour by colour, the blocks of a colour in parallel (inside an
/// in_parallel region). Each bond is evaluated once, at its lower-numbered end, and its terms are
/// added to both ends; the colours keep concurrent blocks on disjoint nodes (see BondSchedule), so
/// there are no atomics and the sums do not depend on the thread count. Nodes of a particle that
/// gathers evaluate all their bonds and write only their own sums. Only the blocks at places
/// [from, to) of schedule.blocks, when given: the sums do not change when the blocks are walked
/// in several such calls, in order, since those of one colour never share a node.
template <class Body>
void for_each_node_in_colours(const BondSchedule& schedule, Body&& body, std::int64_t from = 0,
                              std::int64_t to = std::numeric_limits<std::int64_t>::max()) {
  for (std::size_t c = 0; c + 1 < schedule.colour_offsets.size(); ++c) {
    const std::int64_t first = std::max<std::int64_t>(schedule.colour_offsets[c], from);
    const std::int64_t last = std::min<std::int64_t>(schedule.colour_offsets[c + 1], to);
    if (first >= last) continue;  // the same for every thread
#pragma omp for schedule(dynamic, 1)
    for (std::int64_t k = first; k < last; ++k) {
      const index_t block = schedule.blocks[k];
      for (index_t i = schedule.block_starts[block]; i < schedule.block_starts[block + 1]; ++i) body(i);
    }
  }
}

/// for_each_node_in_colours over the blocks at places [from, to) of `inner`'s blocks followed
/// by `outer`'s (inside an in_parallel region).
template <class Body>
void for_each_node_in_schedules(const BondSchedule& inner, const BondSchedule& outer, Body&& body,
                                std::int64_t from, std::int64_t to) {
  const auto count = static_cast<std::int64_t>(inner.blocks.size());
  for_each_node_in_colours(inner, body, from, to);
  if (to > count) for_each_node_in_colours(outer, body, from - count, to - count);
}

/// What the pair-force loop reads and writes, as raw pointers (kept in registers).
struct PairForceArrays {
  const real* positions;
  const real* volumes;
  const real* pressures;
  const lps::NodeCoefficients* coefficients;
  const real* pmb_stiffness;
  real* forces;
};

/// Adds the pair forces of node i's forward bonds to both ends: w_ij s y/|y| to i and
/// -w_ji s y/|y| to j, with s the LPS (Lps) or PMB scalar force state of the bond without its
/// weight and w_ij = J beta_ij V_j; with Gather, of all i's bonds to i only; with ToOwn, of its
/// forward bonds to the nodes `foreign` does not flag only (i a foreign node).
template <bool Lps, bool Gather, bool ToOwn = false>
void add_pair_forces(index_t i, const NodeBonds& bonds, const std::uint8_t* bond_bits, PairForceArrays a,
                     const std::uint8_t* foreign = nullptr) {
  const real* const x = a.positions;
  real* const f = a.forces;
  const real pressure_i = Lps ? a.pressures[i] : 0;
  const real deviatoric_i = Lps ? a.coefficients[i].deviatoric_stiffness : 0;
  const real stiffness_i = Lps ? 0 : a.pmb_stiffness[i];
  const real volume_i = a.volumes[i];
  const real* const xi = x + 3 * std::size_t{i};
  real fx = 0, fy = 0, fz = 0;
  for (index_t b = Gather ? 0 : bonds.forward; b < bonds.count; ++b) {
    if (!BondStates::intact(bond_bits, b)) continue;
    const index_t j = bonds.neighbor(b);
    if constexpr (ToOwn) {
      if (foreign[j]) continue;
    }
    const real* const xj = x + 3 * std::size_t{j};  // one base register for the three components
    const real dx = xj[0] - xi[0], dy = xj[1] - xi[1], dz = xj[2] - xi[2];
    const real length = std::sqrt(dx * dx + dy * dy + dz * dz);
    if (!(length > 0)) continue;
    const real r = bonds.length(b);
    const real omega = bonds.influence_weight(b);
    const real e = length - r;
    real scalar;
    if constexpr (Lps) {
      scalar = lps::pair_force(omega, r, e, pressure_i, a.pressures[j], deviatoric_i,
                               a.coefficients[j].deviatoric_stiffness);
    } else {
      scalar = pmb::pair_force(stiffness_i + a.pmb_stiffness[j], omega, e / r);
    }
    const real over = scalar / length;
    const real gx = over * dx, gy = over * dy, gz = over * dz;
    const real volume_j = a.volumes[j];
    fx += volume_j * gx;
    fy += volume_j * gy;
    fz += volume_j * gz;
    if constexpr (!Gather) {
      real* const fj = f + 3 * std::size_t{j};
      fj[0] -= volume_i * gx;
      fj[1] -= volume_i * gy;
      fj[2] -= volume_i * gz;
    }
  }
  real* const fi = f + 3 * std::size_t{i};
  fi[0] += fx;
  fi[1] += fy;
  fi[2] += fz;
}

}  // namespace

void Simulation::add_bond_forces(real* forces, std::int64_t from, std::int64_t to) const {
  // Pass 2: pair forces, w_ij s y/|y| on i and -w_ji s y/|y| on j (w_ij = J beta V_j), from the
  // pressures of pass 1. Ghost particles are skipped (set_ghost_particles), and of a foreign
  // node only its forward bonds to own nodes are evaluated (set_foreign_nodes).
  const Model& m = *model_;
  const BondSchedule& schedule = m.bond_schedule();
  const PairForceArrays arrays{state_.positions.data(),     m.volumes().data(),       pressure_.data(),
                               m.lps_coefficients().data(), m.pmb_stiffness().data(), forces};
  const std::uint8_t* const ghost = ghost_.empty() ? nullptr : ghost_.data();
  const std::uint8_t* const foreign = foreign_.empty() ? nullptr : foreign_.data();
  const auto evaluate = [&](index_t i) {
    if (ghost && ghost[m.node_particle()[i]]) return;  // another process's forces
    const NodeBonds bonds = m.node_bonds(i);
    const bool lps = m.materials()[m.node_material()[i]].params.model == ForceModel::lps;
    const bool gathers = schedule.particle_gathers[m.node_particle()[i]];
    const std::uint8_t* const bits = state_.bonds.node(i);
    if (foreign && foreign[i]) {  // its terms on own nodes; own nodes that gather take their own
      if (gathers || foreign[i] == far_foreign) return;
      if (lps) {
        add_pair_forces<true, false, true>(i, bonds, bits, arrays, foreign);
      } else {
        add_pair_forces<false, false, true>(i, bonds, bits, arrays, foreign);
      }
    } else if (lps && !gathers) {
      add_pair_forces<true, false>(i, bonds, bits, arrays);
    } else if (!gathers) {
      add_pair_forces<false, false>(i, bonds, bits, arrays);
    } else if (lps) {
      add_pair_forces<true, true>(i, bonds, bits, arrays);
    } else {
      add_pair_forces<false, true>(i, bonds, bits, arrays);
    }
  };
  in_parallel([&] { for_each_node_in_schedules(inner_schedule(), outer_schedule_, evaluate, from, to); });
}

std::vector<real> Simulation::bond_force_densities() const {
  std::vector<real> forces(state_.positions.size(), 0.0);
  if (forces_current_) add_bond_forces(forces.data());
  return forces;
}

void Simulation::compute_forces() {
  update_kinematic_nodes();
  sum_dilatation_and_break_bonds();  // pass 1
  finish_forces({});
}

void Simulation::finish_forces(std::span<const std::array<index_t, 2>> ghost_breaks) {
  if (blocks_evaluated_ == pass_not_begun) {
    start_node_forces(NodeGroup::both);
    blocks_evaluated_ = 0;
  } else {
    start_node_forces(NodeGroup::halo);  // evaluate_bonds started the own nodes
  }
  add_bond_forces(state_.forces.data(), blocks_evaluated_);  // what evaluate_bonds left
  blocks_evaluated_ = pass_not_begun;
  const std::size_t own = breaks_.size();
  break_ghost_bonds(ghost_breaks);
  if (!breaks_.empty()) ++bond_changes_;
  contact_.bonds_broke(*model_, state_, std::span(breaks_).subspan(own));
  broken_bond_copies_ +=
      2 * (foreign_.empty()
               ? breaks_.size()
               : static_cast<std::size_t>(std::count_if(
                     breaks_.begin(), breaks_.end(), [&](const auto& pair) { return !foreign_[pair[0]]; })));
  add_contact_forces();
  add_nodal_forces();
  forces_current_ = true;
}

void Simulation::sum_dilatation_and_break_bonds() {
  // Pass 1: stretch, irreversible breaking, sum_j w r e at both ends. A bond breaks at the end
  // that evaluates it; its other copy is cleared here, after every block, before any loop reads
  // it (when both ends gather, both see bitwise the same stretch and each clears its own). The
  // bonds broken are left in breaks_ for finish_forces, and the anchors they change are taken
  // anew here, so that a step's list positions are settled once it has begun.
  sum_dilatation_terms(std::numeric_limits<std::int64_t>::max());
  dilatation_blocks_ = pass_not_begun;
  const Model& m = *model_;
  for (const auto& [i, j] : breaks_) {
    const NodeBonds bonds = m.node_bonds(j);
    BondStates::clear(state_.bonds.node(j), bonds.find(i));
  }
  contact_.bonds_broke(m, state_, breaks_);
}

void Simulation::sum_dilatation_terms(std::int64_t to) {
  // Ghost particles are skipped (set_ghost_particles): their breaks come from their owners; of
  // a foreign node only its forward bonds to own nodes are evaluated (set_foreign_nodes).
  const Model& m = *model_;
  const auto& materials = m.materials();
  const auto& node_material = m.node_material();
  auto& intact = state_.bonds;
  const std::int64_t n = m.node_count();
  const BondSchedule& schedule = m.bond_schedule();
  const real* const positions = state_.positions.data();
  const real* const volumes = m.volumes().data();
  real* const dilatation_sums = state_.dilatation.data();
  const std::uint8_t* const ghost = ghost_.empty() ? nullptr : ghost_.data();
  const std::uint8_t* const foreign = foreign_.empty() ? nullptr : foreign_.data();
  const bool begins = dilatation_blocks_ == pass_not_begun;
  const std::int64_t from = begins ? 0 : dilatation_blocks_;
  to = std::min(to, block_count());
  if (begins) breaks_.clear();  // (evaluating node, neighbour)
  dilatation_blocks_ = std::max(from, to);
  if (!begins && to <= from) return;
  const auto evaluate = [&](index_t i, std::vector<std::array<index_t, 2>>& broken_here) {
    const Material& material = materials[node_material[i]];
    const NodeBonds bonds = m.node_bonds(i);
    const CriticalStretch criterion{m.particles()[m.node_particle()[i]].critical_stretch,
                                    material.params.break_in_compression};
    const bool breaks = material.params.fracture, gathers = schedule.particle_gathers[m.node_particle()[i]];
    if (ghost && ghost[m.node_particle()[i]]) return;  // another process's bonds
    std::uint8_t* const bits = intact.node(i);
    if (foreign && foreign[i]) {  // its terms on own nodes; own nodes that gather take their own
      if (gathers || foreign[i] == far_foreign) return;
      if (breaks) {
        add_dilatation_terms<true, false, true>(i, bonds, bits, criterion, positions, volumes,
                                                dilatation_sums, broken_here, foreign);
      } else {
        add_dilatation_terms<false, false, true>(i, bonds, bits, criterion, positions, volumes,
                                                 dilatation_sums, broken_here, foreign);
      }
    } else if (breaks && !gathers) {
      add_dilatation_terms<true, false>(i, bonds, bits, criterion, positions, volumes, dilatation_sums,
                                        broken_here);
    } else if (!gathers) {
      add_dilatation_terms<false, false>(i, bonds, bits, criterion, positions, volumes, dilatation_sums,
                                         broken_here);
    } else if (breaks) {
      add_dilatation_terms<true, true>(i, bonds, bits, criterion, positions, volumes, dilatation_sums,
                                       broken_here);
    } else {
      add_dilatation_terms<false, true>(i, bonds, bits, criterion, positions, volumes, dilatation_sums,
                                        broken_here);
    }
  };
  in_parallel([&] {
    if (begins) {
#pragma omp for schedule(static)
      for (std::int64_t i = 0; i < n; ++i) dilatation_sums[i] = 0;
    }
    std::vector<std::array<index_t, 2>> broken_here;
    for_each_node_in_schedules(
        inner_schedule(), outer_schedule_, [&](index_t i) { evaluate(i, broken_here); }, from, to);
    if (!broken_here.empty()) {
#pragma omp critical(granulate_broken_bonds)
      breaks_.insert(breaks_.end(), broken_here.begin(), broken_here.end());
    }
  });
}

void Simulation::start_node_forces(NodeGroup group) {
  // Dilatation and pressure of LPS nodes; body forces and damping start each node's sum.
  const Model& m = *model_;
  const auto& materials = m.materials();
  const auto& node_material = m.node_material();
  const auto& lps_coefficients = m.lps_coefficients();
  auto& f = state_.forces;
  auto& theta = state_.dilatation;
  const std::int64_t n = m.node_count();
  const auto g = body_acceleration_;
  const std::uint8_t* const foreign = foreign_.empty() ? nullptr : foreign_.data();
  in_parallel([&] {
#pragma omp for schedule(static)
    for (std::int64_t ii = 0; ii < n; ++ii) {
      const index_t i = static_cast<index_t>(ii);
      if (foreign && foreign[i] == far_foreign) continue;  // nothing here reads it
      const bool halo = foreign && foreign[i];
      if ((group == NodeGroup::own && halo) || (group == NodeGroup::halo && !halo)) continue;
      if (materials[node_material[i]].params.model == ForceModel::lps) {
        theta[i] *= lps_coefficients[i].dilatation_scale;
        pressure_[i] = lps_coefficients[i].dilatation_coupling * theta[i];
      } else {
        theta[i] = 0;
      }
      const real* vi = &state_.velocities[3 * i];
      const real density = materials[node_material[i]].params.density;
      f[3 * i] = density * (g[0] - viscous_damping_ * vi[0]);
      f[3 * i + 1] = density * (g[1] - viscous_damping_ * vi[1]);
      f[3 * i + 2] = density * (g[2] - viscous_damping_ * vi[2]);
    }
  });
}

void Simulation::add_contact_forces() {
  const auto contact_start = std::chrono::steady_clock::now();
  contact_.add_forces(*model_, state_, broken_bond_copies_);
  peridem_damping_.add_forces(*model_, state_);
  phase_times_.contact +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - contact_start).count();
  phase_times_.contact_search = contact_.search_seconds();
}

void Simulation::add_nodal_forces() {
  auto& f = state_.forces;
  const real t = state_.time;
  for (const NodalForce& load : nodal_forces_) {
    const real scale = load.function.value(t);
    for (index_t i : load.nodes) {
      for (int c = 0; c < 3; ++c) f[3 * i + c] += scale * load.vector[c];
    }
  }
}

}  // namespace granulate
