#include "granulate/simulation.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <sstream>

#include "granulate/peridynamics/critical_stretch.hpp"
#include "granulate/peridynamics/lps.hpp"
#include "granulate/peridynamics/pmb.hpp"

namespace granulate {
namespace {

using clock_type = std::chrono::steady_clock;

double seconds_since(clock_type::time_point start) {
  return std::chrono::duration<double>(clock_type::now() - start).count();
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

real Simulation::stable_time_step() const {
  const real contact = contact_.stable_time_step(*model_);
  if (!std::isfinite(contact)) return stable_time_step_;
  return 1.0 / std::sqrt(1.0 / (stable_time_step_ * stable_time_step_) + 1.0 / (contact * contact));
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

namespace {

/// |x_j - x_i| - length (inline: it is the inner step of the bond loops).
inline real bond_extension(index_t i, index_t j, real length, const real* x) {
  const real* const xi = x + 3 * std::size_t{i};
  const real* const xj = x + 3 * std::size_t{j};
  const real dx = xj[0] - xi[0], dy = xj[1] - xi[1], dz = xj[2] - xi[2];
  return std::sqrt(dx * dx + dy * dy + dz * dz) - length;
}

/// Adds V_j J beta r e of node i's forward bonds to i's sum and V_i J beta r e to j's (the sums
/// of w r e in the dilatation); with Gather, of all i's bonds to i's sum only. With CanBreak, a
/// bond past the critical stretch breaks instead: its bit at i is cleared and (i, j) is
/// appended to `broken` (by the lower-numbered end only, when both ends evaluate it).
template <bool CanBreak, bool Gather>
void add_dilatation_terms(index_t i, const NodeBonds& bonds, std::uint8_t* bond_bits,
                          CriticalStretch criterion, const real* x, const real* volumes, real* sums,
                          std::vector<std::array<index_t, 2>>& broken) {
  const real volume_i = volumes[i];
  real sum = 0;
  for (index_t b = Gather ? 0 : bonds.forward; b < bonds.count; ++b) {
    if (!BondStates::intact(bond_bits, b)) continue;
    const index_t j = bonds.neighbor(b);
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
/// omp parallel region). Each bond is evaluated once, at its lower-numbered end, and its terms are
/// added to both ends; the colours keep concurrent blocks on disjoint nodes (see BondSchedule), so
/// there are no atomics and the sums do not depend on the thread count. Nodes of a particle that
/// gathers evaluate all their bonds and write only their own sums.
template <class Body>
void for_each_node_in_colours(const BondSchedule& schedule, Body&& body) {
  for (std::size_t c = 0; c + 1 < schedule.colour_offsets.size(); ++c) {
    const std::int64_t first = schedule.colour_offsets[c], last = schedule.colour_offsets[c + 1];
#pragma omp for schedule(dynamic, 1)
    for (std::int64_t k = first; k < last; ++k) {
      const index_t block = schedule.blocks[k];
      for (index_t i = schedule.block_starts[block]; i < schedule.block_starts[block + 1]; ++i) body(i);
    }
  }
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
/// weight and w_ij = J beta_ij V_j; with Gather, of all i's bonds to i only.
template <bool Lps, bool Gather>
void add_pair_forces(index_t i, const NodeBonds& bonds, const std::uint8_t* bond_bits, PairForceArrays a) {
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

void Simulation::add_bond_forces(real* forces) const {
  // Pass 2: pair forces, w_ij s y/|y| on i and -w_ji s y/|y| on j (w_ij = J beta V_j), from the
  // pressures of pass 1.
  const Model& m = *model_;
  const BondSchedule& schedule = m.bond_schedule();
  const PairForceArrays arrays{state_.positions.data(),     m.volumes().data(),       pressure_.data(),
                               m.lps_coefficients().data(), m.pmb_stiffness().data(), forces};
#pragma omp parallel
  for_each_node_in_colours(schedule, [&](index_t i) {
    const NodeBonds bonds = m.node_bonds(i);
    const bool lps = m.materials()[m.node_material()[i]].params.model == ForceModel::lps;
    const bool gathers = schedule.particle_gathers[m.node_particle()[i]];
    const std::uint8_t* const bits = state_.bonds.node(i);
    if (lps && !gathers) {
      add_pair_forces<true, false>(i, bonds, bits, arrays);
    } else if (!gathers) {
      add_pair_forces<false, false>(i, bonds, bits, arrays);
    } else if (lps) {
      add_pair_forces<true, true>(i, bonds, bits, arrays);
    } else {
      add_pair_forces<false, true>(i, bonds, bits, arrays);
    }
  });
}

std::vector<real> Simulation::bond_force_densities() const {
  std::vector<real> forces(state_.positions.size(), 0.0);
  if (forces_current_) add_bond_forces(forces.data());
  return forces;
}

void Simulation::compute_forces() {
  update_kinematic_nodes();
  const std::uint64_t newly_broken = sum_dilatation_and_break_bonds();  // pass 1
  start_node_forces();
  add_bond_forces(state_.forces.data());  // pass 2
  broken_bond_copies_ += newly_broken;
  add_contact_forces();
  add_nodal_forces();
  forces_current_ = true;
}

std::uint64_t Simulation::sum_dilatation_and_break_bonds() {
  // Pass 1: stretch, irreversible breaking, sum_j w r e at both ends. A bond breaks at the end
  // that evaluates it; its other copy is cleared below, before any loop reads it (when both
  // ends gather, both see bitwise the same stretch and each clears its own).
  const Model& m = *model_;
  const auto& materials = m.materials();
  const auto& node_material = m.node_material();
  auto& intact = state_.bonds;
  const std::int64_t n = m.node_count();
  const BondSchedule& schedule = m.bond_schedule();
  const real* const positions = state_.positions.data();
  const real* const volumes = m.volumes().data();
  real* const dilatation_sums = state_.dilatation.data();
  std::vector<std::array<index_t, 2>> broken;  // (evaluating node, neighbour)
#pragma omp parallel
  {
#pragma omp for schedule(static)
    for (std::int64_t i = 0; i < n; ++i) dilatation_sums[i] = 0;
    std::vector<std::array<index_t, 2>> broken_here;
    for_each_node_in_colours(schedule, [&](index_t i) {
      const Material& material = materials[node_material[i]];
      const NodeBonds bonds = m.node_bonds(i);
      const CriticalStretch criterion{m.particles()[m.node_particle()[i]].critical_stretch,
                                      material.params.break_in_compression};
      const bool breaks = material.params.fracture, gathers = schedule.particle_gathers[m.node_particle()[i]];
      std::uint8_t* const bits = intact.node(i);
      if (breaks && !gathers) {
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
    });
    if (!broken_here.empty()) {
#pragma omp critical(granulate_broken_bonds)
      broken.insert(broken.end(), broken_here.begin(), broken_here.end());
    }
  }
  for (const auto& [i, j] : broken) {
    const NodeBonds bonds = m.node_bonds(j);
    BondStates::clear(intact.node(j), bonds.find(i));
  }
  contact_.bonds_broke(m, broken);
  return 2 * broken.size();
}

void Simulation::start_node_forces() {
  // Dilatation and pressure of LPS nodes; body forces and damping start each node's sum.
  const Model& m = *model_;
  const auto& materials = m.materials();
  const auto& node_material = m.node_material();
  const auto& lps_coefficients = m.lps_coefficients();
  const auto& density = m.node_density();
  auto& f = state_.forces;
  auto& theta = state_.dilatation;
  const std::int64_t n = m.node_count();
  const auto g = body_acceleration_;
#pragma omp parallel for schedule(static)
  for (std::int64_t ii = 0; ii < n; ++ii) {
    const index_t i = static_cast<index_t>(ii);
    if (materials[node_material[i]].params.model == ForceModel::lps) {
      theta[i] *= lps_coefficients[i].dilatation_scale;
      pressure_[i] = lps_coefficients[i].dilatation_coupling * theta[i];
    } else {
      theta[i] = 0;
    }
    const real* vi = &state_.velocities[3 * i];
    f[3 * i] = density[i] * (g[0] - viscous_damping_ * vi[0]);
    f[3 * i + 1] = density[i] * (g[1] - viscous_damping_ * vi[1]);
    f[3 * i + 2] = density[i] * (g[2] - viscous_damping_ * vi[2]);
  }
}

void Simulation::add_contact_forces() {
  const auto contact_start = clock_type::now();
  contact_.add_forces(*model_, state_, broken_bond_copies_);
  peridem_damping_.add_forces(*model_, state_);
  phase_times_.contact += seconds_since(contact_start);
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

void Simulation::run(std::uint64_t steps) {
  const Model& m = *model_;
  const auto& density = m.node_density();
  const auto& particles = m.particles();
  const auto& node_particle = m.node_particle();
  const std::int64_t n3 = 3 * static_cast<std::int64_t>(m.node_count());
  auto& x = state_.positions;
  auto& v = state_.velocities;
  auto& f = state_.forces;
  const real dt = time_step_;
  if (!forces_current_) {
    apply_prescribed_motion(true);
    compute_forces();
  }
  for (std::uint64_t s = 0; s < steps; ++s) {
    auto start = clock_type::now();
#pragma omp parallel for schedule(static)
    for (std::int64_t k = 0; k < n3; ++k) {
      v[k] += 0.5 * dt * f[k] / density[k / 3];
      x[k] += dt * v[k];
    }
    state_.time += dt;
    phase_times_.integration += seconds_since(start);

    start = clock_type::now();
    apply_prescribed_motion(true);
    phase_times_.loading += seconds_since(start);

    start = clock_type::now();
    const double contact_before = phase_times_.contact;
    compute_forces();
    phase_times_.peridynamics += seconds_since(start) - (phase_times_.contact - contact_before);

    start = clock_type::now();
    // The second half kick, and the first node (if any) that moved more than its mesh size in
    // the step or became non-finite: checked every step, at the cost of one comparison per node.
    std::int64_t first_unstable = n3;
#pragma omp parallel for schedule(static) reduction(min : first_unstable)
    for (std::int64_t i = 0; i < n3 / 3; ++i) {
      real speed2 = 0;
      for (std::int64_t k = 3 * i; k < 3 * i + 3; ++k) {
        v[k] += 0.5 * dt * f[k] / density[i];
        speed2 += v[k] * v[k];
      }
      const real limit = particles[node_particle[i]].mesh_size / dt;
      if (!(speed2 <= limit * limit)) first_unstable = std::min(first_unstable, i);
    }
    apply_prescribed_motion(false);
    ++state_.step;
    if (first_unstable < n3) check_stability();  // names the node (a prescribed one is fine)
    phase_times_.integration += seconds_since(start);
  }
}

std::array<std::size_t, 2> Simulation::memory_bytes() const {
  auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  const Model& m = *model_;
  std::size_t bonds = state_.bonds.bit_bytes();
  for (const BondFamilies& f : m.families())
    bonds += bytes(f.neighbors) + bytes(f.weights) + bytes(f.lengths);
  std::size_t other = state_.bonds.offset_bytes() + bytes(state_.positions) + bytes(state_.velocities) +
                      bytes(state_.forces) + bytes(state_.dilatation) + bytes(pressure_) +
                      bytes(m.reference_positions()) + bytes(m.volumes()) + bytes(m.node_particle()) +
                      bytes(m.node_material()) + bytes(m.node_density()) + bytes(m.bond_offsets()) +
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
  broken_bond_copies_ = state_.bonds.broken(model_->bond_offsets(), 0, model_->node_count());
  contact_.restore(*model_, state_, contact);
  forces_current_ = true;
}

void Simulation::check_stability() const {
  const auto& v = state_.velocities;
  const auto& x = state_.positions;
  const index_t n = model_->node_count();
  for (index_t i = 0; i < n; ++i) {
    const real speed2 = v[3 * i] * v[3 * i] + v[3 * i + 1] * v[3 * i + 1] + v[3 * i + 2] * v[3 * i + 2];
    const bool finite = std::isfinite(speed2) && std::isfinite(x[3 * i]) && std::isfinite(x[3 * i + 1]) &&
                        std::isfinite(x[3 * i + 2]);
    const real mesh_size = model_->particles()[model_->node_particle()[i]].mesh_size;
    if (!finite || std::sqrt(speed2) * time_step_ > mesh_size) {
      std::ostringstream msg;
      msg << "the simulation became unstable at step " << state_.step << " (t = " << state_.time
          << " s): node " << i << " of particle " << model_->node_particle()[i];
      if (finite)
        msg << " moves at " << std::sqrt(speed2) << " m/s, more than its mesh size " << mesh_size
            << " m per step";
      else
        msg << " has a non-finite position or velocity";
      msg << ". The time step is " << time_step_ << " s and the stable estimate is " << stable_time_step()
          << " s; use a smaller time step, a slower loading or smaller initial velocities";
      throw InstabilityError(msg.str());
    }
  }
}

real Simulation::kinetic_energy() const {
  const auto& v = state_.velocities;
  const auto& volume = model_->volumes();
  const auto& density = model_->node_density();
  real sum = 0;
  for (index_t i = 0; i < model_->node_count(); ++i) {
    sum += 0.5 * density[i] * volume[i] *
           (v[3 * i] * v[3 * i] + v[3 * i + 1] * v[3 * i + 1] + v[3 * i + 2] * v[3 * i + 2]);
  }
  return sum;
}

void Simulation::strain_energy_density(real* out) const {
  const Model& m = *model_;
  const real inverse_dimension = 1.0 / m.lps_dimension();
#pragma omp parallel for schedule(static)
  for (std::int64_t ii = 0; ii < static_cast<std::int64_t>(m.node_count()); ++ii) {
    const index_t i = static_cast<index_t>(ii);
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
}

real Simulation::strain_energy() const {
  std::vector<real> density(model_->node_count());
  strain_energy_density(density.data());
  real total = 0;
  for (index_t i = 0; i < model_->node_count(); ++i) total += density[i] * model_->volumes()[i];
  return total;
}

void Simulation::damage(real* phi, real* z) const {
  const Model& m = *model_;
#pragma omp parallel for schedule(static)
  for (std::int64_t ii = 0; ii < static_cast<std::int64_t>(m.node_count()); ++ii) {
    const index_t i = static_cast<index_t>(ii);
    const real s0 = m.particles()[m.node_particle()[i]].critical_stretch;
    const NodeBonds bonds = m.node_bonds(i);
    real all = 0, intact = 0, max_stretch = 0;
    for (index_t b = 0; b < bonds.count; ++b) {
      const real w = bonds.weight(b), r = bonds.length(b);
      all += w;
      if (state_.bonds.intact(i, b)) intact += w;
      max_stretch = std::max(max_stretch,
                             std::abs(bond_extension(i, bonds.neighbor(b), r, state_.positions.data()) / r));
    }
    if (phi) phi[i] = all > 0 ? 1.0 - intact / all : 0.0;
    if (z) z[i] = std::isfinite(s0) ? max_stretch / s0 : 0.0;
  }
}

void Simulation::break_bonds(const std::vector<std::array<index_t, 2>>& pairs) {
  const Model& m = *model_;
  auto copy_of = [&](index_t i, index_t j) -> std::array<index_t, 2> {  // (node, its bond)
    const bool same_particle =
        i < m.node_count() && j < m.node_count() && m.node_particle()[i] == m.node_particle()[j];
    const index_t b = same_particle ? m.node_bonds(i).find(j) : 0;
    if (!same_particle || b == m.node_bonds(i).count) {
      throw InputError("nodes " + std::to_string(i) + " and " + std::to_string(j) + " are not bonded");
    }
    return {i, b};
  };
  for (const auto& [i, j] : pairs) {
    const auto forward = copy_of(i, j), backward = copy_of(j, i);
    if (state_.bonds.intact(forward[0], forward[1])) {
      BondStates::clear(state_.bonds.node(forward[0]), forward[1]);
      BondStates::clear(state_.bonds.node(backward[0]), backward[1]);
      broken_bond_copies_ += 2;
      const std::array<index_t, 2> pair{i, j};
      contact_.bonds_broke(*model_, {&pair, 1});
    }
  }
  forces_current_ = false;
}

std::uint64_t Simulation::broken_bonds() const {
  return broken_bond_copies_ / 2;
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
