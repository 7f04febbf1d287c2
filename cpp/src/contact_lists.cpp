// The contact neighbour lists: when they are rebuilt, updates after bonds break, the friction
// springs carried over, slots, groups (the searches themselves: contact_search.cpp).
#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <map>

#include "contact_vectors.hpp"
#include "granulate/cell_grid.hpp"
#include "granulate/contact/body_sums.hpp"
#include "granulate/contact/contact_model.hpp"
#include "granulate/in_parallel.hpp"

namespace granulate {
using namespace contact_vectors;

namespace {

/// Gives back all of a vector's spare memory, for the arrays made anew at each list build: a
/// copy per build, where the growth of the build would keep up to twice their size.
template <class T>
void fit(std::vector<T>& v) {
  if (v.capacity() > v.size()) v.shrink_to_fit();
}

}  // namespace

real ContactModel::largest_displacement(const Model& model, const State& state) const {
  const std::int64_t n = model.node_count();
  const std::uint8_t* const inert = inert_.empty() ? nullptr : inert_.data();  // listed nowhere
  real worst = 0;
  in_parallel([&] {
#pragma omp for schedule(static) reduction(max : worst)
    for (std::int64_t i = 0; i < n; ++i) {
      const index_t node = static_cast<index_t>(i);
      const real* y = &state.positions[3 * node];
      const vec3 x = centres_.moved(node) ? centres_.at_list(model, state, node) : vec3{y[0], y[1], y[2]};
      real d2 = 0;
      for (int k = 0; k < 3; ++k) {
        const real d = x[k] - positions_at_build_[3 * i + k];
        d2 += d * d;
      }
      if (!inert || !inert[i]) worst = std::max(worst, d2);
    }
  });
  return std::sqrt(worst);
}

std::vector<index_t> ContactModel::nodes_moved_past(const Model& model, const State& state,
                                                    real limit) const {
  std::vector<index_t> moved;
  for (index_t i = 0; i < model.node_count(); ++i) {
    if (inert(i)) continue;
    const vec3 x = centres_.at_list(model, state, i);
    real d2 = 0;
    for (int k = 0; k < 3; ++k) {
      const real d = x[k] - positions_at_build_[3 * i + k];
      d2 += d * d;
    }
    if (d2 > limit * limit) moved.push_back(i);
  }
  return moved;
}

bool ContactModel::needs_search(const Model& model, const State& state, bool broke, real& moved,
                                std::vector<index_t>& relist) const {
  moved = 0;
  relist.clear();
  if (!built_) return true;
  const real half_skin = 0.5 * skin_;
  for (const Wall& wall : walls_) {
    if (wall.motion_bound(time_at_build_, state.time) > half_skin) return true;
  }
  moved = largest_displacement(model, state);
  if (moved > half_skin) {
    if (!all_near_ || !relisting_) return true;  // a moved node may reach a particle not searched
    // The nodes that moved a quarter of the skin come along: their turn would come soon, and
    // every list change costs a pass over all entries (finish_lists).
    relist = nodes_moved_past(model, state, 0.25 * skin_);
  }
  if (broke || !changed_inert_.empty()) {
    // A node a crack opened, or that lost its surface point (its list position and reach
    // change), has not moved half the skin (or it is relisted already): it can reach only the
    // particles near its own. So can a node made inert or woken (set_inert_nodes).
    std::vector<index_t> changed = changed_inert_;
    if (broke) {
      const std::vector<index_t> opened = opened_nodes(model);
      changed.insert(changed.end(), opened.begin(), opened.end());
      changed.insert(changed.end(), detached_nodes_.begin(), detached_nodes_.end());
    }
    for (const index_t k : changed) {
      if (!near_particle_[model.node_particle()[k]] || !relisting_) return true;
      relist.push_back(k);
    }
    std::sort(relist.begin(), relist.end());
    relist.erase(std::unique(relist.begin(), relist.end()), relist.end());
  }
  return relist.size() * relist_share > static_cast<std::size_t>(model.node_count());
}

bool ContactModel::takes_part(const Model& model, const State& state, index_t i) const {
  if (!surface_particle(model.node_particle()[i]) || on_surface(model, i)) return true;
  const NodeBonds bonds = model.node_bonds(i);
  for (index_t b = 0; b < bonds.count; ++b) {
    if (!state.bonds.intact(i, b)) return true;  // on a crack face
  }
  return false;
}

bool ContactModel::surface_entry(const Model& model, index_t i, std::size_t e) const {
  if (!any_surface_) return false;
  if (probe_entry(e)) return true;  // i probes j: a surface point of another body
  const index_t j = pair_partner_[e];
  return on_surface(model, i) && slot_law(pair_slot_[e]).surface && node_body_[i] != node_body_[j];
}

void ContactModel::bonds_broke(const Model& model, const State& state,
                               std::span<const std::array<index_t, 2>> pairs) {
  if (!active()) return;
  newly_broken_.insert(newly_broken_.end(), pairs.begin(), pairs.end());
  for (const index_t k : centres_.detach_anchored(model, state, pairs)) {
    if (!surface_particle(model.node_particle()[k])) continue;  // the node spheres' reach is kept
    if (!opened_rest_.empty()) opened_rest_[k] = -1;
    detached_nodes_.push_back(k);
  }
}

std::vector<index_t> ContactModel::opened_nodes(const Model& model) const {
  std::vector<index_t> opened;
  if (taking_part_.empty()) return opened;  // every node takes part already
  for (const auto& [i, j] : newly_broken_) {
    for (const index_t k : {i, j}) {
      if (!taking_part_[k] && surface_particle(model.node_particle()[k])) opened.push_back(k);
    }
  }
  std::sort(opened.begin(), opened.end());
  opened.erase(std::unique(opened.begin(), opened.end()), opened.end());
  return opened;
}

std::vector<std::array<index_t, 2>> ContactModel::broken_pairs(const Model& model, const State& state,
                                                               real moved) {
  // A node moves at most skin/2 from where it was listed before it is listed again, so a pair
  // now at d stays beyond d - skin - 2 w (w: the largest displacement since listed so far). A
  // pair left out now stays out of reach until then (w only grows; the reach taken is the larger
  // of its reaches within one body and between two: were they one body now, a later break could
  // part them), so only the bonds broken since the last update are candidates.
  const auto& node_material = model.node_material();
  const real extra = skin_ + 2 * moved;
  std::vector<std::array<index_t, 2>> added;
  for (const auto& [i, j] : newly_broken_) {
    const index_t m = node_material[i];  // a bond joins two nodes of one particle
    if (!law_set_[m * material_count_ + m] || inert(i) || inert(j)) continue;
    const real limit = std::max(pair_reach(model, i, j, true), pair_reach(model, i, j, false)) + extra;
    const vec3 xi = centres_.at_list(model, state, i);
    const vec3 xj = centres_.at_list(model, state, j);
    const real dx = xj[0] - xi[0], dy = xj[1] - xi[1], dz = xj[2] - xi[2];
    if (dx * dx + dy * dy + dz * dz > limit * limit) continue;
    added.push_back({i, j});
    added.push_back({j, i});
  }
  newly_broken_.clear();
  return added;
}

std::vector<std::array<index_t, 2>> ContactModel::relisted_pairs(const Model& model, const State& state,
                                                                 const std::vector<index_t>& relist) {
  // Each relisted node's partners are those a search would list: a grid over every node that
  // takes part, at its list position (as listed), within each pair's reach plus the skin.
  const auto& node_particle = model.node_particle();
  for (const index_t k : relist) {
    if (!taking_part_.empty() && surface_particle(node_particle[k]) && takes_part(model, state, k))
      taking_part_[k] = 1;
  }
  const std::uint8_t* const inert = inert_.empty() ? nullptr : inert_.data();
  auto part = [&](index_t i) {
    const index_t p = node_particle[i];
    return near_particle_[p] && !(inert && inert[i]) &&
           (taking_part_.empty() || !surface_particle(p) || taking_part_[i]);
  };
  std::vector<index_t> searched;
  for (index_t i = 0; i < model.node_count(); ++i) {
    if (part(i)) searched.push_back(i);
  }
  const real reach = largest_pair_reach(model) + skin_;
  const CellGrid grid = CellGrid::build(positions_at_build_, searched, reach);
  std::vector<std::array<index_t, 2>> pairs;
  for (const index_t k : relist) {
    if (!part(k)) continue;
    grid.for_each_within(positions_at_build_, k, reach, dimension_, [&](index_t j, real r2) {
      if (!lists_pair(model, state, k, j, r2, true)) return;
      pairs.push_back({k, j});
      pairs.push_back({j, k});
    });
  }
  return pairs;
}

void ContactModel::update_lists(const Model& model, const State& state, std::uint64_t broken_bonds,
                                real moved, const std::vector<index_t>& relist) {
  label_bodies(model, state, broken_bonds);
  const index_t n = model.node_count();
  std::vector<std::array<index_t, 2>> added = broken_pairs(model, state, moved);
  std::vector<std::uint8_t> relisted(relist.empty() ? 0 : n, 0);
  for (const index_t k : relist) {
    relisted[k] = 1;
    const vec3 x = centres_.at_list(model, state, k);
    for (int c = 0; c < 3; ++c) positions_at_build_[3 * k + c] = static_cast<float>(x[c]);
  }
  if (!relist.empty()) {
    const auto pairs = relisted_pairs(model, state, relist);
    added.insert(added.end(), pairs.begin(), pairs.end());
  }
  std::sort(added.begin(), added.end());
  added.erase(std::unique(added.begin(), added.end()), added.end());
  if (added.empty() && relist.empty()) {
    finish_lists(model);  // the bodies may have changed
  } else {
    const KeptLists kept{std::move(pair_offsets_), std::move(pair_partner_), std::move(pair_spring_),
                         std::move(wall_offsets_), std::move(wall_entry_),   std::move(wall_spring_)};
    auto is_relisted = [&](index_t i) { return !relisted.empty() && relisted[i]; };
    // Per node: the kept partners (none for a relisted node, no relisted one otherwise) and the
    // added ones, merged in order.
    pair_offsets_.assign(static_cast<std::size_t>(n) + 1, 0);
    pair_partner_.clear();
    wall_offsets_.assign(static_cast<std::size_t>(n) + 1, 0);
    wall_entry_.clear();
    std::vector<index_t> old, fresh;
    auto next = added.begin();
    for (index_t i = 0; i < n; ++i) {
      old.clear();
      fresh.clear();
      if (!is_relisted(i)) {
        for (index_t e = kept.pair_offsets[i]; e < kept.pair_offsets[i + 1]; ++e) {
          if (!is_relisted(kept.pair_partner[e])) old.push_back(kept.pair_partner[e]);
        }
      }
      for (; next != added.end() && (*next)[0] == i; ++next) fresh.push_back((*next)[1]);
      std::set_union(old.begin(), old.end(), fresh.begin(), fresh.end(), std::back_inserter(pair_partner_));
      pair_offsets_[i + 1] = static_cast<index_t>(pair_partner_.size());
      if (is_relisted(i)) {
        if (!inert(i)) list_node_walls(model, time_at_build_, i, wall_entry_);
      } else {
        wall_entry_.insert(wall_entry_.end(), kept.wall_entry.begin() + kept.wall_offsets[i],
                           kept.wall_entry.begin() + kept.wall_offsets[i + 1]);
      }
      wall_offsets_[i + 1] = static_cast<index_t>(wall_entry_.size());
    }
    carry_over_springs(kept, n);
    finish_lists(model);
  }
  broken_at_build_ = broken_bonds;
  detached_nodes_.clear();
  changed_inert_.clear();
  ++statistics_.list_updates;
  statistics_.list_entries = pair_partner_.size();
}

void ContactModel::label_bodies(const Model& model, const State& state, std::uint64_t broken_bonds) {
  if (bodies_labelled_ && broken_bonds == broken_at_labelling_) return;
  if (bodies_labelled_) relabelled_first_node_ = body_first_nodes();  // the slots' numbering
  bodies_labelled_ = true;
  broken_at_labelling_ = broken_bonds;
  const index_t n = model.node_count();
  node_body_.resize(n);
  if (broken_bonds == 0) {  // every particle is whole: the bodies are the particles
    for (index_t i = 0; i < n; ++i) node_body_[i] = model.node_particle()[i];
  } else {  // fragments, numbered in the order of their smallest node
    model.fragments(state.bonds, node_body_.data());
    std::vector<index_t> number(n, 0);
    index_t next = 0;
    for (index_t i = 0; i < n; ++i) {
      if (node_body_[i] == i) number[i] = next++;
      node_body_[i] = number[node_body_[i]];
    }
  }
  const index_t count = n == 0 ? 0 : *std::max_element(node_body_.begin(), node_body_.end()) + 1;
  body_mass_.assign(count, 0);
  body_kinematic_.assign(count, 1);
  body_material_.assign(count, 0);
  body_particle_.assign(count, 0);
  body_node_offsets_.assign(static_cast<std::size_t>(count) + 1, 0);
  for (index_t i = 0; i < n; ++i) {
    body_mass_[node_body_[i]] += model.density(i) * model.volumes()[i];
    if (node_kinematic_.empty() || !node_kinematic_[i]) body_kinematic_[node_body_[i]] = 0;
    body_material_[node_body_[i]] = model.node_material()[i];
    body_particle_[node_body_[i]] = model.node_particle()[i];
    ++body_node_offsets_[node_body_[i] + 1];
  }
  for (index_t b = 0; b < count; ++b) body_node_offsets_[b + 1] += body_node_offsets_[b];
  body_nodes_.resize(n);
  std::vector<index_t> fill(body_node_offsets_.begin(), body_node_offsets_.end() - 1);
  for (index_t i = 0; i < n; ++i) body_nodes_[fill[node_body_[i]]++] = i;
  body_splittable_.assign(count, 0);
  for (index_t b = 0; b < count; ++b) {
    if (!splittable(model, body_particle_[b])) continue;
    body_splittable_[b] = 1;
    const index_t* nodes = body_nodes_.data() + body_node_offsets_[b];
    body_mass_[b] = order_free_mass(model, nodes, body_node_offsets_[b + 1] - body_node_offsets_[b]);
  }
}

void ContactModel::set_inert_nodes(std::vector<std::uint8_t> inert) {
  const std::size_t n = std::max(inert.size(), inert_.size());
  for (std::size_t i = 0; i < n; ++i) {
    const bool was = i < inert_.size() && inert_[i], now = i < inert.size() && inert[i];
    if (was != now) changed_inert_.push_back(static_cast<index_t>(i));
  }
  inert_ = std::move(inert);
}

std::vector<std::span<const index_t>> ContactModel::bodies_in(index_t first, index_t end) const {
  // Bodies are numbered in the order of their smallest node, so those starting in [first, end)
  // follow the body of `first` (when `first` is the smallest node of a particle).
  std::vector<std::span<const index_t>> bodies;
  const index_t count = static_cast<index_t>(body_node_offsets_.size()) - 1;
  for (index_t b = first < end ? node_body_[first] : count; b < count; ++b) {
    const index_t* nodes = body_nodes_.data() + body_node_offsets_[b];
    if (nodes[0] >= end) break;
    bodies.emplace_back(nodes, body_node_offsets_[b + 1] - body_node_offsets_[b]);
  }
  return bodies;
}

std::vector<index_t> ContactModel::body_first_nodes() const {
  std::vector<index_t> first(body_node_offsets_.size() - 1);
  for (std::size_t b = 0; b < first.size(); ++b) first[b] = body_nodes_[body_node_offsets_[b]];
  return first;
}

void ContactModel::carry_over_springs(const KeptLists& kept, index_t n) {
  // A merge walk per node: both lists are sorted by partner, wall entries by (wall, surface);
  // new entries have no spring.
  pair_spring_.assign(pair_partner_.size(), no_spring);
  wall_spring_.assign(wall_entry_.size(), no_spring);
  auto walk = [](const auto& old_offsets, const auto& old_keys, const std::vector<index_t>& old_springs,
                 const auto& offsets, const auto& keys, std::vector<index_t>& new_springs, index_t node) {
    if (old_offsets.size() <= node + 1 || old_springs.size() != old_keys.size()) return;
    index_t old = old_offsets[node];
    for (index_t e = offsets[node]; e < offsets[node + 1]; ++e) {
      while (old < old_offsets[node + 1] && old_keys[old] < keys[e]) ++old;
      if (old < old_offsets[node + 1] && old_keys[old] == keys[e]) new_springs[e] = old_springs[old];
    }
  };
  in_parallel([&] {
#pragma omp for schedule(static)
    for (std::int64_t ii = 0; ii < static_cast<std::int64_t>(n); ++ii) {
      const index_t i = static_cast<index_t>(ii);
      walk(kept.pair_offsets, kept.pair_partner, kept.pair_spring, pair_offsets_, pair_partner_, pair_spring_,
           i);
      walk(kept.wall_offsets, kept.wall_entry, kept.wall_spring, wall_offsets_, wall_entry_, wall_spring_, i);
    }
  });
  compact_springs();
}

void ContactModel::compact_springs() {
  std::size_t held = 0;
  for (const index_t s : pair_spring_) held += s != no_spring;
  for (const index_t s : wall_spring_) held += s != no_spring;
  std::vector<vec3> springs;
  springs.reserve(held);
  auto take = [&](index_t& s) {
    if (s == no_spring) return;
    springs.push_back(springs_[s]);
    s = static_cast<index_t>(springs.size() - 1);
  };
  for (index_t& s : pair_spring_) take(s);
  for (index_t& s : wall_spring_) take(s);
  springs_ = std::move(springs);
  free_springs_.clear();
  release_excess(free_springs_);
}

void ContactModel::assign_springs() {
  auto update = [&](index_t& spring, bool touching) {
    if (touching && spring == no_spring) {
      if (free_springs_.empty()) {
        spring = static_cast<index_t>(springs_.size());
        springs_.push_back({0, 0, 0});
      } else {
        spring = free_springs_.back();
        free_springs_.pop_back();
        springs_[spring] = {0, 0, 0};
      }
    } else if (!touching && spring != no_spring) {  // apart: the spring is released
      free_springs_.push_back(spring);
      spring = no_spring;
    }
  };
  for (std::size_t e = 0; e < pair_spring_.size(); ++e) update(pair_spring_[e], pair_stiffness_[e] > 0);
  for (std::size_t e = 0; e < wall_spring_.size(); ++e) update(wall_spring_[e], wall_entry_stiffness_[e] > 0);
}

void ContactModel::group_contact_nodes(const Model& model) {
  const index_t n = model.node_count();
  const index_t bodies = static_cast<index_t>(body_mass_.size());
  body_contact_offsets_.assign(static_cast<std::size_t>(bodies) + 1, 0);
  auto has_entries = [&](index_t i) {
    return pair_offsets_[i] != pair_offsets_[i + 1] || wall_offsets_[i] != wall_offsets_[i + 1];
  };
  for (index_t i = 0; i < n; ++i) {
    if (has_entries(i)) ++body_contact_offsets_[node_body_[i] + 1];
  }
  for (index_t b = 0; b < bodies; ++b) body_contact_offsets_[b + 1] += body_contact_offsets_[b];
  contact_nodes_.resize(body_contact_offsets_[bodies]);
  std::vector<index_t> fill(body_contact_offsets_.begin(), body_contact_offsets_.end() - 1);
  for (index_t i = 0; i < n; ++i) {
    if (has_entries(i)) contact_nodes_[fill[node_body_[i]]++] = i;
  }
  body_touch_.assign(bodies, not_touching);
  touching_bodies_.clear();
  slot_touch_.assign(slots_.size(), not_touching);
  wall_damping_.assign(walls_.size(), {0, 0, 0, 0, 0, 0});
}

void ContactModel::finish_lists(const Model& model) {
  // Everything that follows from the lists and the bodies: slots, reduced masses, the laws of
  // the slots, the collision history carried over by slot, and the per-entry scratch.
  const std::vector<std::array<index_t, 2>> old_slots = slots_;
  const std::size_t old_particle_slots = particle_slot_count_;
  find_slots(model);
  resolve_slot_laws();
  carry_over_collisions(old_slots, old_particle_slots);
  group_contact_nodes(model);
  find_groups(model);
  find_rotated_bodies(model);
  pair_stiffness_.assign(pair_partner_.size(), 0);
  wall_entry_stiffness_.assign(wall_entry_.size(), 0);
  wall_points_.assign(wall_entry_.size(), {});
  wall_entry_reaction_.assign(wall_entry_.size(), {0, 0, 0, 0, 0, 0});
  for (auto* v : {&pair_offsets_, &pair_partner_, &pair_slot_, &pair_spring_, &wall_offsets_, &wall_slot_,
                  &wall_spring_, &slot_law_index_, &slot_touch_, &contact_nodes_, &body_contact_offsets_})
    fit(*v);
  fit(pair_stiffness_);
  fit(slots_);
  fit(slot_stiffness_);
  fit(wall_entry_);
}

void ContactModel::find_rotated_bodies(const Model& model) {
  // The bodies of round particles that have wall entries, whose osculating spheres' normals
  // turn with them (measure_wall_points): they change only with the lists and the bodies.
  rotated_bodies_.clear();
  body_rotation_slot_.clear();
  if (any_surface_) {
    body_rotation_slot_.assign(body_mass_.size(), no_rotation);
    for (index_t i = 0; i < model.node_count(); ++i) {
      const index_t b = node_body_[i];
      if (wall_offsets_[i] == wall_offsets_[i + 1] || body_rotation_slot_[b] != no_rotation) continue;
      if (centres_.seen(model, i).osculating_radius > 0) {
        body_rotation_slot_[b] = static_cast<index_t>(rotated_bodies_.size());
        rotated_bodies_.push_back(b);
      }
    }
  }
  body_rotation_.resize(rotated_bodies_.size());
  body_rotated_.assign(rotated_bodies_.size(), 0);
  for (auto* v : {&rotated_bodies_, &body_rotation_slot_}) fit(*v);
  fit(body_rotation_);
  fit(body_rotated_);
}

ContactModel::HeldSlots ContactModel::held_slots() const {
  // Called before slots_ is replaced: its slots, their collisions, and (after a relabelling)
  // the smallest node of each of the bodies they name.
  HeldSlots held;
  auto now = [&](index_t body) {
    return relabelled_first_node_.empty() ? body : node_body_[relabelled_first_node_[body]];
  };
  for (std::size_t slot = 0; slot < slots_.size(); ++slot) {
    if (!(collisions_.approach(slot) > 0)) continue;
    const index_t p = now(slots_[slot][0]);
    if (slot >= particle_slot_count_) {
      held.walls.push_back({p, slots_[slot][1]});
      continue;
    }
    const index_t q = now(slots_[slot][1]);
    if (p != q) held.particles.push_back({std::min(p, q), std::max(p, q)});
  }
  return held;
}

void ContactModel::find_slots(const Model& model) {
  // One slot per pair of bodies that appear in the lists, in sorted order, then one per pair of
  // a body and a wall; and the slots of collisions still open (held_slots).
  const index_t n = model.node_count();
  const auto& node_body = node_body_;
  // Bucketed by the first body (a counting sort), so the sorts are per body and small, and an
  // entry finds its slot among its first body's few slots (fragments make many entries).
  const index_t bodies = static_cast<index_t>(body_mass_.size());
  const HeldSlots held = held_slots();
  std::vector<index_t> bucket(static_cast<std::size_t>(bodies) + 1, 0);
  for (index_t i = 0; i < n; ++i) {
    for (index_t e = pair_offsets_[i]; e < pair_offsets_[i + 1]; ++e) {
      ++bucket[std::min(node_body[i], node_body[pair_partner_[e]]) + 1];
    }
  }
  for (const auto& [a, b] : held.particles) ++bucket[a + 1];
  for (index_t a = 0; a < bodies; ++a) bucket[a + 1] += bucket[a];
  std::vector<index_t> second(bucket.back()), filled(bucket.begin(), bucket.end() - 1);
  for (index_t i = 0; i < n; ++i) {
    for (index_t e = pair_offsets_[i]; e < pair_offsets_[i + 1]; ++e) {
      const index_t p = node_body[i], q = node_body[pair_partner_[e]];
      const index_t a = std::min(p, q), b = std::max(p, q);
      if (filled[a] > bucket[a] && second[filled[a] - 1] == b) continue;  // as the entry before
      second[filled[a]++] = b;
    }
  }
  for (const auto& [a, b] : held.particles) second[filled[a]++] = b;
  slots_.clear();
  std::vector<index_t> body_slots(static_cast<std::size_t>(bodies) + 1, 0);  // slots of first body a
  for (index_t a = 0; a < bodies; ++a) {
    const auto begin = second.begin() + bucket[a], end = second.begin() + filled[a];
    std::sort(begin, end);
    const auto last = std::unique(begin, end);
    for (auto it = begin; it != last; ++it) slots_.push_back({a, *it});
    body_slots[a + 1] = static_cast<index_t>(slots_.size());
  }
  const std::size_t particle_slots = slots_.size();
  particle_slot_count_ = particle_slots;
  pair_slot_.resize(pair_partner_.size());
  in_parallel([&] {
#pragma omp for schedule(static)
    for (std::int64_t ii = 0; ii < static_cast<std::int64_t>(n); ++ii) {
      const index_t i = static_cast<index_t>(ii);
      for (index_t e = pair_offsets_[i]; e < pair_offsets_[i + 1]; ++e) {
        const index_t p = node_body[i], q = node_body[pair_partner_[e]];
        const index_t a = std::min(p, q);
        const std::array<index_t, 2> key{a, std::max(p, q)};
        pair_slot_[e] = static_cast<index_t>(
            std::lower_bound(slots_.begin() + body_slots[a], slots_.begin() + body_slots[a + 1], key) -
            slots_.begin());
      }
    }
  });
  std::vector<std::array<index_t, 2>> wall_keys = held.walls;
  for (index_t i = 0; i < n; ++i) {
    for (index_t e = wall_offsets_[i]; e < wall_offsets_[i + 1]; ++e)
      wall_keys.push_back({node_body[i], wall_entry_[e][0]});
  }
  std::sort(wall_keys.begin(), wall_keys.end());
  wall_keys.erase(std::unique(wall_keys.begin(), wall_keys.end()), wall_keys.end());
  slots_.insert(slots_.end(), wall_keys.begin(), wall_keys.end());
  wall_slot_.resize(wall_entry_.size());
  for (index_t i = 0; i < n; ++i) {
    for (index_t e = wall_offsets_[i]; e < wall_offsets_[i + 1]; ++e) {
      const std::array<index_t, 2> key{node_body[i], wall_entry_[e][0]};
      wall_slot_[e] = static_cast<index_t>(
          particle_slots + (std::lower_bound(wall_keys.begin(), wall_keys.end(), key) - wall_keys.begin()));
    }
  }
}

void ContactModel::resolve_slot_laws() {
  const std::size_t particle_slots = particle_slot_count_;
  // The laws of the slots: one per pair of particles (or particle and wall) that the slots
  // meet, however many fragments the particles broke into.
  slot_law_index_.resize(slots_.size());
  resolved_laws_.clear();
  std::map<std::array<index_t, 3>, index_t> law_of;  // (kind: 0 particles, 1 wall; p; q or wall)
  for (std::size_t s = 0; s < slots_.size(); ++s) {
    const bool wall = s >= particle_slots;
    const index_t p = body_particle_[slots_[s][0]], q = wall ? slots_[s][1] : body_particle_[slots_[s][1]];
    const auto [found, added] =
        law_of.try_emplace({wall ? 1u : 0u, p, q}, static_cast<index_t>(resolved_laws_.size()));
    if (added) resolved_laws_.push_back(wall ? wall_law(q, p) : pair_law(p, q));
    slot_law_index_[s] = found->second;
  }
  resolved_laws_.shrink_to_fit();  // 48 B each, rebuilt at every list build: no growth slack
}

void ContactModel::carry_over_collisions(const std::vector<std::array<index_t, 2>>& old_slots,
                                         std::size_t old_particle_slots) {
  const std::size_t particle_slots = particle_slot_count_;
  slot_stiffness_.assign(slots_.size(), 0);
  // The collisions carry over by slot. Old and new slots are sorted within their two parts
  // (particle pairs, walls): merge walks.
  // Slots are keyed by their bodies' smallest nodes (the numbering's order, so both stay
  // sorted); the second of a wall slot is the wall.
  const bool relabelled = !relabelled_first_node_.empty();
  auto key = [&](const std::array<index_t, 2>& slot, bool wall, const std::vector<index_t>& first) {
    if (!relabelled) return slot;
    return std::array<index_t, 2>{first[slot[0]], wall ? slot[1] : first[slot[1]]};
  };
  const std::vector<index_t> first_node = relabelled ? body_first_nodes() : std::vector<index_t>{};
  std::vector<index_t> old_of_new(slots_.size(), contact::CollisionStore::none);
  auto carry_over = [&](std::size_t slot, std::size_t slot_end, std::size_t old, std::size_t old_end,
                        bool wall) {
    for (; slot < slot_end && old < old_end; ++slot) {
      const std::array<index_t, 2> now = key(slots_[slot], wall, first_node);
      while (old < old_end && key(old_slots[old], wall, relabelled_first_node_) < now) ++old;
      if (old < old_end && key(old_slots[old], wall, relabelled_first_node_) == now)
        old_of_new[slot] = static_cast<index_t>(old);
    }
  };
  carry_over(0, particle_slots, 0, old_particle_slots, false);
  carry_over(particle_slots, slots_.size(), old_particle_slots, old_slots.size(), true);
  collisions_.renumber(old_of_new);
  std::vector<index_t>().swap(relabelled_first_node_);
}

void ContactModel::find_groups(const Model& model) {
  // A node's probe entries: partners that carry surface points of another body, under the
  // surface law; one group per such body, in the order of first appearance.
  const index_t n = model.node_count();
  groups_.clear();
  if (!any_surface_) {
    // No particle uses the surface law: none of its per-node or per-entry tables.
    std::vector<index_t>().swap(entry_group_);
    std::vector<index_t>().swap(group_offsets_);
    std::vector<index_t>().swap(surface_slot_);
    std::vector<index_t>().swap(entry_target_);
    surface_nodes_.clear();
    probes_.clear();
    group_probe_.clear();
    return;
  }
  entry_group_.assign(pair_partner_.size(), no_group);
  group_offsets_.assign(static_cast<std::size_t>(n) + 1, 0);
  for (index_t i = 0; i < n; ++i) {
    const std::size_t first = groups_.size();
    for (index_t e = pair_offsets_[i]; e < pair_offsets_[i + 1]; ++e) {
      const index_t j = pair_partner_[e];
      if (node_body_[j] == node_body_[i] || !slot_law(pair_slot_[e]).surface || !on_surface(model, j))
        continue;
      std::size_t g = first;
      while (g < groups_.size() && groups_[g].body != node_body_[j]) ++g;
      if (g == groups_.size()) groups_.push_back({i, node_body_[j], pair_slot_[e]});
      entry_group_[e] = static_cast<index_t>(g);
    }
    group_offsets_[i + 1] = static_cast<index_t>(groups_.size());
  }
  // The surface points that probes may reach: every node with entries that carries one.
  surface_nodes_.clear();
  surface_slot_.assign(n, no_group);
  for (index_t i = 0; i < n; ++i) {
    if (pair_offsets_[i] == pair_offsets_[i + 1] || !on_surface(model, i) ||
        !surface_particle(model.node_particle()[i]))
      continue;
    surface_slot_[i] = static_cast<index_t>(surface_nodes_.size());
    surface_nodes_.push_back(i);
  }
  surface_points_.resize(surface_nodes_.size());
  surface_sizes_.resize(surface_nodes_.size());
  surface_stretches_.resize(surface_nodes_.size());
  fit(surface_nodes_);
  fit(surface_points_);
  fit(surface_sizes_);
  fit(surface_stretches_);
  fit(groups_);
  // Each entry (i, j) of a node i with a surface point: the group of j that probes i's body.
  entry_target_.assign(pair_partner_.size(), no_group);
  in_parallel([&] {
#pragma omp for schedule(static)
    for (std::int64_t ii = 0; ii < static_cast<std::int64_t>(n); ++ii) {
      const index_t i = static_cast<index_t>(ii);
      if (surface_slot_[i] == no_group) continue;
      for (index_t e = pair_offsets_[i]; e < pair_offsets_[i + 1]; ++e) {
        const index_t j = pair_partner_[e];
        if (node_body_[j] != node_body_[i]) entry_target_[e] = target_group(i, j);
      }
    }
  });
  probes_.clear();
  group_probe_.assign(groups_.size(), no_probe);
}

index_t ContactModel::target_group(index_t i, index_t j) const {
  const index_t* begin = pair_partner_.data() + pair_offsets_[j];
  const index_t* end = pair_partner_.data() + pair_offsets_[j + 1];
  const index_t* at = std::lower_bound(begin, end, i);
  return at == end || *at != i ? no_group : entry_group_[static_cast<std::size_t>(at - pair_partner_.data())];
}

}  // namespace granulate
