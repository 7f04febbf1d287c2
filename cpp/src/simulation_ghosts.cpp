// A distributed run's part in the core (granulate.parallel): the ghosts, the particles another
// process owns, which this one holds for its own particles' contact (their bonds break where
// their owner breaks them; their bodies move as their owner measures them); the foreign nodes,
// another process's part of a particle split at node level; and the numbers its messages give
// its nodes and particles.
#include <algorithm>
#include <span>
#include <sstream>

#include "granulate/simulation.hpp"

namespace granulate {

void Simulation::set_ghost_particles(const std::vector<index_t>& particles) {
  std::vector<std::uint8_t> ghost(model_->particles().size(), 0);
  for (index_t q : particles) {
    if (q >= ghost.size()) {
      std::ostringstream msg;
      msg << "ghost particle " << q << " does not exist: the model has " << ghost.size() << " particles";
      throw InputError(msg.str());
    }
    ghost[q] = 1;
  }
  ghost_ = particles.empty() ? std::vector<std::uint8_t>{} : std::move(ghost);  // empty: none
  contact_.set_ghost_particles(ghost_);
  peridem_damping_.set_ghost_particles(ghost_);
  mark_others();
}

void Simulation::set_foreign_nodes(const std::vector<index_t>& nodes) {
  const index_t n = model_->node_count();
  if (!nodes.empty() && (contact_.active() || peridem_damping_.active())) {
    throw InputError(
        "a particle split at node level runs without contact and PeriDEM's damping for now: its "
        "bodies' motions are not measured across processes (set contact to None)");
  }
  std::vector<std::uint8_t> foreign(n, 0);
  for (const index_t i : nodes) {
    if (i >= n || ghost_node(i)) {
      throw InputError("foreign node " + std::to_string(i) + " is not a node of this process's particles");
    }
    foreign[i] = 1;
  }
  for (const index_t i : nodes) {  // no bond to an own node: nothing of it is evaluated
    const NodeBonds bonds = model_->node_bonds(i);
    bool reaches_own = false;
    for (index_t b = 0; b < bonds.count && !reaches_own; ++b) reaches_own = !foreign[bonds.neighbor(b)];
    if (!reaches_own) foreign[i] = far_foreign;
  }
  foreign_ = nodes.empty() ? std::vector<std::uint8_t>{} : std::move(foreign);
  mark_others();
  count_broken_bond_copies();
  cut_schedule();
}

namespace {

/// The nodes a block's evaluation writes (itself and, unless its particle gathers, its nodes'
/// forward neighbours), and whether it reads a halo node (foreign[i] == 1): evaluates one (a
/// foreign node evaluates its bonds to own nodes), or an own node reading one's position or
/// pressure through a bond it evaluates.
bool block_reach(const Model& model, index_t first, index_t last, const std::uint8_t* foreign,
                 std::vector<index_t>& touched) {
  const bool gathers = model.bond_schedule().particle_gathers[model.node_particle()[first]];
  bool reads_halo = false;
  touched.clear();
  for (index_t i = first; i < last; ++i) {
    touched.push_back(i);
    const NodeBonds bonds = model.node_bonds(i);
    reads_halo = reads_halo || foreign[i] == 1;
    for (index_t b = gathers ? 0 : bonds.forward; b < bonds.count; ++b) {
      const index_t j = bonds.neighbor(b);
      if (!gathers) touched.push_back(j);
      reads_halo = reads_halo || (!foreign[i] && foreign[j]);
    }
  }
  return reads_halo;
}

}  // namespace

void Simulation::cut_schedule() {
  // In colour order: a block is inner unless it reads the halo or touches a node an outer
  // block of an earlier colour touched (blocks of one colour never share a node), so every
  // node takes its inner blocks' terms before its outer blocks', as in the model's order.
  inner_schedule_ = outer_schedule_ = BondSchedule{};
  if (foreign_.empty()) return;
  const BondSchedule& all = model_->bond_schedule();
  for (BondSchedule* part : {&inner_schedule_, &outer_schedule_}) {
    part->block_starts = all.block_starts;
    part->particle_gathers = all.particle_gathers;
    part->colour_offsets.push_back(0);
  }
  std::vector<std::uint8_t> outer_touched(model_->node_count(), 0);
  std::vector<index_t> touched, outer_nodes;
  for (std::size_t c = 0; c + 1 < all.colour_offsets.size(); ++c) {
    outer_nodes.clear();
    for (index_t k = all.colour_offsets[c]; k < all.colour_offsets[c + 1]; ++k) {
      const index_t block = all.blocks[k], first = all.block_starts[block],
                    last = all.block_starts[block + 1];
      if (std::all_of(foreign_.begin() + first, foreign_.begin() + last,
                      [](std::uint8_t f) { return f == far_foreign; }))
        continue;  // nothing of it is evaluated here
      const bool reads_halo = block_reach(*model_, first, last, foreign_.data(), touched);
      const bool inner = !reads_halo && std::none_of(touched.begin(), touched.end(),
                                                     [&](index_t i) { return outer_touched[i] != 0; });
      (inner ? inner_schedule_ : outer_schedule_).blocks.push_back(block);
      if (!inner) outer_nodes.insert(outer_nodes.end(), touched.begin(), touched.end());
    }
    for (const index_t i : outer_nodes) outer_touched[i] = 1;
    for (BondSchedule* part : {&inner_schedule_, &outer_schedule_})
      part->colour_offsets.push_back(static_cast<index_t>(part->blocks.size()));
  }
}

void Simulation::mark_others() {
  if (ghost_.empty() && foreign_.empty()) {
    others_.clear();
    return;
  }
  others_.assign(model_->node_count(), 0);
  for (index_t i = 0; i < model_->node_count(); ++i)
    others_[i] = ghost_node(i) || (!foreign_.empty() && foreign_[i]);
}

void Simulation::set_reported_numbers(std::vector<index_t> nodes, std::vector<index_t> particles) {
  const bool none = nodes.empty() && particles.empty();
  if (!none && (nodes.size() != model_->node_count() || particles.size() != model_->particles().size())) {
    throw InputError("reported numbers: one per node (" + std::to_string(model_->node_count()) +
                     ") and one per particle (" + std::to_string(model_->particles().size()) + "), got " +
                     std::to_string(nodes.size()) + " and " + std::to_string(particles.size()));
  }
  reported_node_ = std::move(nodes);
  reported_particle_ = std::move(particles);
}

void Simulation::check_ghost_breaks(std::span<const std::array<index_t, 2>> pairs) const {
  for (const auto& [i, j] : pairs) {
    const auto b = model_->bond_between(i, j);
    if (!b || !ghost_node(i) || !state_.bonds.intact(i, *b)) {
      throw InputError("ghost bond " + std::to_string(i) + "-" + std::to_string(j) +
                       " is not an intact bond of a ghost particle");
    }
  }
}

void Simulation::break_ghost_bonds(std::span<const std::array<index_t, 2>> pairs) {
  const Model& m = *model_;
  for (const auto& [i, j] : pairs) {
    BondStates::clear(state_.bonds.node(i), m.node_bonds(i).find(j));
    BondStates::clear(state_.bonds.node(j), m.node_bonds(j).find(i));
    breaks_.push_back({i, j});
  }
}

namespace {

/// The fragments of the `count` nodes from `first` (whole particles) under `intact`: each
/// fragment's nodes in node order, the fragments in the order of their smallest node.
std::vector<std::vector<index_t>> fragments_of(const Model& model, const BondStates& intact, index_t first,
                                               index_t count) {
  std::vector<index_t> labels(count);  // each node's fragment, named by its smallest node
  model.fragments_in(intact, first, count, labels.data());
  std::vector<index_t> place(count, 0);  // a fragment's place among them, by its smallest node
  std::vector<std::vector<index_t>> fragments;
  for (index_t k = 0; k < count; ++k) {
    if (labels[k] == first + k) {
      place[k] = static_cast<index_t>(fragments.size());
      fragments.emplace_back();
    }
    fragments[place[labels[k] - first]].push_back(first + k);
  }
  return fragments;
}

}  // namespace

std::vector<std::pair<index_t, BodyMotion>> Simulation::fragment_motions(
    const std::vector<index_t>& particles) const {
  if (!step_begun_) throw InputError("fragment_motions: call it between begin_step and finish_step");
  const Model& m = *model_;
  std::vector<std::uint8_t> broke(m.particles().size(), 0);  // in this step's pass 1
  for (const auto& pair : breaks_) broke[m.node_particle()[pair[0]]] = 1;
  const bool labelled = contact_.bodies_labelled_at(broken_bond_copies_);  // before this step
  std::vector<std::pair<index_t, BodyMotion>> motions;
  auto add = [&](std::span<const index_t> body) {
    motions.emplace_back(
        body[0], measure_body(m, state_, body.data(), static_cast<index_t>(body.size()), m.dimension()));
  };
  for (const index_t p : particles) {
    if (p >= broke.size() || (!ghost_.empty() && ghost_[p])) {
      throw InputError("fragment_motions: particle " + std::to_string(p) + " is not one of this process's");
    }
    const index_t first = m.particles()[p].first_node, count = m.particles()[p].node_count;
    if (labelled && !broke[p]) {  // the contact's bodies are the particle's fragments now
      for (const auto body : contact_.bodies_in(first, first + count)) add(body);
    } else {
      for (const auto& body : fragments_of(m, state_.bonds, first, count)) add(body);
    }
  }
  return motions;
}

std::vector<real> Simulation::surface_normals(const std::vector<index_t>& nodes) const {
  std::vector<real> normals;
  normals.reserve(3 * nodes.size());
  for (const index_t i : nodes) {
    if (i >= model_->node_count()) throw InputError("surface_normals: no node " + std::to_string(i));
    const vec3 n = contact_.surface_normal_at(*model_, state_, i);
    normals.insert(normals.end(), n.begin(), n.end());
  }
  return normals;
}

void Simulation::give_ghost_surface_normals(std::vector<std::pair<index_t, vec3>> normals) {
  for (const auto& [node, normal] : normals) {
    if (node >= model_->node_count() || !ghost_node(node)) {
      throw InputError("ghost surface normal: node " + std::to_string(node) +
                       " is not a node of a ghost particle");
    }
  }
  contact_.give_ghost_surface_normals(std::move(normals));
}

void Simulation::give_ghost_motions(std::vector<std::pair<index_t, BodyMotion>> motions) {
  for (const auto& [node, motion] : motions) {
    if (node >= model_->node_count() || !ghost_node(node)) {
      throw InputError("ghost motion: node " + std::to_string(node) + " is not a node of a ghost particle");
    }
  }
  contact_.give_ghost_motions(std::move(motions));
}

}  // namespace granulate
