// The contact neighbour lists built anew: the broad phase over particles (bounding spheres in a
// cell grid), the node-pair search over the particles that can touch, the node-wall search.
#include <algorithm>
#include <cmath>
#include <limits>

#include "contact_vectors.hpp"
#include "granulate/cell_grid.hpp"
#include "granulate/contact/contact_model.hpp"
#include "granulate/in_parallel.hpp"

namespace granulate {
using namespace contact_vectors;

namespace {

bool intact_bond(const Model& model, const State& state, index_t i, index_t j) {
  const NodeBonds bonds = model.node_bonds(i);
  const index_t b = bonds.find(j);
  return b != bonds.count && state.bonds.intact(i, b);
}

}  // namespace

void ContactModel::rebuild(const Model& model, const State& state, std::uint64_t broken_bonds, bool finish) {
  skin_ = list_skin();
  const KeptLists kept{std::move(pair_offsets_), std::move(pair_partner_), std::move(pair_spring_),
                       std::move(wall_offsets_), std::move(wall_entry_),   std::move(wall_spring_)};
  const real reach = largest_pair_reach(model) + skin_;
  newly_broken_.clear();  // the search finds every unbonded pair
  detached_nodes_.clear();
  changed_inert_.clear();  // the search lists every node as it is now
  label_bodies(model, state, broken_bonds);
  const NearParticles near = near_particles(model, state, broken_bonds, reach);
  near_particle_ = near.particle;
  all_near_ =
      std::all_of(near_particle_.begin(), near_particle_.end(), [](std::uint8_t f) { return f != 0; });
  search_node_pairs(model, state, near.particle, reach);
  search_node_walls(model, state, near.wall);
  carry_over_springs(kept, model.node_count());
  if (finish) finish_lists(model);

  time_at_build_ = state.time;
  broken_at_build_ = broken_bonds;
  built_ = true;
  ++statistics_.rebuilds;
  statistics_.list_entries = pair_partner_.size();
}

ContactModel::NearParticles ContactModel::near_particles(const Model& model, const State& state,
                                                         std::uint64_t broken_bonds, real reach) const {
  const std::vector<float>& x = positions_at_build_;
  const auto& particles = model.particles();
  const std::size_t particle_count = particles.size();
  // Broad phase: bounding spheres of particles; a particle takes part when another particle's
  // sphere or a wall is within reach, or when it has broken bonds (fragments may touch).
  std::vector<real> centres(3 * particle_count, 0), radii(particle_count, 0);
  for (std::size_t p = 0; p < particle_count; ++p) {
    const Particle& particle = particles[p];
    for (index_t i = particle.first_node; i < particle.first_node + particle.node_count; ++i) {
      for (int k = 0; k < 3; ++k) centres[3 * p + k] += x[3 * i + k];
    }
    for (int k = 0; k < 3; ++k) centres[3 * p + k] /= particle.node_count;
    for (index_t i = particle.first_node; i < particle.first_node + particle.node_count; ++i) {
      real d2 = 0;
      for (int k = 0; k < 3; ++k)
        d2 += (x[3 * i + k] - centres[3 * p + k]) * (x[3 * i + k] - centres[3 * p + k]);
      radii[p] = std::max(radii[p], std::sqrt(d2));
    }
  }
  NearParticles near{std::vector<std::uint8_t>(particle_count, 0),
                     std::vector<std::uint8_t>(particle_count, 0)};
  std::vector<std::uint8_t>& near_particle = near.particle;
  std::vector<std::uint8_t>& near_wall = near.wall;
  if (any_law_) {
    const real largest = *std::max_element(radii.begin(), radii.end());
    const CellGrid centre_grid =
        CellGrid::build(centres, 0, static_cast<index_t>(particle_count), 2 * largest + reach);
    for (std::size_t p = 0; p < particle_count; ++p) {
      centre_grid.for_each_within(centres, static_cast<index_t>(p), 2 * largest + reach, dimension_,
                                  [&](index_t q, real r2) {
                                    if (std::sqrt(r2) <= radii[p] + radii[q] + reach) near_particle[p] = 1;
                                  });
      if (broken_bonds > 0 && !near_particle[p]) {
        const Particle& particle = particles[p];
        if (state.bonds.broken(model.bond_offsets(), particle.first_node,
                               particle.first_node + particle.node_count) > 0)
          near_particle[p] = 1;
      }
    }
  }
  std::vector<WallContact> found;
  for (std::size_t p = 0; p < particle_count; ++p) {
    for (std::size_t w = 0; w < walls_.size(); ++w) {
      const auto centre = walls_[w].to_reference(&centres[3 * p], state.time);
      for (std::size_t s = 0; s < walls_[w].surfaces.size(); ++s) {
        found.clear();
        walls_[w].contacts(s, centre, radii[p] + reach, dimension_, found);
        if (!found.empty()) near_wall[p] = 1;
      }
    }
  }
  return near;
}

void ContactModel::search_node_pairs(const Model& model, const State& state,
                                     const std::vector<std::uint8_t>& near_particle, real reach) {
  const std::vector<float>& x = positions_at_build_;
  const index_t n = model.node_count();
  const auto& particles = model.particles();
  const std::size_t particle_count = particles.size();
  // Node pairs: a grid over the nodes that take part (takes_part) of particles near another
  // particle or broken.
  std::vector<index_t> searched;
  const std::vector<std::uint8_t>& surface = surface_particles_;
  if (any_surface_) {
    taking_part_.assign(n, 0);
  } else {
    std::vector<std::uint8_t>().swap(taking_part_);  // every node takes part
  }
  for (std::size_t p = 0; p < particle_count; ++p) {
    if (!near_particle[p]) continue;
    for (index_t i = particles[p].first_node; i < particles[p].first_node + particles[p].node_count; ++i) {
      if (inert(i) || (surface[p] && !takes_part(model, state, i))) continue;
      if (surface[p]) taking_part_[i] = 1;
      searched.push_back(i);
    }
  }
  const CellGrid grid = CellGrid::build(x, searched, reach);
  pair_offsets_.assign(n + 1, 0);
  // One search: each thread keeps its nodes' partners, then copies them into place.
  const std::int64_t searched_count = static_cast<std::int64_t>(searched.size());
  in_parallel([&] {
    std::vector<index_t> found_partners;
    std::vector<std::array<index_t, 2>> found_nodes;  // (node, first of its partners)
#pragma omp for schedule(static)
    for (std::int64_t a = 0; a < searched_count; ++a) {
      const index_t i = searched[a];
      const std::size_t first = found_partners.size();
      grid.for_each_within(x, i, reach, dimension_, [&](index_t j, real r2) {
        if (lists_pair(model, state, i, j, r2, false)) found_partners.push_back(j);
      });
      std::sort(found_partners.begin() + static_cast<std::ptrdiff_t>(first), found_partners.end());
      pair_offsets_[i + 1] = static_cast<index_t>(found_partners.size() - first);
      found_nodes.push_back({i, static_cast<index_t>(first)});
    }
#pragma omp single
    {
      for (index_t i = 0; i < n; ++i) pair_offsets_[i + 1] += pair_offsets_[i];
      pair_partner_.resize(pair_offsets_[n]);
    }
    for (const auto& [i, first] : found_nodes) {
      std::copy_n(found_partners.begin() + first, pair_offsets_[i + 1] - pair_offsets_[i],
                  pair_partner_.begin() + pair_offsets_[i]);
    }
  });
}

bool ContactModel::lists_pair(const Model& model, const State& state, index_t i, index_t j, real r2,
                              bool either_reach) const {
  const index_t mi = model.node_material()[i], mj = model.node_material()[j];
  if (!law_set_[mi * material_count_ + mj]) return false;
  // Most candidates are bonded neighbours: the bond test first, the reach after.
  if (model.node_particle()[i] == model.node_particle()[j] && intact_bond(model, state, i, j)) return false;
  const bool same_body = node_body_[i] == node_body_[j];
  real reach = pair_reach(model, i, j, same_body);
  if (same_body && either_reach) reach = std::max(reach, pair_reach(model, i, j, false));
  const real limit = reach + skin_;
  return r2 <= limit * limit;
}

void ContactModel::search_node_walls(const Model& model, const State& state,
                                     const std::vector<std::uint8_t>& near_wall) {
  const index_t n = model.node_count();
  const auto& particles = model.particles();
  const std::size_t particle_count = particles.size();
  // Node-wall candidates of the nodes of particles near a wall.
  std::vector<std::vector<std::array<index_t, 2>>> per_node(n);
  std::vector<index_t> wall_nodes;
  for (std::size_t p = 0; p < particle_count; ++p) {
    if (!near_wall[p]) continue;
    for (index_t i = particles[p].first_node; i < particles[p].first_node + particles[p].node_count; ++i) {
      if (!inert(i)) wall_nodes.push_back(i);
    }
  }
  const std::int64_t wall_node_count = static_cast<std::int64_t>(wall_nodes.size());
  in_parallel([&] {
#pragma omp for schedule(static)
    for (std::int64_t a = 0; a < wall_node_count; ++a) {
      list_node_walls(model, state.time, wall_nodes[a], per_node[wall_nodes[a]]);
    }
  });
  wall_offsets_.assign(n + 1, 0);
  for (index_t i = 0; i < n; ++i)
    wall_offsets_[i + 1] = wall_offsets_[i] + static_cast<index_t>(per_node[i].size());
  wall_entry_.clear();
  wall_entry_.reserve(wall_offsets_[n]);
  for (index_t i = 0; i < n; ++i)
    wall_entry_.insert(wall_entry_.end(), per_node[i].begin(), per_node[i].end());
}

void ContactModel::list_node_walls(const Model& model, real time, index_t i,
                                   std::vector<std::array<index_t, 2>>& out) const {
  const std::vector<float>& x = positions_at_build_;
  const auto& node_particle = model.node_particle();
  std::vector<WallContact> found;
  for (std::size_t w = 0; w < walls_.size(); ++w) {
    if (!wall_law_set_[w * material_count_ + model.node_material()[i]]) continue;
    // x is the list position, list_offset out from the contact centre.
    const real radius = wall_law(static_cast<index_t>(w), node_particle[i]).contact_radius;
    real limit = radius + list_offset(model, i, radius) + skin_;
    // An osculating sphere weighs the points whose chord to the wall is below the support a:
    // the surface point then lies within a^2 / (2 r) of the wall.
    const real r = centres_.seen(model, i).osculating_radius;
    if (r > 0) {
      const real support = contact::surface_support_factor * model.particles()[node_particle[i]].mesh_size;
      limit = std::max(limit, support * support / (2 * r) + skin_);
    }
    const real at[3] = {x[3 * i], x[3 * i + 1], x[3 * i + 2]};
    const auto p = walls_[w].to_reference(at, time);
    for (std::size_t s = 0; s < walls_[w].surfaces.size(); ++s) {
      found.clear();
      walls_[w].contacts(s, p, limit, dimension_, found);
      if (!found.empty()) out.push_back({static_cast<index_t>(w), static_cast<index_t>(s)});
    }
  }
}

}  // namespace granulate
