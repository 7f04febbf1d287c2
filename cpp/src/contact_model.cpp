// The contact model's set-up: laws per pair of materials and per wall, walls, the skin, which
// particles are centred on their surfaces, the reach of a pair, the stable time step, and the
// checks at the start (a node inside a wall, particles overlapping).
#include "granulate/contact/contact_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "contact_vectors.hpp"
#include "granulate/cell_grid.hpp"

namespace granulate {
using namespace contact_vectors;

namespace {

void require_valid(const contact::Law& law, const char* what) {
  const bool radius = law.contact_radius > 0 || (law.contact_radius == 0 && law.contact_radius_factor > 0);
  const bool stiffness = law.normal_stiffness > 0 || (law.normal_stiffness == 0 && law.stiffness_factor > 0);
  if (!radius || !stiffness || !(law.damping_ratio >= 0) || !(law.damping_ratio < 1) ||
      !(law.friction >= 0) || !(law.tangential_stiffness_ratio > 0) ||
      !(law.tangential_stiffness_ratio <= 1) || !(law.rolling_friction >= 0) ||
      !std::isfinite(law.rolling_friction) || !(law.rolling_damping >= 0) || !(law.rolling_damping <= 1) ||
      !std::isfinite(law.contact_radius + law.contact_radius_factor) ||
      !std::isfinite(law.normal_stiffness + law.stiffness_factor)) {
    throw InputError(
        std::string(what) +
        " needs a positive contact radius (or factor) and stiffness (or factor), a damping ratio in "
        "[0, 1), non-negative friction and rolling friction coefficients, a tangential stiffness ratio "
        "in (0, 1] and a rolling damping ratio in [0, 1]");
  }
}

}  // namespace

void ContactModel::configure(const Model& model) {
  material_count_ = static_cast<index_t>(model.materials().size());
  laws_.assign(static_cast<std::size_t>(material_count_) * material_count_, {});
  damping_tables_.assign(laws_.size(), {});
  law_set_.assign(laws_.size(), 0);
  dimension_ = model.dimension();
  particle_side_.clear();
  particle_material_.clear();
  material_max_mesh_size_.assign(material_count_, 0);
  for (const Particle& p : model.particles()) {
    particle_side_.push_back({p.mesh_size, p.horizon, model.materials()[p.material].dilatation_modulus});
    particle_material_.push_back(p.material);
    material_max_mesh_size_[p.material] = std::max(material_max_mesh_size_[p.material], p.mesh_size);
  }
  find_surface_particles();
  built_ = false;
  centres_.forget();
  opened_rest_.clear();
}

real ContactModel::surface_normal_reach(const Model& model) const {
  bool spheres = false, surface = false;  // some law's sphere pairs anywhere / under the surface law
  for (std::size_t k = 0; k < laws_.size(); ++k) {
    if (!law_set_[k] || laws_[k].node_pair) continue;
    (laws_[k].surface ? surface : spheres) = true;
  }
  if (spheres) return list_cutoff(model);
  return surface ? max_contact_radius_ + list_skin() : 0;
}

bool ContactModel::centres_particle(const Model& model, index_t p) const {
  const Particle& particle = model.particles()[p];
  if (model.shapes()[particle.shape].anchors.anchors.empty()) return false;
  const index_t m = particle.material;
  for (index_t b = 0; b < material_count_; ++b) {
    if (law_set_[m * material_count_ + b] && laws_[m * material_count_ + b].node_pair) return false;
  }
  for (std::size_t w = 0; w < walls_.size(); ++w) {
    if (wall_law_set_[w * material_count_ + m] && wall_laws_[w * material_count_ + m].node_pair) return false;
  }
  return true;
}

std::vector<real> ContactModel::centring_depths(const Model& model) const {
  std::vector<real> depth(model.particles().size(), 0);
  for (index_t p = 0; p < static_cast<index_t>(depth.size()); ++p) {
    if (centres_particle(model, p)) depth[p] = centring_depth(p);
  }
  return depth;
}

void ContactModel::find_surface_particles() {
  surface_particles_.assign(particle_material_.size(), 0);
  any_surface_ = false;
  for (index_t p = 0; p < static_cast<index_t>(surface_particles_.size()); ++p) {
    const index_t m = particle_material_[p];
    for (index_t b = 0; b < material_count_; ++b) {
      if (law_set_[m * material_count_ + b] && laws_[m * material_count_ + b].surface)
        surface_particles_[p] = 1;
    }
    any_surface_ = any_surface_ || surface_particles_[p];
  }
}

real ContactModel::centring_depth(index_t p) const {
  // The node's contact radius over h/2, from its material's law with itself, or else its first
  // law with another material or a wall.
  const index_t m = particle_material_[p];
  const contact::Law* law = law_set_[m * material_count_ + m] ? &laws_[m * material_count_ + m] : nullptr;
  for (index_t b = 0; law == nullptr && b < material_count_; ++b) {
    if (law_set_[m * material_count_ + b]) law = &laws_[m * material_count_ + b];
  }
  for (std::size_t w = 0; law == nullptr && w < walls_.size(); ++w) {
    if (wall_law_set_[w * material_count_ + m]) law = &wall_laws_[w * material_count_ + m];
  }
  if (law == nullptr) return 0;
  return contact::node_contact_radius(*law, particle_side_[p]) / (0.5 * particle_side_[p].mesh_size);
}

real ContactModel::pair_reach(const Model& model, index_t i, index_t j, bool same_body) const {
  const auto& owner = model.node_particle();
  const contact::Law& law = laws_[model.node_material()[i] * material_count_ + model.node_material()[j]];
  const real rc = contact::resolve_contact_radius(law, particle_side_[owner[i]], particle_side_[owner[j]]);
  const SurfaceAnchor* ai = centres_.anchor(model, i);
  const SurfaceAnchor* aj = centres_.anchor(model, j);
  if (same_body || !law.surface || (ai == nullptr && aj == nullptr)) {
    // Spheres at the contact centres, below the list positions.
    return rc + list_offset(model, i, node_radius(law, model, i, j, rc)) +
           list_offset(model, j, node_radius(law, model, j, i, rc));
  }
  const real support_i = contact::surface_support_factor * particle_side_[owner[i]].mesh_size;
  const real support_j = contact::surface_support_factor * particle_side_[owner[j]].mesh_size;
  if (ai != nullptr && aj != nullptr) return std::max(support_i, support_j);
  if (aj != nullptr) return support_j + node_radius(law, model, i, j, rc);  // i's sphere probes j's surface
  return support_i + node_radius(law, model, j, i, rc);
}

real ContactModel::list_offset(const Model& model, index_t i, real radius) const {
  const SurfaceAnchor* anchor = centres_.anchor(model, i);
  return anchor != nullptr && surface_particle(model.node_particle()[i]) ? radius * anchor->reach : 0.0;
}

real ContactModel::largest_pair_reach(const Model& model) const {
  // Rc, plus the centres' depths below the surface points and the surface law's support where
  // particles use it.
  real coarsest = 0;
  for (index_t p = 0; p < model.particles().size(); ++p) {
    if (surface_particle(p)) coarsest = std::max(coarsest, model.particles()[p].mesh_size);
  }
  if (coarsest == 0) return max_contact_radius_;
  real widest = 1;
  for (const Shape& shape : model.shapes()) {
    for (const SurfaceAnchor& a : shape.anchors.anchors) widest = std::max<real>(widest, a.reach);
  }
  return std::max(max_contact_radius_ * (1 + widest),
                  contact::surface_support_factor * coarsest + max_contact_radius_);
}

contact::PairLaw ContactModel::pair_law(index_t p, index_t q) const {
  return contact::resolve(laws_[particle_material_[p] * material_count_ + particle_material_[q]],
                          particle_side_[p], particle_side_[q], dimension_);
}

contact::PairLaw ContactModel::wall_law(index_t wall, index_t p) const {
  return contact::resolve_wall(wall_laws_[wall * material_count_ + particle_material_[p]], particle_side_[p],
                               dimension_);
}

void ContactModel::set_law(index_t a, index_t b, const contact::Law& law) {
  if (a >= material_count_ || b >= material_count_) throw InputError("contact law names an unknown material");
  require_valid(law, "contact law");
  laws_[a * material_count_ + b] = law;
  laws_[b * material_count_ + a] = law;
  damping_tables_[a * material_count_ + b] = damping_tables_[b * material_count_ + a] =
      contact::DampingTable(law.damping_ratio);
  law_set_[a * material_count_ + b] = law_set_[b * material_count_ + a] = 1;
  any_law_ = true;
  any_rolling_ = any_rolling_ || law.rolling_friction > 0;
  const contact::ContactSide coarsest_a{material_max_mesh_size_[a], 0, 0};
  const contact::ContactSide coarsest_b{material_max_mesh_size_[b], 0, 0};
  max_contact_radius_ =
      std::max(max_contact_radius_, contact::resolve_contact_radius(law, coarsest_a, coarsest_b));
  find_surface_particles();
  built_ = false;
  centres_.forget();
  opened_rest_.clear();
}

index_t ContactModel::add_wall(Wall wall, int dimension) {
  wall.validate(dimension);
  walls_.push_back(std::move(wall));
  wall_laws_.resize(walls_.size() * material_count_);
  wall_damping_tables_.resize(wall_laws_.size());
  wall_law_set_.resize(walls_.size() * material_count_, 0);
  wall_reactions_.assign(walls_.size(), {0, 0, 0, 0, 0, 0});
  built_ = false;
  return static_cast<index_t>(walls_.size() - 1);
}

void ContactModel::set_wall_law(index_t wall, index_t material, const contact::Law& law) {
  if (wall >= walls_.size() || material >= material_count_)
    throw InputError("wall law names an unknown wall or material");
  require_valid(law, "wall contact law");
  wall_laws_[wall * material_count_ + material] = law;
  wall_damping_tables_[wall * material_count_ + material] = contact::DampingTable(law.damping_ratio);
  wall_law_set_[wall * material_count_ + material] = 1;
  any_rolling_ = any_rolling_ || law.rolling_friction > 0;
  const contact::ContactSide coarsest{material_max_mesh_size_[material], 0, 0};
  max_contact_radius_ = std::max(max_contact_radius_, contact::resolve_wall_contact_radius(law, coarsest));
  built_ = false;
  centres_.forget();
}

void ContactModel::set_skin(real skin) {
  if (!(skin > 0) || !std::isfinite(skin)) throw InputError("the neighbour-list skin must be positive");
  skin_ = skin;
  built_ = false;
}

std::vector<ContactModel::Partner> ContactModel::partners(const Model& model) const {
  const auto& particles = model.particles();
  std::vector<Partner> result(particles.size());
  for (std::size_t p = 0; p < particles.size(); ++p) {
    result[p].material = particles[p].material;
    result[p].side = particle_side_[p];
  }
  for (index_t i = 0; i < model.node_count(); ++i) {
    Partner& partner = result[model.node_particle()[i]];
    partner.largest_volume = std::max(partner.largest_volume, model.volumes()[i]);
  }
  return result;
}

real ContactModel::stable_time_step(const Model& model, const std::vector<Partner>& partners) const {
  const real neighbours = dimension_ == 2 ? 4.0 : 6.0;
  const auto& particles = model.particles();
  const std::size_t count = particles.size();
  std::vector<real> largest_volume(count, 0);
  for (index_t i = 0; i < model.node_count(); ++i) {
    const index_t p = model.node_particle()[i];
    largest_volume[p] = std::max(largest_volume[p], model.volumes()[i]);
  }
  // max over partners q of kn(p, q) V_max(q) for partners as fine or finer, kn(p, q)
  // min(V_max(p), V_max(q)) for coarser ones (node-pair law: V_max(q) for all). kn depends on q only
  // through the finer particle's horizon, so sort each material's partners by mesh size: partners
  // finer than p give kn(q) V(q) (a prefix maximum), coarser ones kn(p) V(q) (a suffix maximum of V).
  std::vector<real> stiffness(count, 0);
  std::vector<std::vector<index_t>> own(material_count_), by_material(material_count_);
  for (std::size_t p = 0; p < count; ++p) own[particles[p].material].push_back(static_cast<index_t>(p));
  for (std::size_t q = 0; q < partners.size(); ++q) {
    if (partners[q].material >= material_count_) throw InputError("contact partner of an unknown material");
    by_material[partners[q].material].push_back(static_cast<index_t>(q));
  }
  for (auto& list : by_material) {
    std::sort(list.begin(), list.end(), [&](index_t p, index_t q) {
      return partners[p].side.mesh_size < partners[q].side.mesh_size ||
             (partners[p].side.mesh_size == partners[q].side.mesh_size && p < q);
    });
  }
  for (index_t a = 0; a < material_count_; ++a) {
    for (index_t b = 0; b < material_count_; ++b) {
      if (!law_set_[a * material_count_ + b] || by_material[b].empty()) continue;
      const contact::Law& law = laws_[a * material_count_ + b];
      const real modulus_a = model.materials()[a].dilatation_modulus;
      const auto& partners_b = by_material[b];
      std::vector<real> prefix(partners_b.size()), suffix(partners_b.size());
      for (std::size_t k = 0; k < partners_b.size(); ++k) {
        const Partner& q = partners[partners_b[k]];
        const real kn =
            contact::resolve(law, {q.side.mesh_size, q.side.horizon, modulus_a}, q.side, dimension_)
                .normal_stiffness;
        prefix[k] = std::max(k ? prefix[k - 1] : 0.0, kn * q.largest_volume);
      }
      for (std::size_t k = partners_b.size(); k-- > 0;) {
        suffix[k] =
            std::max(k + 1 < partners_b.size() ? suffix[k + 1] : 0.0, partners[partners_b[k]].largest_volume);
      }
      for (const index_t p : own[a]) {
        const real h = particle_side_[p].mesh_size;
        // Finer-or-equal partners: those up to the last with mesh size <= h.
        const auto split =
            std::upper_bound(partners_b.begin(), partners_b.end(), h,
                             [&](real value, index_t q) { return value < partners[q].side.mesh_size; });
        const std::size_t k = static_cast<std::size_t>(split - partners_b.begin());
        // Same-size partners may have a smaller horizon: count them on both sides.
        const auto first_equal =
            std::lower_bound(partners_b.begin(), partners_b.end(), h,
                             [&](index_t q, real value) { return partners[q].side.mesh_size < value; });
        const std::size_t e = static_cast<std::size_t>(first_equal - partners_b.begin());
        const real finer = k > 0 ? prefix[k - 1] : 0.0;
        const real coarser =
            e < partners_b.size()
                ? contact::resolve(law, particle_side_[p], partners[partners_b[e]].side, dimension_)
                          .normal_stiffness *
                      (law.node_pair ? suffix[e] : std::min(largest_volume[p], suffix[e]))
                : 0.0;
        stiffness[p] = std::max({stiffness[p], finer, coarser});
      }
    }
  }
  real dt = std::numeric_limits<real>::infinity();
  for (std::size_t p = 0; p < count; ++p) {
    for (std::size_t w = 0; w < walls_.size(); ++w) {
      if (wall_law_set_[w * material_count_ + particles[p].material]) {
        stiffness[p] = std::max(
            stiffness[p],
            wall_law(static_cast<index_t>(w), static_cast<index_t>(p)).normal_stiffness * largest_volume[p]);
      }
    }
    if (stiffness[p] > 0) {
      const real density = model.materials()[particles[p].material].params.density;
      dt = std::min(dt, std::sqrt(2.0 * density / (2.0 * neighbours * stiffness[p])));
    }
  }
  return dt;
}

std::size_t ContactModel::memory_bytes() const {
  auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  return bytes(laws_) + bytes(wall_laws_) + bytes(node_body_) + bytes(body_mass_) +
         bytes(body_node_offsets_) + bytes(body_nodes_) + bytes(positions_at_build_) + bytes(pair_offsets_) +
         bytes(pair_partner_) + bytes(pair_slot_) + bytes(wall_offsets_) + bytes(wall_entry_) +
         bytes(wall_slot_) + bytes(slots_) + bytes(slot_law_index_) + bytes(resolved_laws_) +
         bytes(slot_stiffness_) + collisions_.memory_bytes() + bytes(pair_stiffness_) + bytes(wall_points_) +
         bytes(wall_entry_stiffness_) + bytes(wall_entry_reaction_) + bytes(springs_) + bytes(free_springs_) +
         bytes(pair_spring_) + bytes(wall_spring_) + bytes(contact_nodes_) + bytes(body_contact_offsets_) +
         bytes(body_touch_) + bytes(touching_bodies_) + bytes(slot_touch_) + bytes(body_motion_) +
         bytes(body_rotation_) + bytes(body_rotated_) + bytes(rotated_bodies_) + bytes(body_rotation_slot_) +
         bytes(body_load_) + bytes(slot_force_) + bytes(slot_normal_) + bytes(slot_point_) +
         bytes(slot_load_) + bytes(damping_tables_) + bytes(wall_damping_tables_) + bytes(wall_slot_terms_) +
         bytes(slot_surface_normal_) + bytes(touching_nodes_) + bytes(touching_normals_) +
         centres_.memory_bytes() + bytes(anchor_forces_) + bytes(entry_group_) + bytes(entry_target_) +
         bytes(taking_part_) + bytes(opened_rest_) + bytes(surface_nodes_) + bytes(surface_slot_) +
         bytes(surface_points_) + bytes(surface_sizes_) + bytes(surface_stretches_) + bytes(groups_) +
         bytes(group_offsets_) + bytes(probes_) + bytes(group_probe_);
}

std::array<index_t, 2> ContactModel::first_wall_penetration(const Model& model, const State& state) const {
  std::vector<WallContact> found;
  for (index_t i = 0; i < model.node_count(); ++i) {
    for (std::size_t w = 0; w < walls_.size(); ++w) {
      if (!wall_law_set_[w * material_count_ + model.node_material()[i]]) continue;
      const auto p = walls_[w].to_reference(&state.positions[3 * i], state.time);
      for (std::size_t s = 0; s < walls_[w].surfaces.size(); ++s) {
        found.clear();
        walls_[w].contacts(s, p, 0.0, dimension_, found);
        for (const WallContact& c : found) {
          if (c.distance < 0) return {i, static_cast<index_t>(w)};
        }
      }
    }
  }
  return {model.node_count(), 0};
}

std::array<index_t, 2> ContactModel::first_overlap(const Model& model, const State& state, real fraction) {
  const index_t n = model.node_count();
  if (!any_law_ || n == 0) return {n, n};
  if (!centres_.found()) centres_.find(model, state, centring_depths(model), surface_particles_);
  real finest = std::numeric_limits<real>::infinity();
  for (const Particle& p : model.particles()) finest = std::min(finest, p.mesh_size);
  const real radius = fraction * finest;
  const CellGrid grid = CellGrid::build(state.positions, 0, n, radius);
  const auto& owner = model.node_particle();
  for (index_t i = 0; i < n; ++i) {
    index_t hit = n;
    grid.for_each_within(state.positions, i, radius, dimension_, [&](index_t j, real r2) {
      if (hit != n || owner[j] == owner[i] || !interact(model, i, j) || between_surfaces(model, i, j)) return;
      const real limit =
          fraction * std::min(model.particles()[owner[i]].mesh_size, model.particles()[owner[j]].mesh_size);
      if (r2 < limit * limit) hit = j;
    });
    if (hit != n) return {i, hit};
  }
  return first_surface_overlap(model, state, fraction);
}

bool ContactModel::interact(const Model& model, index_t i, index_t j) const {
  return law_set_[model.node_material()[i] * material_count_ + model.node_material()[j]] != 0;
}

bool ContactModel::between_surfaces(const Model& model, index_t i, index_t j) const {
  // Under the surface law a node that carries a surface point meets the other particle at its
  // surface, where at rest it may lie arbitrarily close to the other's nodes (a mesh's boundary
  // vertices, a lattice's corner nodes): first_surface_overlap judges those.
  const auto& owner = model.node_particle();
  return surface_particles_[owner[i]] && surface_particles_[owner[j]] &&
         (on_surface(model, i) || on_surface(model, j));
}

std::array<index_t, 2> ContactModel::first_surface_overlap(const Model& model, const State& state,
                                                           real fraction) const {
  // Surface point s_i of one particle and the nearest surface point s_j of another (within 4
  // mesh sizes): they overlap where s_i lies deeper than fraction h inside j's osculating
  // sphere and s_j deeper than that inside the sphere of the point of i's particle nearest to
  // it (one side alone misleads at a corner, whose sphere is one face's plane).
  const index_t n = model.node_count();
  const auto& owner = model.node_particle();
  std::vector<index_t> nodes;
  std::vector<real> points(3 * static_cast<std::size_t>(n), 0.0);
  real coarsest = 0;
  for (index_t i = 0; i < n; ++i) {
    if (!surface_particles_[owner[i]] || !on_surface(model, i)) continue;
    nodes.push_back(i);
    const vec3 s = centres_.at_surface(model, state, i);
    for (int c = 0; c < 3; ++c) points[3 * i + c] = s[c];
    coarsest = std::max(coarsest, model.particles()[owner[i]].mesh_size);
  }
  if (nodes.empty()) return {n, n};
  const real reach = 4 * coarsest;
  const CellGrid grid = CellGrid::build(points, nodes, reach);
  auto nearest = [&](index_t i, auto&& wanted) {
    index_t best = n;
    real best_r2 = reach * reach;
    grid.for_each_within(points, i, reach, dimension_, [&](index_t j, real r2) {
      if (wanted(j) && (r2 < best_r2 || (r2 == best_r2 && j < best))) best = j, best_r2 = r2;
    });
    return best;
  };
  for (const index_t i : nodes) {
    const index_t j = nearest(i, [&](index_t k) { return owner[k] != owner[i] && interact(model, i, k); });
    if (j == n) continue;
    const real limit =
        fraction * std::min(model.particles()[owner[i]].mesh_size, model.particles()[owner[j]].mesh_size);
    if (!(depth_inside(model, state, i, j) > limit)) continue;
    const index_t k = nearest(j, [&](index_t m) { return owner[m] == owner[i]; });
    if (k != n && depth_inside(model, state, j, k) > limit) return {i, j};
  }
  return {n, n};
}

real ContactModel::depth_inside(const Model& model, const State& state, index_t probe, index_t node) const {
  real size = 0;
  const contact::SurfacePoint point = surface_point_now(centres_.seen(model, node), state, node, size);
  const vec3 p = surface_point_now(centres_.seen(model, probe), state, probe, size).position;
  // Support far beyond any probe: the sphere's distance, whatever the weight.
  return -contact::point_terms(point, p, 1e3 * model.particles()[model.node_particle()[node]].mesh_size)
              .distance;
}

}  // namespace granulate
