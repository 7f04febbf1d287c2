#include "granulate/contact/contact_model.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "granulate/cell_grid.hpp"

namespace granulate {
namespace {

using vec = std::array<real, 3>;

/// Centre of mass and mean velocity of a body (V = sum m v / M): the body-level dashpot acts on
/// the bodies' approach speed along the contact normal.
struct BodyMotion {
  vec centre{0, 0, 0};
  vec velocity{0, 0, 0};
};

BodyMotion body_motion(const Model& model, const State& state, const index_t* nodes, index_t count) {
  BodyMotion motion;
  const auto& x = state.positions;
  const auto& v = state.velocities;
  real mass = 0;
  for (index_t slot = 0; slot < count; ++slot) {
    const index_t i = nodes[slot];
    const real m = model.node_density()[i] * model.volumes()[i];
    mass += m;
    for (int k = 0; k < 3; ++k) {
      motion.centre[k] += m * x[3 * i + k];
      motion.velocity[k] += m * v[3 * i + k];
    }
  }
  for (int k = 0; k < 3; ++k) {
    motion.centre[k] /= mass;
    motion.velocity[k] /= mass;
  }
  return motion;
}

void require_valid(const contact::Law& law, const char* what) {
  const bool radius = law.contact_radius > 0 || (law.contact_radius == 0 && law.contact_radius_factor > 0);
  const bool stiffness = law.normal_stiffness > 0 || (law.normal_stiffness == 0 && law.stiffness_factor > 0);
  if (!radius || !stiffness || !(law.damping_ratio >= 0) || !(law.damping_ratio < 1) ||
      !(law.friction >= 0) || !(law.slip_velocity > 0) ||
      !std::isfinite(law.contact_radius + law.contact_radius_factor) ||
      !std::isfinite(law.normal_stiffness + law.stiffness_factor)) {
    throw InputError(
        std::string(what) +
        " needs a positive contact radius (or factor), stiffness (or factor) and slip velocity, a "
        "damping ratio in [0, 1) and a non-negative friction coefficient");
  }
}

bool intact_bond(const Model& model, const State& state, index_t i, index_t j) {
  const NodeBonds bonds = model.node_bonds(i);
  const index_t b = bonds.find(j);
  return b != bonds.count && state.bonds.intact(i, b);
}

}  // namespace

void ContactModel::configure(const Model& model) {
  material_count_ = static_cast<index_t>(model.materials().size());
  laws_.assign(static_cast<std::size_t>(material_count_) * material_count_, {});
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
  built_ = false;
}

contact::PairLaw ContactModel::pair_law(index_t p, index_t q) const {
  return contact::resolve(laws_[particle_material_[p] * material_count_ + particle_material_[q]],
                          particle_side_[p], particle_side_[q], dimension_);
}

contact::PairLaw ContactModel::wall_law(index_t wall, index_t p) const {
  return contact::resolve(wall_laws_[wall * material_count_ + particle_material_[p]], particle_side_[p],
                          particle_side_[p], dimension_);
}

void ContactModel::set_law(index_t a, index_t b, const contact::Law& law) {
  if (a >= material_count_ || b >= material_count_) throw InputError("contact law names an unknown material");
  require_valid(law, "contact law");
  laws_[a * material_count_ + b] = law;
  laws_[b * material_count_ + a] = law;
  law_set_[a * material_count_ + b] = law_set_[b * material_count_ + a] = 1;
  any_law_ = true;
  max_contact_radius_ = std::max(
      max_contact_radius_,
      law.contact_radius > 0
          ? law.contact_radius
          : law.contact_radius_factor * std::min(material_max_mesh_size_[a], material_max_mesh_size_[b]));
  built_ = false;
}

index_t ContactModel::add_wall(Wall wall, int dimension) {
  wall.validate(dimension);
  walls_.push_back(std::move(wall));
  wall_laws_.resize(walls_.size() * material_count_);
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
  wall_law_set_[wall * material_count_ + material] = 1;
  max_contact_radius_ =
      std::max(max_contact_radius_, law.contact_radius > 0
                                        ? law.contact_radius
                                        : law.contact_radius_factor * material_max_mesh_size_[material]);
  built_ = false;
}

void ContactModel::set_skin(real skin) {
  if (!(skin > 0) || !std::isfinite(skin)) throw InputError("the neighbour-list skin must be positive");
  skin_ = skin;
  built_ = false;
}

real ContactModel::stable_time_step(const Model& model) const {
  const real partners = dimension_ == 2 ? 4.0 : 6.0;
  const auto& particles = model.particles();
  const std::size_t count = particles.size();
  std::vector<real> largest_volume(count, 0);
  for (index_t i = 0; i < model.node_count(); ++i) {
    const index_t p = model.node_particle()[i];
    largest_volume[p] = std::max(largest_volume[p], model.volumes()[i]);
  }
  // max over partners q of kn(p, q) V_max(q). kn depends on q only through the finer particle's
  // horizon, so sort each material's particles by mesh size: partners finer than p give
  // kn(q) V(q) (a prefix maximum), coarser ones kn(p) V(q) (a suffix maximum of V).
  std::vector<real> stiffness(count, 0);
  std::vector<std::vector<index_t>> by_material(material_count_);
  for (std::size_t p = 0; p < count; ++p)
    by_material[particles[p].material].push_back(static_cast<index_t>(p));
  for (auto& list : by_material) {
    std::sort(list.begin(), list.end(), [&](index_t p, index_t q) {
      return particle_side_[p].mesh_size < particle_side_[q].mesh_size ||
             (particle_side_[p].mesh_size == particle_side_[q].mesh_size && p < q);
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
        const contact::ContactSide& q = particle_side_[partners_b[k]];
        const real kn =
            contact::resolve(law, {q.mesh_size, q.horizon, modulus_a}, q, dimension_).normal_stiffness;
        prefix[k] = std::max(k ? prefix[k - 1] : 0.0, kn * largest_volume[partners_b[k]]);
      }
      for (std::size_t k = partners_b.size(); k-- > 0;) {
        suffix[k] = std::max(k + 1 < partners_b.size() ? suffix[k + 1] : 0.0, largest_volume[partners_b[k]]);
      }
      for (const index_t p : by_material[a]) {
        const real h = particle_side_[p].mesh_size;
        // Finer-or-equal partners: those up to the last with mesh size <= h.
        const auto split =
            std::upper_bound(partners_b.begin(), partners_b.end(), h,
                             [&](real value, index_t q) { return value < particle_side_[q].mesh_size; });
        const std::size_t k = static_cast<std::size_t>(split - partners_b.begin());
        // Same-size partners may have a smaller horizon: count them on both sides.
        const auto first_equal =
            std::lower_bound(partners_b.begin(), partners_b.end(), h,
                             [&](index_t q, real value) { return particle_side_[q].mesh_size < value; });
        const std::size_t e = static_cast<std::size_t>(first_equal - partners_b.begin());
        const real finer = k > 0 ? prefix[k - 1] : 0.0;
        const real coarser =
            e < partners_b.size() ? pair_law(p, partners_b[e]).normal_stiffness * suffix[e] : 0.0;
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
      dt = std::min(dt, std::sqrt(2.0 * density / (2.0 * partners * stiffness[p])));
    }
  }
  return dt;
}

real ContactModel::largest_displacement(const Model& model, const State& state) const {
  const auto& x = state.positions;
  const std::int64_t n = model.node_count();
  real worst = 0;
#pragma omp parallel for schedule(static) reduction(max : worst)
  for (std::int64_t i = 0; i < n; ++i) {
    real d2 = 0;
    for (int k = 0; k < 3; ++k) {
      const real d = x[3 * i + k] - positions_at_build_[3 * i + k];
      d2 += d * d;
    }
    worst = std::max(worst, d2);
  }
  return std::sqrt(worst);
}

bool ContactModel::needs_rebuild(const Model& model, const State& state, real& moved) const {
  moved = 0;
  if (!built_) return true;
  const real half_skin = 0.5 * skin_;
  for (const Wall& wall : walls_) {
    if (wall.motion_bound(time_at_build_, state.time) > half_skin) return true;
  }
  moved = largest_displacement(model, state);
  return moved > half_skin;
}

void ContactModel::update_after_breaks(const Model& model, const State& state, std::uint64_t broken_bonds,
                                       real moved) {
  // Bonds broke, nothing moved far: no grid search. The lists gain every newly unbonded pair
  // that could come within its Rc before the next rebuild: a node moves at most skin/2 from
  // where the lists were built before that, so a pair now at d stays beyond d - skin - 2 w (w:
  // the largest displacement since the build so far). A pair left out now stays out of reach
  // until the next rebuild (w only grows), so only the bonds broken since the last update are
  // candidates. Then the bodies are labelled again.
  label_bodies(model, state, broken_bonds);
  const index_t n = model.node_count();
  const auto& x = state.positions;
  const auto& node_particle = model.node_particle();
  const auto& node_material = model.node_material();
  const real extra = skin_ + 2 * moved;
  std::vector<std::array<index_t, 2>> added;  // (node, partner), both ways
  for (const auto& [i, j] : newly_broken_) {
    const index_t m = node_material[i];  // a bond joins two nodes of one particle
    if (!law_set_[m * material_count_ + m]) continue;
    const real limit =
        contact::resolve_contact_radius(laws_[m * material_count_ + m], particle_side_[node_particle[i]],
                                        particle_side_[node_particle[i]]) +
        extra;
    const real dx = x[3 * j] - x[3 * i], dy = x[3 * j + 1] - x[3 * i + 1], dz = x[3 * j + 2] - x[3 * i + 2];
    if (dx * dx + dy * dy + dz * dz > limit * limit) continue;
    const index_t* listed = pair_partner_.data();
    if (std::binary_search(listed + pair_offsets_[i], listed + pair_offsets_[i + 1], j)) continue;
    added.push_back({i, j});
    added.push_back({j, i});
  }
  newly_broken_.clear();
  if (!added.empty()) {
    std::sort(added.begin(), added.end());
    added.erase(std::unique(added.begin(), added.end()), added.end());
    std::vector<index_t> offsets(static_cast<std::size_t>(n) + 1, 0);
    for (const auto& [i, j] : added) ++offsets[i + 1];
    for (index_t i = 0; i < n; ++i) offsets[i + 1] += offsets[i] + (pair_offsets_[i + 1] - pair_offsets_[i]);
    std::vector<index_t> partners(offsets[n]);
    auto next = added.begin();
    for (index_t i = 0; i < n; ++i) {
      const index_t* begin = pair_partner_.data() + pair_offsets_[i];
      const index_t* end = pair_partner_.data() + pair_offsets_[i + 1];
      index_t* out = partners.data() + offsets[i];
      while (next != added.end() && (*next)[0] == i) {  // merge the (sorted) new partners in
        while (begin != end && *begin < (*next)[1]) *out++ = *begin++;
        *out++ = (*next)[1];
        ++next;
      }
      out = std::copy(begin, end, out);
    }
    pair_offsets_ = std::move(offsets);
    pair_partner_ = std::move(partners);
  }
  finish_lists(model);
  broken_at_build_ = broken_bonds;
  ++statistics_.list_updates;
  statistics_.list_entries = pair_partner_.size();
}

void ContactModel::label_bodies(const Model& model, const State& state, std::uint64_t broken_bonds) {
  if (bodies_labelled_ && broken_bonds == broken_at_labelling_) return;
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
    body_mass_[node_body_[i]] += model.node_density()[i] * model.volumes()[i];
    if (node_kinematic_.empty() || !node_kinematic_[i]) body_kinematic_[node_body_[i]] = 0;
    body_material_[node_body_[i]] = model.node_material()[i];
    body_particle_[node_body_[i]] = model.node_particle()[i];
    ++body_node_offsets_[node_body_[i] + 1];
  }
  for (index_t b = 0; b < count; ++b) body_node_offsets_[b + 1] += body_node_offsets_[b];
  body_nodes_.resize(n);
  std::vector<index_t> fill(body_node_offsets_.begin(), body_node_offsets_.end() - 1);
  for (index_t i = 0; i < n; ++i) body_nodes_[fill[node_body_[i]]++] = i;
}

void ContactModel::finish_lists(const Model& model) {
  // Everything that follows from the lists and the bodies: slots, reduced masses, the laws of
  // the slots, the collision history carried over by slot, and the per-entry scratch.
  const index_t n = model.node_count();
  const auto& node_body = node_body_;
  // Slots: one per pair of bodies that appear in the lists, in sorted order.
  const std::vector<std::array<index_t, 2>> old_slots = slots_;
  const std::vector<real> old_approach = slot_approach_;
  const std::vector<real> old_normal = slot_last_normal_;
  const std::size_t old_particle_slots = particle_slot_count_;
  // Bucketed by the first body (a counting sort), so the sorts are per body and small, and an
  // entry finds its slot among its first body's few slots (fragments make many entries).
  const index_t bodies = static_cast<index_t>(body_mass_.size());
  std::vector<index_t> bucket(static_cast<std::size_t>(bodies) + 1, 0);
  for (index_t i = 0; i < n; ++i) {
    for (index_t e = pair_offsets_[i]; e < pair_offsets_[i + 1]; ++e) {
      ++bucket[std::min(node_body[i], node_body[pair_partner_[e]]) + 1];
    }
  }
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
#pragma omp parallel for schedule(static)
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
  std::vector<std::array<index_t, 2>> wall_keys;
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
  // Reduced masses of the bodies (particles, or fragments once bonds break): two bodies
  // m_p m_q / (m_p + m_q); unbonded nodes of one body (a crack that has not separated it),
  // about m_p / 4; a body and a rigid wall, or a body whose every node is prescribed (a held
  // particle, a meshed wall), the moving body's mass; two such bodies, 0 (no dashpot).
  slot_reduced_mass_.resize(slots_.size());
  slot_law_.resize(slots_.size());
  for (std::size_t s = 0; s < slots_.size(); ++s) {
    slot_law_[s] = s >= particle_slots ? wall_law(slots_[s][1], body_particle_[slots_[s][0]])
                                       : pair_law(body_particle_[slots_[s][0]], body_particle_[slots_[s][1]]);
    const index_t bp = slots_[s][0];
    const real mp = body_kinematic_[bp] ? 0.0 : body_mass_[bp];
    if (s >= particle_slots) {
      slot_reduced_mass_[s] = mp;
    } else if (slots_[s][0] == slots_[s][1]) {
      slot_reduced_mass_[s] = 0.25 * mp;
    } else {
      const index_t bq = slots_[s][1];
      const real mq = body_kinematic_[bq] ? 0.0 : body_mass_[bq];
      slot_reduced_mass_[s] = mp == 0 || mq == 0 ? mp + mq : mp * mq / (mp + mq);
    }
  }
  slot_stiffness_.assign(slots_.size(), 0);
  slot_approach_.assign(slots_.size(), 0);
  slot_last_normal_.assign(3 * slots_.size(), 0);
  // Old and new slots are sorted within their two parts (particle pairs, walls): merge walks.
  auto carry_over = [&](std::size_t slot, std::size_t slot_end, std::size_t old, std::size_t old_end) {
    for (; slot < slot_end && old < old_end; ++slot) {
      while (old < old_end && old_slots[old] < slots_[slot]) ++old;
      if (old < old_end && old_slots[old] == slots_[slot]) {
        slot_approach_[slot] = old_approach[old];
        for (int k = 0; k < 3; ++k) slot_last_normal_[3 * slot + k] = old_normal[3 * old + k];
      }
    }
  };
  carry_over(0, particle_slots, 0, old_particle_slots);
  carry_over(particle_slots, slots_.size(), old_particle_slots, old_slots.size());
  pair_stiffness_.assign(pair_partner_.size(), 0);
  wall_entry_stiffness_.assign(wall_entry_.size(), 0);
  pair_distance_.assign(pair_partner_.size(), 0);
  wall_points_.assign(wall_entry_.size(), {});
  wall_entry_reaction_.assign(wall_entry_.size(), {0, 0, 0, 0, 0, 0});
}

void ContactModel::rebuild(const Model& model, const State& state, std::uint64_t broken_bonds, bool finish) {
  if (skin_ < 0) skin_ = 0.5 * max_contact_radius_;
  const auto& x = state.positions;
  const index_t n = model.node_count();
  const auto& particles = model.particles();
  const auto& node_particle = model.node_particle();
  const auto& node_material = model.node_material();
  const std::size_t particle_count = particles.size();
  const real reach = max_contact_radius_ + skin_;
  newly_broken_.clear();  // the search finds every unbonded pair
  label_bodies(model, state, broken_bonds);

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
  std::vector<std::uint8_t> near_particle(particle_count, 0), near_wall(particle_count, 0);
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

  // Node pairs: a grid over the nodes of particles near another particle or broken.
  std::vector<index_t> searched;
  for (std::size_t p = 0; p < particle_count; ++p) {
    if (!near_particle[p]) continue;
    for (index_t i = particles[p].first_node; i < particles[p].first_node + particles[p].node_count; ++i) {
      searched.push_back(i);
    }
  }
  const CellGrid grid = CellGrid::build(x, searched, reach);
  pair_offsets_.assign(n + 1, 0);
  auto accept = [&](index_t i, index_t j, real r2) {
    const index_t mi = node_material[i], mj = node_material[j];
    if (!law_set_[mi * material_count_ + mj]) return false;
    const real limit =
        contact::resolve_contact_radius(laws_[mi * material_count_ + mj], particle_side_[node_particle[i]],
                                        particle_side_[node_particle[j]]) +
        skin_;
    if (r2 > limit * limit) return false;
    return node_particle[i] != node_particle[j] || !intact_bond(model, state, i, j);
  };
  // One search: each thread keeps its nodes' partners, then copies them into place.
  const std::int64_t searched_count = static_cast<std::int64_t>(searched.size());
#pragma omp parallel
  {
    std::vector<index_t> found_partners;
    std::vector<std::array<index_t, 2>> found_nodes;  // (node, first of its partners)
#pragma omp for schedule(static)
    for (std::int64_t a = 0; a < searched_count; ++a) {
      const index_t i = searched[a];
      const std::size_t first = found_partners.size();
      grid.for_each_within(x, i, reach, dimension_, [&](index_t j, real r2) {
        if (accept(i, j, r2)) found_partners.push_back(j);
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
  }

  // Node-wall candidates.
  wall_offsets_.assign(n + 1, 0);
  std::vector<std::vector<std::array<index_t, 2>>> per_node(n);
  std::vector<index_t> wall_nodes;
  for (std::size_t p = 0; p < particle_count; ++p) {
    if (!near_wall[p]) continue;
    for (index_t i = particles[p].first_node; i < particles[p].first_node + particles[p].node_count; ++i) {
      wall_nodes.push_back(i);
    }
  }
  const std::int64_t wall_node_count = static_cast<std::int64_t>(wall_nodes.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t a = 0; a < wall_node_count; ++a) {
    const index_t i = wall_nodes[a];
    std::vector<WallContact> local;
    for (std::size_t w = 0; w < walls_.size(); ++w) {
      if (!wall_law_set_[w * material_count_ + node_material[i]]) continue;
      const real limit = wall_law(static_cast<index_t>(w), node_particle[i]).contact_radius + skin_;
      const auto p = walls_[w].to_reference(&x[3 * i], state.time);
      for (std::size_t s = 0; s < walls_[w].surfaces.size(); ++s) {
        local.clear();
        walls_[w].contacts(s, p, limit, dimension_, local);
        if (!local.empty()) per_node[i].push_back({static_cast<index_t>(w), static_cast<index_t>(s)});
      }
    }
  }
  for (index_t i = 0; i < n; ++i)
    wall_offsets_[i + 1] = wall_offsets_[i] + static_cast<index_t>(per_node[i].size());
  wall_entry_.clear();
  wall_entry_.reserve(wall_offsets_[n]);
  for (index_t i = 0; i < n; ++i)
    wall_entry_.insert(wall_entry_.end(), per_node[i].begin(), per_node[i].end());

  if (finish) finish_lists(model);

  positions_at_build_ = x;
  time_at_build_ = state.time;
  broken_at_build_ = broken_bonds;
  built_ = true;
  ++statistics_.rebuilds;
  statistics_.list_entries = pair_partner_.size();
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

std::array<index_t, 2> ContactModel::first_overlap(const Model& model, const State& state,
                                                   real fraction) const {
  const index_t n = model.node_count();
  if (!any_law_ || n == 0) return {n, n};
  real finest = std::numeric_limits<real>::infinity();
  for (const Particle& p : model.particles()) finest = std::min(finest, p.mesh_size);
  const real radius = fraction * finest;
  const CellGrid grid = CellGrid::build(state.positions, 0, n, radius);
  const auto& owner = model.node_particle();
  for (index_t i = 0; i < n; ++i) {
    index_t hit = n;
    grid.for_each_within(state.positions, i, radius, dimension_, [&](index_t j, real r2) {
      if (hit != n || owner[j] == owner[i]) return;
      const index_t a = model.node_material()[i], b = model.node_material()[j];
      if (!law_set_[a * material_count_ + b]) return;
      const real limit =
          fraction * std::min(model.particles()[owner[i]].mesh_size, model.particles()[owner[j]].mesh_size);
      if (r2 < limit * limit) hit = j;
    });
    if (hit != n) return {i, hit};
  }
  return {n, n};
}

std::size_t ContactModel::memory_bytes() const {
  auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  return bytes(laws_) + bytes(wall_laws_) + bytes(node_body_) + bytes(body_mass_) +
         bytes(body_node_offsets_) + bytes(body_nodes_) + bytes(positions_at_build_) + bytes(pair_offsets_) +
         bytes(pair_partner_) + bytes(pair_slot_) + bytes(wall_offsets_) + bytes(wall_entry_) +
         bytes(wall_slot_) + bytes(slots_) + bytes(slot_reduced_mass_) + bytes(slot_law_) +
         bytes(slot_stiffness_) + bytes(slot_approach_) + bytes(slot_last_normal_) + bytes(pair_stiffness_) +
         bytes(pair_distance_) + bytes(wall_points_) + bytes(wall_entry_stiffness_) +
         bytes(wall_entry_reaction_);
}

ContactCheckpoint ContactModel::checkpoint() const {
  ContactCheckpoint c;
  c.built = built_;
  c.positions_at_build = positions_at_build_;
  c.time_at_build = time_at_build_;
  c.broken_at_build = broken_at_build_;
  c.skin = skin_;
  c.slots = slots_;
  c.particle_slot_count = particle_slot_count_;
  c.slot_approach = slot_approach_;
  c.slot_normal = slot_last_normal_;
  c.pair_offsets = pair_offsets_;
  c.pair_partners = pair_partner_;
  c.last_time = last_time_;
  c.has_last_time = has_last_time_;
  c.statistics = statistics_;
  c.wall_reactions = wall_reactions_;
  return c;
}

void ContactModel::restore(const Model& model, const State& state, const ContactCheckpoint& saved) {
  if (saved.slot_approach.size() != saved.slots.size() ||
      saved.slot_normal.size() != 3 * saved.slots.size() || saved.particle_slot_count > saved.slots.size() ||
      (saved.built && saved.positions_at_build.size() != 3 * static_cast<std::size_t>(model.node_count())) ||
      saved.wall_reactions.size() != walls_.size()) {
    throw InputError("the checkpoint's contact data do not match this model (nodes or walls differ)");
  }
  skin_ = saved.skin;
  bodies_labelled_ = false;  // the restored bonds may differ from the current ones
  newly_broken_.clear();
  slots_ = saved.slots;
  particle_slot_count_ = saved.particle_slot_count;
  slot_approach_ = saved.slot_approach;
  slot_last_normal_ = saved.slot_normal;
  built_ = false;
  if (saved.built) {
    // Rebuild the lists from the positions and time they were built at: the same lists,
    // and rebuild() carries each pair's collision history over from the restored slots.
    State at_build = state;
    at_build.positions = saved.positions_at_build;
    at_build.time = saved.time_at_build;
    // Lists updated after bond breaks are not those of a search: take the saved ones (a
    // checkpoint without them predates these updates, and a search gives them again).
    const bool saved_lists = saved.pair_offsets.size() == static_cast<std::size_t>(model.node_count()) + 1 &&
                             saved.pair_offsets.back() == saved.pair_partners.size();
    rebuild(model, at_build, saved.broken_at_build, !saved_lists);
    if (saved_lists) {
      pair_offsets_ = saved.pair_offsets;
      pair_partner_ = saved.pair_partners;
      statistics_.list_entries = pair_partner_.size();
      finish_lists(model);
    }
  }
  last_time_ = saved.last_time;
  has_last_time_ = saved.has_last_time;
  statistics_ = saved.statistics;
  wall_reactions_ = saved.wall_reactions;
}

void ContactModel::add_forces(const Model& model, State& state, std::uint64_t broken_bonds) {
  if (!active()) return;
  const auto search_start = std::chrono::steady_clock::now();
  real moved = 0;  // largest node displacement since the build
  if (needs_rebuild(model, state, moved)) {
    rebuild(model, state, broken_bonds);
  } else if (broken_bonds != broken_at_build_) {
    update_after_breaks(model, state, broken_bonds, moved);
  }
  search_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - search_start).count();
  const auto& x = state.positions;
  const auto& v = state.velocities;
  auto& f = state.forces;
  const auto& volume = model.volumes();
  const auto& node_material = model.node_material();
  const std::int64_t n = model.node_count();
  const real t = state.time;

  // Pass A, the only geometry pass: distance and spring stiffness k = kn V_i V_j of every pair
  // entry in contact, and the contact points (normals in the world frame) of every wall entry.
  // The later passes read these back.
#pragma omp parallel
  {
    std::vector<WallContact> found;  // scratch of this thread
#pragma omp for schedule(static)
    for (std::int64_t ii = 0; ii < n; ++ii) {
      const index_t i = static_cast<index_t>(ii);
      for (index_t e = pair_offsets_[i]; e < pair_offsets_[i + 1]; ++e) {
        const index_t j = pair_partner_[e];
        const contact::PairLaw& law = slot_law_[pair_slot_[e]];
        const real dx = x[3 * j] - x[3 * i], dy = x[3 * j + 1] - x[3 * i + 1],
                   dz = x[3 * j + 2] - x[3 * i + 2];
        const real distance = std::sqrt(dx * dx + dy * dy + dz * dz);
        pair_distance_[e] = distance;
        pair_stiffness_[e] = distance < law.contact_radius && distance > 0
                                 ? law.normal_stiffness * volume[i] * volume[j]
                                 : 0.0;
      }
      for (index_t e = wall_offsets_[i]; e < wall_offsets_[i + 1]; ++e) {
        const Wall& wall = walls_[wall_entry_[e][0]];
        const contact::PairLaw& law = slot_law_[wall_slot_[e]];
        found.clear();
        wall.contacts(wall_entry_[e][1], wall.to_reference(&x[3 * i], t), law.contact_radius, dimension_,
                      found);
        WallPoints& points = wall_points_[e];
        points.count = static_cast<std::uint8_t>(std::min(found.size(), points.points.size()));
        for (std::size_t k = 0; k < points.count; ++k) {
          points.points[k] = {found[k].distance, wall.rotate_to_world(found[k].normal, t)};
        }
        wall_entry_stiffness_[e] =
            static_cast<real>(points.count) * law.normal_stiffness * volume[i] * volume[i];
      }
    }
  }
  // Pass B: K per pair of bodies, summed in node order (each node pair is listed twice).
  std::fill(slot_stiffness_.begin(), slot_stiffness_.end(), 0.0);
  std::uint64_t touching = 0, wall_touching = 0;
  for (std::size_t e = 0; e < pair_stiffness_.size(); ++e) {
    slot_stiffness_[pair_slot_[e]] += 0.5 * pair_stiffness_[e];
    touching += pair_stiffness_[e] > 0 ? 1 : 0;
  }
  for (std::size_t e = 0; e < wall_entry_stiffness_.size(); ++e) {
    slot_stiffness_[wall_slot_[e]] += wall_entry_stiffness_[e];
    wall_touching += wall_entry_stiffness_[e] > 0 ? 1 : 0;
  }
  statistics_.node_contacts = touching / 2;
  statistics_.wall_contacts = wall_touching;

  // Damping between bodies (see contact_law.hpp): per pair of touching bodies, a dashpot
  // 2 zeta sqrt(M K_s) along the mean contact normal on the bodies' approach speed, applied to
  // each body as a uniform acceleration. K_s = F / x is the secant stiffness of the collision
  // (contact force over the approach since the bodies touched); the sum of the contact springs
  // K overestimates it when the bodies deform, and the dashpot would then overdamp.
  const auto& node_body = node_body_;
  const std::size_t slot_count = slots_.size();
  std::vector<std::uint8_t> touching_body(body_mass_.size(), 0);
  for (std::size_t slot = 0; slot < slot_count; ++slot) {
    if (slot_stiffness_[slot] == 0) continue;
    touching_body[slots_[slot][0]] = 1;
    if (slot < particle_slot_count_) touching_body[slots_[slot][1]] = 1;
  }
  std::vector<BodyMotion> bodies(body_mass_.size());
  const std::int64_t body_count = static_cast<std::int64_t>(body_mass_.size());
#pragma omp parallel for schedule(dynamic, 16)
  for (std::int64_t p = 0; p < body_count; ++p) {
    if (touching_body[p]) {
      bodies[p] = body_motion(model, state, body_nodes_.data() + body_node_offsets_[p],
                              body_node_offsets_[p + 1] - body_node_offsets_[p]);
    }
  }
  // Spring force and stiffness-weighted normal per slot (from the first body to the second, or
  // from the wall to the particle), summed in node order.
  std::vector<vec> slot_normal(slot_count, vec{0, 0, 0});
  std::vector<real> slot_force(slot_count, 0);
  for (index_t i = 0; i < static_cast<index_t>(n); ++i) {
    for (index_t e = pair_offsets_[i]; e < pair_offsets_[i + 1]; ++e) {
      const index_t j = pair_partner_[e];
      const std::size_t slot = pair_slot_[e];
      if (pair_stiffness_[e] == 0 || node_body[i] == node_body[j] || node_body[i] != slots_[slot][0])
        continue;
      const contact::PairLaw& law = slot_law_[slot];
      const vec d{x[3 * j] - x[3 * i], x[3 * j + 1] - x[3 * i + 1], x[3 * j + 2] - x[3 * i + 2]};
      const real distance = pair_distance_[e];
      const real spring = contact::normal_force(pair_stiffness_[e], law.contact_radius - distance);
      slot_force[slot] += spring;
      for (int k = 0; k < 3; ++k) slot_normal[slot][k] += spring * d[k] / distance;
    }
    for (index_t e = wall_offsets_[i]; e < wall_offsets_[i + 1]; ++e) {
      const contact::PairLaw& law = slot_law_[wall_slot_[e]];
      const WallPoints& points = wall_points_[e];
      for (std::size_t k = 0; k < points.count; ++k) {
        const real spring = contact::normal_force(law.normal_stiffness * volume[i] * volume[i],
                                                  law.contact_radius - points.points[k].distance);
        slot_force[wall_slot_[e]] += spring;
        for (int c = 0; c < 3; ++c) slot_normal[wall_slot_[e]][c] += spring * points.points[k].normal[c];
      }
    }
  }
  const real dt = has_last_time_ ? t - last_time_ : 0.0;
  last_time_ = t;
  has_last_time_ = true;
  std::vector<real> body_damping(3 * body_mass_.size(), 0.0);  // force, then acceleration (pass C)
  std::vector<std::array<real, 6>> wall_damping(walls_.size(), {0, 0, 0, 0, 0, 0});
  for (std::size_t slot = 0; slot < slot_count; ++slot) {
    const bool wall_slot = slot >= particle_slot_count_;
    const index_t p = slots_[slot][0], q = slots_[slot][1];
    const real norm =
        std::sqrt(slot_normal[slot][0] * slot_normal[slot][0] + slot_normal[slot][1] * slot_normal[slot][1] +
                  slot_normal[slot][2] * slot_normal[slot][2]);
    if (!wall_slot && p == q) {  // fragments of one body: damped node pair by node pair
      slot_approach_[slot] = 0;
      continue;
    }
    // A collision lasts until the bodies are back where they first touched (approach x = 0),
    // not while springs are in contact: the surface nodes of deformable bodies chatter (touch,
    // part, touch again) within one collision when the contact is stiffer than the material,
    // and a dashpot restarted at each touch would damp the collision many times over.
    const bool in_contact = slot_stiffness_[slot] > 0 && norm > 0;
    real* last_normal = &slot_last_normal_[3 * slot];
    if (in_contact) {
      for (int k = 0; k < 3; ++k) last_normal[k] = slot_normal[slot][k] / norm;
    } else if (!(slot_approach_[slot] > 0)) {
      slot_approach_[slot] = 0;
      continue;
    }
    const vec normal{last_normal[0], last_normal[1], last_normal[2]};
    real approach;  // closing speed of the two bodies along the normal
    real zeta;
    if (wall_slot) {
      const vec wall_velocity = walls_[q].velocity_at(bodies[p].centre.data(), t);
      approach = -((bodies[p].velocity[0] - wall_velocity[0]) * normal[0] +
                   (bodies[p].velocity[1] - wall_velocity[1]) * normal[1] +
                   (bodies[p].velocity[2] - wall_velocity[2]) * normal[2]);
      zeta = wall_laws_[q * material_count_ + body_material_[p]].damping_ratio;
    } else {
      approach = (bodies[p].velocity[0] - bodies[q].velocity[0]) * normal[0] +
                 (bodies[p].velocity[1] - bodies[q].velocity[1]) * normal[1] +
                 (bodies[p].velocity[2] - bodies[q].velocity[2]) * normal[2];
      zeta = laws_[body_material_[p] * material_count_ + body_material_[q]].damping_ratio;
    }
    slot_approach_[slot] += approach * dt;
    if (!in_contact) {  // a gap within the collision: no spring, no dashpot
      slot_approach_[slot] = std::max(0.0, slot_approach_[slot]);
      continue;
    }
    if (zeta == 0) continue;
    const real K = slot_stiffness_[slot];
    const real secant = slot_approach_[slot] > 0 ? std::min(K, slot_force[slot] / slot_approach_[slot]) : K;
    const real damping = 2.0 * zeta * std::sqrt(slot_reduced_mass_[slot] * secant) * approach;
    for (int k = 0; k < 3; ++k) body_damping[3 * p + k] += (wall_slot ? damping : -damping) * normal[k];
    if (wall_slot) {  // the wall takes the opposite force, at the body's centre of mass
      const vec arm{bodies[p].centre[0] - walls_[q].center[0], bodies[p].centre[1] - walls_[q].center[1],
                    bodies[p].centre[2] - walls_[q].center[2]};
      const vec on_wall{-damping * normal[0], -damping * normal[1], -damping * normal[2]};
      auto& r = wall_damping[q];
      for (int k = 0; k < 3; ++k) r[k] += on_wall[k];
      r[3] += arm[1] * on_wall[2] - arm[2] * on_wall[1];
      r[4] += arm[2] * on_wall[0] - arm[0] * on_wall[2];
      r[5] += arm[0] * on_wall[1] - arm[1] * on_wall[0];
    } else {
      for (int k = 0; k < 3; ++k) body_damping[3 * q + k] += damping * normal[k];
    }
  }

  // The dashpot of a body is a uniform acceleration of its nodes.
  for (std::size_t b = 0; b < body_mass_.size(); ++b) {
    if (touching_body[b]) {
      for (int k = 0; k < 3; ++k) body_damping[3 * b + k] /= body_mass_[b];
    }
  }

  // Pass C: forces; each node gathers its own.
  const real* const density = model.node_density().data();
#pragma omp parallel for schedule(static)
  for (std::int64_t ii = 0; ii < n; ++ii) {
    const index_t i = static_cast<index_t>(ii);
    const index_t body = node_body[i];
    if (touching_body[body]) {
      for (int k = 0; k < 3; ++k) f[3 * i + k] += density[i] * body_damping[3 * body + k];
    }
    if (pair_offsets_[i] == pair_offsets_[i + 1] && wall_offsets_[i] == wall_offsets_[i + 1]) continue;
    const real* xi = &x[3 * i];
    const real* vi = &v[3 * i];
    vec total{0, 0, 0};
    for (index_t e = pair_offsets_[i]; e < pair_offsets_[i + 1]; ++e) {
      if (pair_stiffness_[e] == 0) continue;
      const index_t j = pair_partner_[e];
      const contact::Law& law = laws_[node_material[i] * material_count_ + node_material[j]];
      const real contact_radius = slot_law_[pair_slot_[e]].contact_radius;
      const vec d{x[3 * j] - xi[0], x[3 * j + 1] - xi[1], x[3 * j + 2] - xi[2]};
      const real distance = pair_distance_[e];
      const vec normal{d[0] / distance, d[1] / distance, d[2] / distance};  // from i to j
      const vec relative{vi[0] - v[3 * j], vi[1] - v[3 * j + 1], vi[2] - v[3 * j + 2]};
      const real approach = relative[0] * normal[0] + relative[1] * normal[1] + relative[2] * normal[2];
      const real k = pair_stiffness_[e];
      real push = contact::normal_force(k, contact_radius - distance);
      if (body == node_body[j]) {  // unbonded nodes of one body: a node-pair dashpot
        const real K = slot_stiffness_[pair_slot_[e]];
        const real c = 2.0 * law.damping_ratio * k * std::sqrt(slot_reduced_mass_[pair_slot_[e]] / K);
        push = std::max(0.0, push + contact::damping_force(c, approach));
      }
      const real tangential[3] = {relative[0] - approach * normal[0], relative[1] - approach * normal[1],
                                  relative[2] - approach * normal[2]};
      real friction[3];
      contact::friction_force(law, push, tangential, friction);
      for (int k3 = 0; k3 < 3; ++k3) total[k3] += -push * normal[k3] + friction[k3];
    }
    for (index_t e = wall_offsets_[i]; e < wall_offsets_[i + 1]; ++e) {
      std::array<real, 6>& reaction = wall_entry_reaction_[e];
      reaction = {0, 0, 0, 0, 0, 0};
      if (wall_entry_stiffness_[e] == 0) continue;
      const Wall& wall = walls_[wall_entry_[e][0]];
      const contact::Law& law = wall_laws_[wall_entry_[e][0] * material_count_ + node_material[i]];
      const contact::PairLaw& resolved = slot_law_[wall_slot_[e]];
      const WallPoints& points = wall_points_[e];
      const vec wall_velocity = wall.velocity_at(xi, t);
      const vec relative{vi[0] - wall_velocity[0], vi[1] - wall_velocity[1], vi[2] - wall_velocity[2]};
      const real k = resolved.normal_stiffness * volume[i] * volume[i];
      vec force{0, 0, 0};
      for (std::size_t point = 0; point < points.count; ++point) {
        const vec& normal = points.points[point].normal;  // towards the particle
        const real push = contact::normal_force(k, resolved.contact_radius - points.points[point].distance);
        const real normal_speed = relative[0] * normal[0] + relative[1] * normal[1] + relative[2] * normal[2];
        const real tangential[3] = {relative[0] - normal_speed * normal[0],
                                    relative[1] - normal_speed * normal[1],
                                    relative[2] - normal_speed * normal[2]};
        real friction[3];
        contact::friction_force(law, push, tangential, friction);
        for (int k3 = 0; k3 < 3; ++k3) force[k3] += push * normal[k3] + friction[k3];
      }
      for (int k3 = 0; k3 < 3; ++k3) total[k3] += force[k3];
      const vec arm{xi[0] - wall.center[0], xi[1] - wall.center[1], xi[2] - wall.center[2]};
      reaction = {-force[0],
                  -force[1],
                  -force[2],
                  -(arm[1] * force[2] - arm[2] * force[1]),
                  -(arm[2] * force[0] - arm[0] * force[2]),
                  -(arm[0] * force[1] - arm[1] * force[0])};
    }
    for (int k3 = 0; k3 < 3; ++k3) f[3 * i + k3] += total[k3] / volume[i];
  }

  // Pass D: wall reactions, summed in node order, plus the dashpots' share.
  wall_reactions_ = wall_damping;
  for (std::size_t e = 0; e < wall_entry_.size(); ++e) {
    auto& reaction = wall_reactions_[wall_entry_[e][0]];
    for (int k = 0; k < 6; ++k) reaction[k] += wall_entry_reaction_[e][k];
  }
}

}  // namespace granulate
