#include "granulate/simulation.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <sstream>
#include <utility>

#include "bond_extension.hpp"
#include "granulate/in_parallel.hpp"
#include "granulate/peridynamics/critical_stretch.hpp"
#include "granulate/peridynamics/lps.hpp"
#include "granulate/peridynamics/pmb.hpp"

namespace granulate {
namespace {

using clock_type = std::chrono::steady_clock;

double seconds_since(clock_type::time_point start) {
  return std::chrono::duration<double>(clock_type::now() - start).count();
}

/// The first half kick and the drift, v += dt/2 f/rho, x += dt v, of every node (with
/// SkipOthers, but those `others` flags, other processes' nodes, which their owners move). A
/// template so that a serial run's loop has no test per node.
template <bool SkipOthers>
void kick_and_drift(const Model& m, State& state, real dt, const std::uint8_t* others) {
  const std::int64_t n = m.node_count();
  auto& x = state.positions;
  auto& v = state.velocities;
  const auto& f = state.forces;
  in_parallel([&] {
#pragma omp for schedule(static)
    for (std::int64_t i = 0; i < n; ++i) {
      if constexpr (SkipOthers) {
        if (others[i]) continue;
      }
      const real density = m.density(static_cast<index_t>(i));
      for (std::int64_t k = 3 * i; k < 3 * i + 3; ++k) {
        v[k] += 0.5 * dt * f[k] / density;
        x[k] += dt * v[k];
      }
    }
  });
}

/// The second half kick of every node (with SkipOthers, but other processes' nodes), and the
/// first node that moves more than its mesh size in a step or is not finite (n if none).
template <bool SkipOthers>
std::int64_t second_half_kick(const Model& m, State& state, real dt, const std::uint8_t* others) {
  const std::int64_t n = m.node_count();
  const auto& particles = m.particles();
  const auto& node_particle = m.node_particle();
  auto& v = state.velocities;
  const auto& f = state.forces;
  std::int64_t first_unstable = n;
  in_parallel([&] {
#pragma omp for schedule(static) reduction(min : first_unstable)
    for (std::int64_t i = 0; i < n; ++i) {
      if constexpr (SkipOthers) {
        if (others[i]) continue;
      }
      real speed2 = 0;
      const real density = m.density(static_cast<index_t>(i));
      for (std::int64_t k = 3 * i; k < 3 * i + 3; ++k) {
        v[k] += 0.5 * dt * f[k] / density;
        speed2 += v[k] * v[k];
      }
      const real limit = particles[node_particle[i]].mesh_size / dt;
      if (!(speed2 <= limit * limit)) first_unstable = std::min(first_unstable, i);
    }
  });
  return first_unstable;
}

/// The largest distance of a node (but other processes', which `others` flags per node; null:
/// none) from its place in `origin`, and of the list position of each node in `watched`
/// (ContactModel::list_position) from its row in `list_origin` [m].
real farthest_travel(const Model& m, const State& state, const ContactModel& contact,
                     const std::vector<real>& origin, std::span<const index_t> watched,
                     const std::vector<real>& list_origin, const std::uint8_t* others) {
  const std::int64_t n = m.node_count(), listed = static_cast<std::int64_t>(watched.size());
  auto squared = [](const real* a, const real* b) {
    const real dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    return dx * dx + dy * dy + dz * dz;
  };
  const real* x = state.positions.data();
  real farthest = 0;  // squared
  in_parallel([&] {
#pragma omp for schedule(static) reduction(max : farthest)
    for (std::int64_t i = 0; i < n; ++i) {
      if (!others || !others[i]) farthest = std::max(farthest, squared(&x[3 * i], &origin[3 * i]));
    }
#pragma omp for schedule(static) reduction(max : farthest)
    for (std::int64_t k = 0; k < listed; ++k) {
      const auto seen = contact.list_position(m, state, watched[k]);
      farthest = std::max(farthest, squared(seen.data(), &list_origin[3 * k]));
    }
  });
  return std::sqrt(farthest);
}

}  // namespace

Simulation::Simulation(std::shared_ptr<Model> model) : model_(std::move(model)) {
  if (!model_) throw InputError("simulation needs a model");
  model_->finalize();
  const Model& m = *model_;
  const index_t n = m.node_count();
  state_.positions = m.reference_positions();
  state_.velocities.assign(3 * static_cast<std::size_t>(n), 0);
  state_.forces.assign(3 * static_cast<std::size_t>(n), 0);
  state_.bonds.reset(m.bond_offsets());
  state_.dilatation.assign(n, 0);
  pressure_.assign(n, 0);
  contact_.configure(m);
  stable_time_step_ = m.stable_time_step();
  time_step_ = 0.8 * stable_time_step_;
}

void Simulation::set_time_step(real dt) {
  if (!(dt > 0) || !std::isfinite(dt)) {
    std::ostringstream msg;
    msg << "time step must be positive and finite, got " << dt;
    throw InputError(msg.str());
  }
  time_step_ = dt;
}

void Simulation::set_body_acceleration(const std::array<real, 3>& g) {
  for (real c : g) {
    if (!std::isfinite(c)) throw InputError("body acceleration must be finite");
  }
  if (model_->dimension() == 2 && g[2] != 0) {
    throw InputError("body acceleration has a z component in a 2D model");
  }
  body_acceleration_ = g;
  forces_current_ = false;
}

void Simulation::set_viscous_damping(real gamma) {
  if (!(gamma >= 0) || !std::isfinite(gamma))
    throw InputError("viscous damping must be a non-negative rate in 1/s");
  viscous_damping_ = gamma;
  forces_current_ = false;
}

void Simulation::add_prescribed_motion(PrescribedMotion motion) {
  motion.function.validate();
  for (index_t i : motion.nodes) {
    if (i >= model_->node_count()) {
      throw InputError("prescribed motion names node " + std::to_string(i) + ", but the model has " +
                       std::to_string(model_->node_count()) + " nodes");
    }
  }
  if (motion.kind == PrescribedMotion::Kind::rotation) {
    const real norm = std::sqrt(motion.axis[0] * motion.axis[0] + motion.axis[1] * motion.axis[1] +
                                motion.axis[2] * motion.axis[2]);
    if (!(norm > 0)) throw InputError("rotation axis must be a non-zero vector");
    for (real& c : motion.axis) c /= norm;
    motion.components = 0b111;
  }
  motions_.push_back(std::move(motion));
  kinematic_stale_ = true;
  forces_current_ = false;
}

void Simulation::add_nodal_force(NodalForce force) {
  force.function.validate();
  for (index_t i : force.nodes) {
    if (i >= model_->node_count()) {
      throw InputError("force set names node " + std::to_string(i) + ", but the model has " +
                       std::to_string(model_->node_count()) + " nodes");
    }
  }
  nodal_forces_.push_back(std::move(force));
  forces_current_ = false;
}

void Simulation::apply_prescribed_motion(bool positions_too) {
  const auto& X = model_->reference_positions();
  auto& x = state_.positions;
  auto& v = state_.velocities;
  const real t = state_.time;
  for (const PrescribedMotion& motion : motions_) {
    const real value = motion.function.value(t);
    const real rate = motion.function.rate(t);
    if (motion.kind == PrescribedMotion::Kind::displacement) {
      for (index_t i : motion.nodes) {
        for (int c = 0; c < 3; ++c) {
          if (!(motion.components & (1u << c))) continue;
          if (positions_too) x[3 * i + c] = X[3 * i + c] + value * motion.direction[c];
          v[3 * i + c] = rate * motion.direction[c];
        }
      }
    } else {
      // Rodrigues: R p = p cos a + (k x p) sin a + k (k . p)(1 - cos a)
      const auto& k = motion.axis;
      const real cs = std::cos(value), sn = std::sin(value);
      for (index_t i : motion.nodes) {
        if (positions_too) {
          const real p[3] = {X[3 * i] - motion.center[0], X[3 * i + 1] - motion.center[1],
                             X[3 * i + 2] - motion.center[2]};
          const real kp = k[0] * p[0] + k[1] * p[1] + k[2] * p[2];
          const real kxp[3] = {k[1] * p[2] - k[2] * p[1], k[2] * p[0] - k[0] * p[2],
                               k[0] * p[1] - k[1] * p[0]};
          for (int c = 0; c < 3; ++c) {
            x[3 * i + c] = motion.center[c] + p[c] * cs + kxp[c] * sn + k[c] * kp * (1.0 - cs);
          }
        }
        const real q[3] = {x[3 * i] - motion.center[0], x[3 * i + 1] - motion.center[1],
                           x[3 * i + 2] - motion.center[2]};
        v[3 * i] = rate * (k[1] * q[2] - k[2] * q[1]);
        v[3 * i + 1] = rate * (k[2] * q[0] - k[0] * q[2]);
        v[3 * i + 2] = rate * (k[0] * q[1] - k[1] * q[0]);
      }
    }
  }
}

void Simulation::update_kinematic_nodes() {
  if (!kinematic_stale_) return;  // once after the loading is set, not per motion added
  const std::uint8_t all = model_->dimension() == 2 ? 0b011 : 0b111;
  std::vector<std::uint8_t> kinematic = fixity();
  for (std::uint8_t& k : kinematic) k = (k & all) == all ? 1 : 0;
  contact_.set_kinematic_nodes(std::move(kinematic));
  kinematic_stale_ = false;
}

void Simulation::evaluate_if_stale() {
  if (forces_current_) return;
  apply_prescribed_motion(true);
  compute_forces();
}

void Simulation::run(std::uint64_t steps) {
  if (step_begun_ || moved_) throw InputError("run: the step begun is not finished (finish_step)");
  evaluate_if_stale();
  for (std::uint64_t s = 0; s < steps; ++s) {
    move_and_break_bonds();
    finish_step_after_breaks({});
  }
}

void Simulation::move() {
  if (step_begun_ || moved_) throw InputError("move: the step begun before is not finished (finish_step)");
  if (!forces_current_ && !others_.empty()) {
    throw InputError(
        "move: evaluate the forces (run(0)) before marking ghost particles or foreign nodes, "
        "whose bonds the first evaluation breaks too");
  }
  evaluate_if_stale();
  move_nodes();
  moved_ = true;
}

std::vector<std::array<index_t, 2>> Simulation::begin_step() {
  if (step_begun_) throw InputError("begin_step: the step begun before is not finished (finish_step)");
  if (!moved_) move();
  moved_ = false;
  break_bonds_and_measure_travel();
  step_begun_ = true;
  return breaks_;
}

void Simulation::finish_step(std::span<const std::array<index_t, 2>> ghost_breaks) {
  if (!step_begun_) throw InputError("finish_step without begin_step");
  check_ghost_breaks(ghost_breaks);  // before anything changes: the step can be finished again
  step_begun_ = false;
  finish_step_after_breaks(ghost_breaks);
}

namespace {

/// `share` (0 to 1) of `count` blocks, rounded down; InputError naming `call` outside [0, 1].
std::int64_t share_of_blocks(real share, std::int64_t count, const char* call) {
  if (!(share >= 0 && share <= 1)) {
    throw InputError(std::string(call) + ": the share of the bond blocks must lie in [0, 1], not " +
                     std::to_string(share));
  }
  return static_cast<std::int64_t>(share * static_cast<real>(count));
}

}  // namespace

void Simulation::evaluate_dilatation(real share) {
  if (!moved_) throw InputError("evaluate_dilatation: call it between move and begin_step");
  const std::int64_t to = share_of_blocks(share, inner_block_count(), "evaluate_dilatation");
  const auto start = clock_type::now();
  sum_dilatation_terms(to);
  phase_times_.peridynamics += seconds_since(start);
}

void Simulation::evaluate_bonds(real share) {
  if (!step_begun_) throw InputError("evaluate_bonds: call it between begin_step and finish_step");
  const std::int64_t to = share_of_blocks(share, inner_block_count(), "evaluate_bonds");
  const auto start = clock_type::now();
  if (blocks_evaluated_ == pass_not_begun) {
    start_node_forces(NodeGroup::own);
    blocks_evaluated_ = 0;
  }
  if (to > blocks_evaluated_) {
    add_bond_forces(state_.forces.data(), blocks_evaluated_, to);  // pass 2
    blocks_evaluated_ = to;
  }
  phase_times_.peridynamics += seconds_since(start);
}

void Simulation::move_and_break_bonds() {
  move_nodes();
  break_bonds_and_measure_travel();
}

void Simulation::move_nodes() {
  const real dt = time_step_;
  auto start = clock_type::now();
  if (others_.empty()) {
    kick_and_drift<false>(*model_, state_, dt, nullptr);
  } else {
    kick_and_drift<true>(*model_, state_, dt, others_.data());
  }
  state_.time += dt;
  phase_times_.integration += seconds_since(start);

  start = clock_type::now();
  apply_prescribed_motion(true);
  phase_times_.loading += seconds_since(start);
}

void Simulation::break_bonds_and_measure_travel() {
  auto start = clock_type::now();
  update_kinematic_nodes();
  sum_dilatation_and_break_bonds();  // pass 1
  phase_times_.peridynamics += seconds_since(start);
  if (!travel_origin_.empty()) {  // where the nodes and list positions stay for the step
    largest_travel_ = farthest_travel(*model_, state_, contact_, travel_origin_, list_watched_, list_origin_,
                                      others_.empty() ? nullptr : others_.data());
  }
}

void Simulation::set_travel_origin(std::vector<index_t> watched) {
  for (const index_t i : watched) {
    if (i >= model_->node_count() || others_node(i)) {
      throw InputError("set_travel_origin: node " + std::to_string(i) +
                       " is not one of this process's nodes");
    }
  }
  travel_origin_ = state_.positions;
  list_watched_ = std::move(watched);
  list_origin_.resize(3 * list_watched_.size());
  for (std::size_t k = 0; k < list_watched_.size(); ++k) {
    const auto at = contact_.list_position(*model_, state_, list_watched_[k]);
    std::copy(at.begin(), at.end(), list_origin_.begin() + 3 * static_cast<std::ptrdiff_t>(k));
  }
  largest_travel_ = 0;
}

std::vector<index_t> Simulation::contact_anchors(const std::vector<index_t>& nodes) const {
  std::vector<index_t> found;
  for (const index_t i : nodes) {
    if (i >= model_->node_count()) throw InputError("contact_anchors: no node " + std::to_string(i));
    contact_.anchors_of(*model_, i, found);
  }
  std::sort(found.begin(), found.end());
  found.erase(std::unique(found.begin(), found.end()), found.end());
  return found;
}

std::vector<real> Simulation::list_positions() const {
  std::vector<real> x;
  contact_.fill_list_positions(*model_, state_, x);
  return x;
}

void Simulation::finish_step_after_breaks(std::span<const std::array<index_t, 2>> ghost_breaks) {
  const std::int64_t n = model_->node_count();
  auto start = clock_type::now();
  const double contact_before = phase_times_.contact;
  finish_forces(ghost_breaks);
  phase_times_.peridynamics += seconds_since(start) - (phase_times_.contact - contact_before);

  start = clock_type::now();
  // The second half kick, and the first node (if any) that moved more than its mesh size in
  // the step or became non-finite: checked every step, at the cost of one comparison per node
  // (not on ghosts, which their owners move and check).
  const std::int64_t first_unstable =
      others_.empty() ? second_half_kick<false>(*model_, state_, time_step_, nullptr)
                      : second_half_kick<true>(*model_, state_, time_step_, others_.data());
  apply_prescribed_motion(false);
  ++state_.step;
  if (first_unstable < n) check_stability();  // names the node (a prescribed one is fine)
  phase_times_.integration += seconds_since(start);
}

std::array<std::size_t, 2> Simulation::memory_bytes() const {
  auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  const Model& m = *model_;
  std::size_t bonds = state_.bonds.bit_bytes();
  for (const BondFamilies& f : m.families())
    bonds += bytes(f.neighbors) + bytes(f.weights) + bytes(f.lengths);
  std::size_t other = state_.bonds.offset_bytes() + bytes(state_.positions) + bytes(state_.velocities) +
                      bytes(state_.forces) + bytes(state_.dilatation) + bytes(pressure_) +
                      bytes(travel_origin_) + bytes(m.reference_positions()) + bytes(m.volumes()) +
                      bytes(m.node_particle()) + bytes(m.node_material()) + bytes(m.bond_offsets()) +
                      bytes(m.lps_coefficients()) + bytes(m.pmb_stiffness()) + contact_.memory_bytes();
  for (const BondFamilies& f : m.families()) other += bytes(f.offsets) + bytes(f.forward);
  other += m.bond_schedule().memory_bytes();
  for (const Shape& s : m.shapes()) other += s.anchors.memory_bytes();  // nodes and volumes released
  return {bonds, other};
}

void Simulation::restore(const State& state, const ContactCheckpoint& contact) {
  const std::size_t n = 3 * static_cast<std::size_t>(model_->node_count());
  if (state.positions.size() != n || state.velocities.size() != n || state.forces.size() != n ||
      state.dilatation.size() != model_->node_count()) {
    throw InputError("the checkpoint's state does not match this model (nodes or bonds differ)");
  }
  auto finite = [](const std::vector<real>& v) {
    return std::all_of(v.begin(), v.end(), [](real x) { return std::isfinite(x); });
  };
  if (!finite(state.positions) || !finite(state.velocities) || !finite(state.forces) ||
      !finite(state.dilatation) || !std::isfinite(state.time)) {
    throw InputError("the checkpoint's state holds non-finite values");
  }
  contact_.check_checkpoint(*model_, contact);  // before anything is replaced
  state_ = state;
  update_kinematic_nodes();  // the contact lists are rebuilt below with the held bodies known
  count_broken_bond_copies();
  contact_.restore(*model_, state_, contact);
  forces_current_ = true;
}

void Simulation::check_stability() const {
  const auto& v = state_.velocities;
  const auto& x = state_.positions;
  const index_t n = model_->node_count();
  for (index_t i = 0; i < n; ++i) {
    if (others_node(i)) continue;  // its owner checks it
    const real speed2 = v[3 * i] * v[3 * i] + v[3 * i + 1] * v[3 * i + 1] + v[3 * i + 2] * v[3 * i + 2];
    const bool finite = std::isfinite(speed2) && std::isfinite(x[3 * i]) && std::isfinite(x[3 * i + 1]) &&
                        std::isfinite(x[3 * i + 2]);
    const real mesh_size = model_->particles()[model_->node_particle()[i]].mesh_size;
    if (!finite || std::sqrt(speed2) * time_step_ > mesh_size) {
      std::ostringstream msg;
      msg << "the simulation became unstable at step " << state_.step << " (t = " << state_.time
          << " s): node " << (reported_node_.empty() ? i : reported_node_[i]) << " of particle "
          << (reported_particle_.empty() ? model_->node_particle()[i]
                                         : reported_particle_[model_->node_particle()[i]]);
      if (finite)
        msg << " moves at " << std::sqrt(speed2) << " m/s, more than its mesh size " << mesh_size
            << " m per step";
      else
        msg << " has a non-finite position or velocity";
      const real estimate = reported_stable_time_step_ > 0 ? reported_stable_time_step_ : stable_time_step();
      msg << ". The time step is " << time_step_ << " s and the stable estimate is " << estimate
          << " s; use a smaller time step, a slower loading or smaller initial velocities";
      throw InstabilityError(msg.str());
    }
  }
}

void Simulation::strain_energy_density(real* out) const {
  const Model& m = *model_;
  const real inverse_dimension = 1.0 / m.lps_dimension();
  in_parallel([&] {
#pragma omp for schedule(static)
    for (std::int64_t ii = 0; ii < static_cast<std::int64_t>(m.node_count()); ++ii) {
      const index_t i = static_cast<index_t>(ii);
      if (others_node(i)) {  // another process's: it measures them
        out[i] = 0;
        continue;
      }
      const Material& material = m.materials()[m.node_material()[i]];
      const bool is_lps = material.params.model == ForceModel::lps;
      const real theta = state_.dilatation[i];
      const NodeBonds bonds = m.node_bonds(i);
      real sum = 0;
      for (index_t b = 0; b < bonds.count; ++b) {
        if (!state_.bonds.intact(i, b)) continue;
        const index_t j = bonds.neighbor(b);
        const real r = bonds.length(b);
        const real e = bond_extension(i, j, r, state_.positions.data());
        sum += is_lps
                   ? lps::deviatoric_energy_term(bonds.weight(b), r, e, theta, inverse_dimension)
                   : pmb::energy_term(m.pmb_stiffness()[i] + m.pmb_stiffness()[j], bonds.weight(b), e / r, r);
      }
      out[i] = is_lps ? 0.5 * material.dilatation_modulus * theta * theta +
                            0.5 * m.lps_coefficients()[i].deviatoric_stiffness * sum
                      : sum;
    }
  });
}

real Simulation::strain_energy() const {
  std::vector<real> density(model_->node_count());
  strain_energy_density(density.data());
  const auto& volumes = model_->volumes();
  real total = 0;
  for (std::size_t i = 0; i < density.size(); ++i) total += density[i] * volumes[i];
  return total;
}

void Simulation::damage(real* phi, real* z) const {
  const Model& m = *model_;
  in_parallel([&] {
#pragma omp for schedule(static)
    for (std::int64_t ii = 0; ii < static_cast<std::int64_t>(m.node_count()); ++ii) {
      const index_t i = static_cast<index_t>(ii);
      if (others_node(i)) {  // another process's: it measures them
        if (phi) phi[i] = 0;
        if (z) z[i] = 0;
        continue;
      }
      const real s0 = m.particles()[m.node_particle()[i]].critical_stretch;
      const NodeBonds bonds = m.node_bonds(i);
      real all = 0, intact = 0, max_stretch = 0;
      for (index_t b = 0; b < bonds.count; ++b) {
        const real w = bonds.weight(b);
        all += w;
        if (state_.bonds.intact(i, b)) intact += w;
      }
      for (index_t b = 0; z && b < bonds.count; ++b) {
        const real r = bonds.length(b);
        max_stretch = std::max(
            max_stretch, std::abs(bond_extension(i, bonds.neighbor(b), r, state_.positions.data()) / r));
      }
      if (phi) phi[i] = all > 0 ? 1.0 - intact / all : 0.0;
      if (z) z[i] = std::isfinite(s0) ? max_stretch / s0 : 0.0;
    }
  });
}

void Simulation::break_bonds(const std::vector<std::array<index_t, 2>>& pairs) {
  const Model& m = *model_;
  auto copy_of = [&](index_t i, index_t j) -> std::array<index_t, 2> {  // (node, its bond)
    const auto b = m.bond_between(i, j);
    if (!b) throw InputError("nodes " + std::to_string(i) + " and " + std::to_string(j) + " are not bonded");
    return {i, *b};
  };
  for (const auto& [i, j] : pairs) {
    const auto forward = copy_of(i, j), backward = copy_of(j, i);
    if (state_.bonds.intact(forward[0], forward[1])) {
      BondStates::clear(state_.bonds.node(forward[0]), forward[1]);
      BondStates::clear(state_.bonds.node(backward[0]), backward[1]);
      broken_bond_copies_ += 2;
      ++bond_changes_;
      const std::array<index_t, 2> pair{i, j};
      contact_.bonds_broke(*model_, state_, {&pair, 1});
    }
  }
  forces_current_ = false;
}

void Simulation::count_broken_bond_copies() {
  const Model& m = *model_;
  ++bond_changes_;  // called where the bond states were set anew
  if (foreign_.empty()) {
    broken_bond_copies_ = state_.bonds.broken(m.bond_offsets(), 0, m.node_count());
    return;
  }
  std::uint64_t broken = 0;  // bonds broken whose lower end is own, as finish_forces counts them
  for (index_t i = 0; i < m.node_count(); ++i) {
    if (foreign_[i]) continue;
    const NodeBonds bonds = m.node_bonds(i);
    for (index_t b = bonds.forward; b < bonds.count; ++b) broken += state_.bonds.intact(i, b) ? 0 : 1;
  }
  broken_bond_copies_ = 2 * broken;
}

std::uint64_t Simulation::broken_bonds() const {
  return broken_bond_copies_ / 2;
}

bool Simulation::assign_bonds(const std::vector<std::uint8_t>& states) {
  if (!state_.bonds.assign_unpacked(model_->bond_offsets(), states)) return false;
  count_broken_bond_copies();
  return true;
}

index_t Simulation::fragments(index_t* labels) const {
  return model_->fragments(state_.bonds, labels);
}

std::vector<std::uint8_t> Simulation::fixity() const {
  std::vector<std::uint8_t> mask(model_->node_count(), 0);
  for (const PrescribedMotion& motion : motions_) {
    for (index_t i : motion.nodes) mask[i] |= motion.components;
  }
  return mask;
}

}  // namespace granulate
