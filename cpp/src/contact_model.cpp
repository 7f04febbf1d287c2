#include "granulate/contact/contact_model.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>

#include "granulate/cell_grid.hpp"

namespace granulate {
namespace {

using vec = std::array<real, 3>;

vec cross(const vec& a, const vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

real dot(const vec& a, const vec& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/// Gives back a vector's memory once it holds under half its capacity: lists shrink as bodies
/// part, and a shattered sample's largest lists would otherwise stay allocated for the run.
template <class T>
void release_excess(std::vector<T>& v) {
  if (v.capacity() > 2 * v.size() + 64) v.shrink_to_fit();
}

/// Gives back all of a vector's spare memory, for the arrays made anew at each list build: a
/// copy per build, where the growth of the build would keep up to twice their size.
template <class T>
void fit(std::vector<T>& v) {
  if (v.capacity() > v.size()) v.shrink_to_fit();
}

/// Symmetric 3x3 matrix (xx, yy, zz, xy, xz, yz) times a vector.
vec symmetric_times(const std::array<real, 6>& m, const vec& v) {
  return {m[0] * v[0] + m[3] * v[1] + m[4] * v[2], m[3] * v[0] + m[1] * v[1] + m[5] * v[2],
          m[4] * v[0] + m[5] * v[1] + m[2] * v[2]};
}

/// Inverse of an inertia tensor (xx, yy, zz, xy, xz, yz); in 2D only the zz part (a planar body
/// turns about z). Zero for a body without rotational inertia (one node, or nodes on a line).
std::array<real, 6> inverse_inertia(const std::array<real, 6>& m, int dimension) {
  if (dimension == 2) return {0, 0, m[2] > 0 ? 1 / m[2] : 0.0, 0, 0, 0};
  const real cxx = m[1] * m[2] - m[5] * m[5], cyy = m[0] * m[2] - m[4] * m[4],
             czz = m[0] * m[1] - m[3] * m[3];
  const real cxy = m[4] * m[5] - m[3] * m[2], cxz = m[3] * m[5] - m[4] * m[1],
             cyz = m[3] * m[4] - m[0] * m[5];
  const real det = m[0] * cxx + m[3] * cxy + m[4] * cxz;
  const real scale = (m[0] + m[1] + m[2]) / 3;
  if (!(det > 1e-9 * scale * scale * scale)) return {0, 0, 0, 0, 0, 0};
  return {cxx / det, cyy / det, czz / det, cxy / det, cxz / det, cyz / det};
}

/// Rigid-body motion of a body from its nodes (one pass, moments about its first node, so far
/// from the origin nothing cancels): centre c, velocity V = sum m v / M, inertia
/// I = sum m (|r|^2 1 - r r^T) and angular momentum L = sum m r x (v - V) about c, omega = I^-1 L.
BodyMotion measure_body(const Model& model, const State& state, const index_t* nodes, index_t count,
                        int dimension) {
  const auto& x = state.positions;
  const auto& v = state.velocities;
  const vec origin{x[3 * nodes[0]], x[3 * nodes[0] + 1], x[3 * nodes[0] + 2]};
  real mass = 0;
  vec first{0, 0, 0}, momentum{0, 0, 0}, spin{0, 0, 0};
  std::array<real, 6> second{0, 0, 0, 0, 0, 0};  // sum m r r^T: xx, yy, zz, xy, xz, yz
  for (index_t slot = 0; slot < count; ++slot) {
    const index_t i = nodes[slot];
    const real m = model.node_density()[i] * model.volumes()[i];
    const vec r{x[3 * i] - origin[0], x[3 * i + 1] - origin[1], x[3 * i + 2] - origin[2]};
    const vec p{m * v[3 * i], m * v[3 * i + 1], m * v[3 * i + 2]};
    mass += m;
    const vec rp = cross(r, p);
    for (int k = 0; k < 3; ++k) {
      first[k] += m * r[k];
      momentum[k] += p[k];
      spin[k] += rp[k];
    }
    second[0] += m * r[0] * r[0];
    second[1] += m * r[1] * r[1];
    second[2] += m * r[2] * r[2];
    second[3] += m * r[0] * r[1];
    second[4] += m * r[0] * r[2];
    second[5] += m * r[1] * r[2];
  }
  BodyMotion motion;
  const vec d{first[0] / mass, first[1] / mass, first[2] / mass};  // centre - origin
  for (int k = 0; k < 3; ++k) {
    motion.centre[k] = origin[k] + d[k];
    motion.velocity[k] = momentum[k] / mass;
  }
  // Second moments about the centre, then the inertia tensor.
  const std::array<real, 6> s{second[0] - mass * d[0] * d[0], second[1] - mass * d[1] * d[1],
                              second[2] - mass * d[2] * d[2], second[3] - mass * d[0] * d[1],
                              second[4] - mass * d[0] * d[2], second[5] - mass * d[1] * d[2]};
  const std::array<real, 6> inertia{s[1] + s[2], s[0] + s[2], s[0] + s[1], -s[3], -s[4], -s[5]};
  const vec moment = cross(d, momentum);  // L about c: sum m r x v - M d x V
  const vec angular_momentum{spin[0] - moment[0], spin[1] - moment[1], spin[2] - moment[2]};
  motion.inverse_inertia = inverse_inertia(inertia, dimension);
  motion.angular_velocity = symmetric_times(motion.inverse_inertia, angular_momentum);
  return motion;
}

/// The contact point with the largest spring of a node-wall entry's points (the friction point).
std::size_t deepest_point(const WallContact* points, std::size_t count) {
  std::size_t best = 0;
  for (std::size_t k = 1; k < count; ++k) {
    if (points[k].distance < points[best].distance) best = k;
  }
  return best;
}

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

bool intact_bond(const Model& model, const State& state, index_t i, index_t j) {
  const NodeBonds bonds = model.node_bonds(i);
  const index_t b = bonds.find(j);
  return b != bonds.count && state.bonds.intact(i, b);
}

/// Outward unit normal of the surface at node i, in the current configuration: the opposite of
/// the influence-weighted sum of its intact bonds, sum_j w_ij (y_j - y_i), which points into
/// the body from a surface node. Zero when that sum is under 10 % of sum_j w_ij |x_j - x_i|
/// (reference lengths): inside the body, or a node without bonds.
vec surface_normal(const Model& model, const State& state, index_t i) {
  const NodeBonds bonds = model.node_bonds(i);
  const real* y = state.positions.data();
  vec sum{0, 0, 0};
  real scale = 0;
  for (index_t b = 0; b < bonds.count; ++b) {
    if (!state.bonds.intact(i, b)) continue;
    const index_t j = bonds.neighbor(b);
    const real w = bonds.weight(b);
    for (int c = 0; c < 3; ++c) sum[c] -= w * (y[3 * j + c] - y[3 * i + c]);
    scale += w * bonds.length(b);
  }
  const real norm = std::sqrt(dot(sum, sum));
  if (!(norm > 0.1 * scale)) return {0, 0, 0};
  return {sum[0] / norm, sum[1] / norm, sum[2] / norm};
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

vec3 ContactModel::contact_position(const Model& model, const State& state, index_t i) const {
  if (!centres_.moved(i))
    return {state.positions[3 * i], state.positions[3 * i + 1], state.positions[3 * i + 2]};
  return centres_.at_centre(model, state, i);
}

vec3 ContactModel::contact_velocity(const Model& model, const State& state, index_t i) const {
  if (!centres_.moved(i))
    return {state.velocities[3 * i], state.velocities[3 * i + 1], state.velocities[3 * i + 2]};
  return centres_.centre_velocity(model, state, i);
}

const contact::SurfacePoint& ContactModel::surface_point(index_t j) const {
  return surface_points_[surface_slot_[j]];
}

real ContactModel::probe_stiffness(const Model& model, index_t i, index_t target,
                                   const contact::PairLaw& law) const {
  // Per unit area the contact is as stiff as the sphere law's node pairs of the finer mesh,
  // kn min(V_i, V_t)^2 per (finer h)^(d-1); a probe carries its own node's share of the surface,
  // h_i^(d-1), and its side's share of the contact.
  const real hi = particle_side_[model.node_particle()[i]].mesh_size;
  const real ht = particle_side_[model.node_particle()[target]].mesh_size;
  const real share = ht * ht / (hi * hi + ht * ht);
  const real area =
      dimension_ == 2 ? hi / std::min(hi, ht) : (hi * hi) / (std::min(hi, ht) * std::min(hi, ht));
  return share * area * contact::pair_stiffness(law, model.volumes()[i], model.volumes()[target]);
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

real ContactModel::stable_time_step(const Model& model) const {
  const real partners = dimension_ == 2 ? 4.0 : 6.0;
  const auto& particles = model.particles();
  const std::size_t count = particles.size();
  std::vector<real> largest_volume(count, 0);
  for (index_t i = 0; i < model.node_count(); ++i) {
    const index_t p = model.node_particle()[i];
    largest_volume[p] = std::max(largest_volume[p], model.volumes()[i]);
  }
  // max over partners q of kn(p, q) V_max(q) for partners as fine or finer, kn(p, q)
  // min(V_max(p), V_max(q)) for coarser ones (node-pair law: V_max(q) for all). kn depends on q only
  // through the finer particle's horizon, so sort each material's particles by mesh size: partners
  // finer than p give kn(q) V(q) (a prefix maximum), coarser ones kn(p) V(q) (a suffix maximum of V).
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
        const real coarser = e < partners_b.size()
                                 ? pair_law(p, partners_b[e]).normal_stiffness *
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
      dt = std::min(dt, std::sqrt(2.0 * density / (2.0 * partners * stiffness[p])));
    }
  }
  return dt;
}

real ContactModel::largest_displacement(const Model& model, const State& state) const {
  const std::int64_t n = model.node_count();
  real worst = 0;
#pragma omp parallel for schedule(static) reduction(max : worst)
  for (std::int64_t i = 0; i < n; ++i) {
    const index_t node = static_cast<index_t>(i);
    const real* y = &state.positions[3 * node];
    const vec3 x = centres_.moved(node) ? centres_.at_list(model, state, node) : vec3{y[0], y[1], y[2]};
    real d2 = 0;
    for (int k = 0; k < 3; ++k) {
      const real d = x[k] - positions_at_build_[3 * i + k];
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
  const index_t j = pair_partner_[e];
  return slot_law(pair_slot_[e]).surface && node_body_[i] != node_body_[j] &&
         (on_surface(model, i) || on_surface(model, j));
}

bool ContactModel::breaks_open_new_nodes(const Model& model) const {
  if (taking_part_.empty()) return false;  // every node takes part already
  for (const auto& [i, j] : newly_broken_) {
    for (const index_t k : {i, j}) {
      if (!taking_part_[k] && surface_particle(model.node_particle()[k])) return true;
    }
  }
  return false;
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
  const auto& node_material = model.node_material();
  const real extra = skin_ + 2 * moved;
  std::vector<std::array<index_t, 2>> added;  // (node, partner), both ways
  for (const auto& [i, j] : newly_broken_) {
    const index_t m = node_material[i];  // a bond joins two nodes of one particle
    if (!law_set_[m * material_count_ + m]) continue;
    const real limit = pair_reach(model, i, j, node_body_[i] == node_body_[j]) + extra;
    const vec3 xi = centres_.at_list(model, state, i);
    const vec3 xj = centres_.at_list(model, state, j);
    const real dx = xj[0] - xi[0], dy = xj[1] - xi[1], dz = xj[2] - xi[2];
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
    // Merge the (sorted) new partners in; listed entries keep their friction springs.
    std::vector<index_t> partners(offsets[n]), springs(offsets[n], no_spring);
    auto next = added.begin();
    for (index_t i = 0; i < n; ++i) {
      index_t old = pair_offsets_[i], out = offsets[i];
      auto copy_old = [&] {
        springs[out] = pair_spring_[old];
        partners[out++] = pair_partner_[old++];
      };
      while (next != added.end() && (*next)[0] == i) {
        while (old < pair_offsets_[i + 1] && pair_partner_[old] < (*next)[1]) copy_old();
        partners[out++] = (*next)[1];
        ++next;
      }
      while (old < pair_offsets_[i + 1]) copy_old();
    }
    pair_offsets_ = std::move(offsets);
    pair_partner_ = std::move(partners);
    pair_spring_ = std::move(springs);
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
#pragma omp parallel for schedule(static)
  for (std::int64_t ii = 0; ii < static_cast<std::int64_t>(n); ++ii) {
    const index_t i = static_cast<index_t>(ii);
    walk(kept.pair_offsets, kept.pair_partner, kept.pair_spring, pair_offsets_, pair_partner_, pair_spring_,
         i);
    walk(kept.wall_offsets, kept.wall_entry, kept.wall_spring, wall_offsets_, wall_entry_, wall_spring_, i);
  }
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
  const index_t n = model.node_count();
  const auto& node_body = node_body_;
  // Slots: one per pair of bodies that appear in the lists, in sorted order.
  const std::vector<std::array<index_t, 2>> old_slots = slots_;
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
  slot_stiffness_.assign(slots_.size(), 0);
  // The collisions carry over by slot. Old and new slots are sorted within their two parts
  // (particle pairs, walls): merge walks.
  std::vector<index_t> old_of_new(slots_.size(), contact::CollisionStore::none);
  auto carry_over = [&](std::size_t slot, std::size_t slot_end, std::size_t old, std::size_t old_end) {
    for (; slot < slot_end && old < old_end; ++slot) {
      while (old < old_end && old_slots[old] < slots_[slot]) ++old;
      if (old < old_end && old_slots[old] == slots_[slot]) old_of_new[slot] = static_cast<index_t>(old);
    }
  };
  carry_over(0, particle_slots, 0, old_particle_slots);
  carry_over(particle_slots, slots_.size(), old_particle_slots, old_slots.size());
  collisions_.renumber(old_of_new);
  group_contact_nodes(model);
  find_groups(model);
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
  // Each entry (i, j) of a node i with a surface point: the group of j that probes i's body.
  entry_target_.assign(pair_partner_.size(), no_group);
#pragma omp parallel for schedule(static)
  for (std::int64_t ii = 0; ii < static_cast<std::int64_t>(n); ++ii) {
    const index_t i = static_cast<index_t>(ii);
    if (surface_slot_[i] == no_group) continue;
    for (index_t e = pair_offsets_[i]; e < pair_offsets_[i + 1]; ++e) {
      const index_t j = pair_partner_[e];
      if (node_body_[j] != node_body_[i]) entry_target_[e] = target_group(i, j);
    }
  }
  probes_.assign(groups_.size(), {});
}

index_t ContactModel::target_group(index_t i, index_t j) const {
  const index_t* begin = pair_partner_.data() + pair_offsets_[j];
  const index_t* end = pair_partner_.data() + pair_offsets_[j + 1];
  const index_t* at = std::lower_bound(begin, end, i);
  return at == end || *at != i ? no_group : entry_group_[static_cast<std::size_t>(at - pair_partner_.data())];
}

void ContactModel::rebuild(const Model& model, const State& state, std::uint64_t broken_bonds, bool finish) {
  if (skin_ < 0) skin_ = 0.5 * max_contact_radius_;
  const KeptLists kept{std::move(pair_offsets_), std::move(pair_partner_), std::move(pair_spring_),
                       std::move(wall_offsets_), std::move(wall_entry_),   std::move(wall_spring_)};
  const std::vector<real>& x = positions_at_build_;
  const index_t n = model.node_count();
  const auto& particles = model.particles();
  const auto& node_particle = model.node_particle();
  const auto& node_material = model.node_material();
  const std::size_t particle_count = particles.size();
  const real reach = largest_pair_reach(model) + skin_;
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
      if (surface[p] && !takes_part(model, state, i)) continue;
      if (surface[p]) taking_part_[i] = 1;
      searched.push_back(i);
    }
  }
  const CellGrid grid = CellGrid::build(x, searched, reach);
  pair_offsets_.assign(n + 1, 0);
  auto accept = [&](index_t i, index_t j, real r2) {
    const index_t mi = node_material[i], mj = node_material[j];
    if (!law_set_[mi * material_count_ + mj]) return false;
    const real limit = pair_reach(model, i, j, node_body_[i] == node_body_[j]) + skin_;
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
      // x is the list position, list_offset out from the contact centre.
      const real radius = wall_law(static_cast<index_t>(w), node_particle[i]).contact_radius;
      const real limit = radius + list_offset(model, i, radius) + skin_;
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

  carry_over_springs(kept, n);
  if (finish) finish_lists(model);

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
         bytes(wall_slot_) + bytes(slots_) + bytes(slot_law_index_) + bytes(resolved_laws_) +
         bytes(slot_stiffness_) + collisions_.memory_bytes() + bytes(pair_stiffness_) + bytes(wall_points_) +
         bytes(wall_entry_stiffness_) + bytes(wall_entry_reaction_) + bytes(springs_) + bytes(free_springs_) +
         bytes(pair_spring_) + bytes(wall_spring_) + bytes(contact_nodes_) + bytes(body_contact_offsets_) +
         bytes(body_touch_) + bytes(touching_bodies_) + bytes(slot_touch_) + bytes(body_motion_) +
         bytes(body_load_) + bytes(slot_force_) + bytes(slot_normal_) + bytes(slot_point_) +
         bytes(slot_load_) + bytes(damping_tables_) + bytes(wall_damping_tables_) +
         bytes(slot_surface_normal_) + bytes(touching_nodes_) + bytes(touching_normals_) +
         centres_.memory_bytes() + bytes(anchor_forces_) + bytes(entry_group_) + bytes(entry_target_) +
         bytes(taking_part_) + bytes(surface_nodes_) + bytes(surface_slot_) + bytes(surface_points_) +
         bytes(surface_sizes_) + bytes(groups_) + bytes(group_offsets_) + bytes(probes_);
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
  // Written out per slot (format 4), Collision{} for the slots without one.
  for (std::size_t slot = 0; slot < slots_.size(); ++slot) {
    const contact::Collision collision = collisions_.get(slot);
    c.slot_approach.push_back(collision.approach);
    c.slot_normal.insert(c.slot_normal.end(), collision.normal.begin(), collision.normal.end());
    c.slot_work.push_back(collision.work);
    c.slot_work.push_back(collision.exponent);
    c.slot_work.push_back(collision.phase);
    if (any_rolling_)
      c.slot_rolling.insert(c.slot_rolling.end(), collision.rolling.begin(), collision.rolling.end());
  }
  c.pair_offsets = pair_offsets_;
  c.pair_partners = pair_partner_;
  for (const vec3& spring : springs_) c.springs.insert(c.springs.end(), spring.begin(), spring.end());
  c.pair_springs = pair_spring_;
  c.wall_springs = wall_spring_;
  c.last_time = last_time_;
  c.has_last_time = has_last_time_;
  c.statistics = statistics_;
  c.wall_reactions = wall_reactions_;
  return c;
}

namespace {

bool all_finite(const std::vector<real>& values) {
  return std::all_of(values.begin(), values.end(), [](real v) { return std::isfinite(v); });
}

/// CSR lists over n nodes: offsets from 0, never decreasing, ending at the partner count;
/// partners are other nodes.
bool valid_lists(const std::vector<index_t>& offsets, const std::vector<index_t>& partners, index_t n) {
  if (offsets.size() != static_cast<std::size_t>(n) + 1 || offsets.front() != 0 ||
      offsets.back() != partners.size())
    return false;
  for (index_t i = 0; i < n; ++i) {
    if (offsets[i + 1] < offsets[i]) return false;
    for (index_t e = offsets[i]; e < offsets[i + 1]; ++e)
      if (partners[e] >= n || partners[e] == i) return false;
  }
  return true;
}

}  // namespace

void ContactModel::check_checkpoint(const Model& model, const ContactCheckpoint& saved) const {
  const index_t n = model.node_count();
  const std::size_t slots = saved.slots.size();
  if (saved.slot_approach.size() != slots || saved.slot_normal.size() != 3 * slots ||
      saved.slot_work.size() != 3 * slots || saved.particle_slot_count > slots ||
      (!saved.slot_rolling.empty() && saved.slot_rolling.size() != 3 * slots) ||
      (saved.built && saved.positions_at_build.size() != 3 * static_cast<std::size_t>(n)) ||
      saved.wall_reactions.size() != walls_.size()) {
    throw InputError("the checkpoint's contact data do not match this model (nodes or walls differ)");
  }
  // Bodies are numbered below the node count; a wall slot's second entry is a wall. Slots are
  // kept sorted (particle slots, then wall slots), which the merge at list builds relies on.
  for (std::size_t k = 0; k < slots; ++k) {
    const bool wall = k >= saved.particle_slot_count;
    const auto& slot = saved.slots[k];
    const bool sorted = k == 0 || k == saved.particle_slot_count || saved.slots[k - 1] < slot;
    if (slot[0] >= n || slot[1] >= (wall ? walls_.size() : n) || !sorted)
      throw InputError("the checkpoint's contact slots are out of range or out of order");
  }
  const bool finite = all_finite(saved.positions_at_build) && all_finite(saved.slot_approach) &&
                      all_finite(saved.slot_normal) && all_finite(saved.slot_work) &&
                      all_finite(saved.slot_rolling) && all_finite(saved.springs) &&
                      std::isfinite(saved.skin) && std::isfinite(saved.time_at_build) &&
                      std::isfinite(saved.last_time);
  if (!finite) throw InputError("the checkpoint's contact data hold non-finite values");
  if (!saved.pair_offsets.empty() && !valid_lists(saved.pair_offsets, saved.pair_partners, n))
    throw InputError("the checkpoint's contact lists are out of range (partners past the node count)");
}

real ContactModel::slot_reduced_mass(std::size_t slot) const {
  const index_t bp = slots_[slot][0], bq = slots_[slot][1];
  const real mp = body_kinematic_[bp] ? 0.0 : body_mass_[bp];
  if (slot >= particle_slot_count_) return mp;
  if (bp == bq) return 0.25 * mp;
  const real mq = body_kinematic_[bq] ? 0.0 : body_mass_[bq];
  return mp == 0 || mq == 0 ? mp + mq : mp * mq / (mp + mq);
}

void ContactModel::restore_collisions(const ContactCheckpoint& saved) {
  // A slot whose values are those of no collision gets no record. A checkpoint without rolling
  // rotations (no law had mu_r > 0 then) restores them as zero.
  collisions_.reset(slots_.size());
  for (std::size_t slot = 0; slot < slots_.size(); ++slot) {
    contact::Collision c;
    c.approach = saved.slot_approach[slot];
    c.work = saved.slot_work[3 * slot];
    c.exponent = static_cast<float>(saved.slot_work[3 * slot + 1]);
    c.phase = static_cast<float>(saved.slot_work[3 * slot + 2]);
    for (int k = 0; k < 3; ++k) c.normal[k] = saved.slot_normal[3 * slot + k];
    if (!saved.slot_rolling.empty()) {
      for (int k = 0; k < 3; ++k) c.rolling[k] = saved.slot_rolling[3 * slot + k];
    }
    if (!(c == contact::Collision{})) collisions_.open(slot) = c;
  }
}

void ContactModel::restore(const Model& model, const State& state, const ContactCheckpoint& saved) {
  check_checkpoint(model, saved);
  skin_ = saved.skin;
  bodies_labelled_ = false;  // the restored bonds may differ from the current ones
  centres_.forget();         // and so may the detached surface nodes
  newly_broken_.clear();
  slots_ = saved.slots;
  particle_slot_count_ = saved.particle_slot_count;
  restore_collisions(saved);
  built_ = false;
  if (saved.built) {
    // Rebuild the lists from the positions and time they were built at: the same lists,
    // and rebuild() carries each pair's collision history over from the restored slots.
    State at_build = state;
    at_build.time = saved.time_at_build;
    positions_at_build_ = saved.positions_at_build;
    centres_.find(model, state, centring_depths(model),
                  surface_particles_);  // which nodes carry surface points
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
    const std::size_t pool = saved.springs.size() / 3;
    auto valid = [&](const std::vector<index_t>& held, std::size_t entries) {
      return held.size() == entries &&
             std::all_of(held.begin(), held.end(), [&](index_t s) { return s == no_spring || s < pool; });
    };
    if (saved.springs.size() % 3 || !valid(saved.pair_springs, pair_partner_.size()) ||
        !valid(saved.wall_springs, wall_entry_.size())) {
      throw InputError("the checkpoint's friction springs do not match its contact lists");
    }
    springs_.resize(pool);
    for (std::size_t k = 0; k < pool; ++k) {
      springs_[k] = {saved.springs[3 * k], saved.springs[3 * k + 1], saved.springs[3 * k + 2]};
    }
    pair_spring_ = saved.pair_springs;
    wall_spring_ = saved.wall_springs;
    compact_springs();
  }
  last_time_ = saved.last_time;
  has_last_time_ = saved.has_last_time;
  statistics_ = saved.statistics;
  wall_reactions_ = saved.wall_reactions;
}

void ContactModel::add_forces(const Model& model, State& state, std::uint64_t broken_bonds) {
  if (!active()) return;
  const auto search_start = std::chrono::steady_clock::now();
  if (!centres_.found()) centres_.find(model, state, centring_depths(model), surface_particles_);
  real moved = 0;  // largest node displacement since the build
  // A crack that opens nodes which took no part in contact needs a search: they may face
  // another body now.
  if (needs_rebuild(model, state, moved) ||
      (broken_bonds != broken_at_build_ && breaks_open_new_nodes(model))) {
    centres_.fill_positions(model, state, positions_at_build_);
    rebuild(model, state, broken_bonds);
  } else if (broken_bonds != broken_at_build_) {
    update_after_breaks(model, state, broken_bonds, moved);
  }
  search_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - search_start).count();
  const real dt = has_last_time_ ? state.time - last_time_ : 0.0;
  last_time_ = state.time;
  has_last_time_ = true;
  if (any_surface_) measure_surface_points(model, state);  // A: the lists' surface points
  measure_contacts(model, state);         //    distances, springs, probes, wall contact points
  sum_slot_stiffness();                   // B: K per pair of bodies; the touching bodies
  measure_bodies(model, state);           //    rigid-body motion of the touching bodies
  measure_surface_normals(model, state);  //    outward normals of the nodes in contact
  sum_slot_springs(model, state);         //    spring force, normal and contact point per slot
  sum_probe_springs();                    //    the same for the surface probes
  slot_dashpots(state, dt);               //    the body dashpots, as loads on the bodies
  slot_rolling_resistance(state, dt);     //    the rolling torques, as couples on the bodies
  slot_redirects();                       //    each collision's force turned to the surface normal
  if (any_surface_) probe_frictions(model, state, dt);  // C: the surface probes' friction
  node_forces(model, state, dt);                        //    springs, friction, fragment dashpots, per node
  probe_couples(state);                                 //    the probes' friction couples, as loads
  body_loads(model, state);  // E: dashpots and friction couples as rigid-body loads
  sum_wall_reactions();      // D: wall reactions
}

real ContactModel::node_radius(const contact::Law& law, const Model& model, index_t i, index_t j,
                               real contact_radius) const {
  const auto& owner = model.node_particle();
  return contact::node_share(law, particle_side_[owner[i]], particle_side_[owner[j]], contact_radius);
}

void ContactModel::measure_surface_points(const Model& model, const State& state) {
  // The surface points of the nodes with list entries, once per step, for every probe that
  // reaches them (surface_slot_ numbers them in node order).
  const std::int64_t count = static_cast<std::int64_t>(surface_nodes_.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t k = 0; k < count; ++k) {
    const index_t j = surface_nodes_[k];
    const SurfaceCentres::Seen seen = centres_.seen(model, j);
    contact::SurfacePoint& point = surface_points_[k];
    const vec3 a = SurfaceCentres::anchored_vector(seen, state.positions, j);
    const real size = std::sqrt(dot(a, a));
    const real* y = state.positions.data();
    for (int c = 0; c < 3; ++c) {
      point.normal[c] = a[c] / size;
      point.position[c] = y[3 * j + c] + seen.surface_length * point.normal[c];
    }
    point.curvature = seen.anchor->curvature / seen.mesh_size;
    surface_sizes_[k] = size;
  }
}

void ContactModel::measure_contacts(const Model& model, const State& state) {
  // The only geometry pass: distance and spring stiffness of every pair entry in contact, and the
  // contact points (normals in the world frame) of every wall entry, and the nodes in contact with
  // another body. The later passes read these.
  const auto& volume = model.volumes();
  const std::int64_t n = model.node_count();
  const real t = state.time;
  touching_nodes_.clear();
#pragma omp parallel
  {
    std::vector<WallContact> found;  // scratch of this thread
    ProbeScratch probe_scratch;
    std::vector<index_t> touching_nodes;
    real deepest = 0;  // overlap / Rc
#pragma omp for schedule(static) nowait
    for (std::int64_t ii = 0; ii < n; ++ii) {
      const index_t i = static_cast<index_t>(ii);
      if (pair_offsets_[i] == pair_offsets_[i + 1] && wall_offsets_[i] == wall_offsets_[i + 1]) continue;
      vec3 xi{0, 0, 0};
      bool have_xi = false;  // the contact centre, where a sphere pair or a wall needs it
      auto centre = [&]() -> const vec3& {
        if (!have_xi) xi = contact_position(model, state, i), have_xi = true;
        return xi;
      };
      bool touching = false;
      for (index_t e = pair_offsets_[i]; e < pair_offsets_[i + 1]; ++e) {
        const index_t j = pair_partner_[e];
        const contact::PairLaw& law = slot_law(pair_slot_[e]);
        if (surface_entry(model, i, e)) {
          pair_stiffness_[e] = 0;  // the surface law (measure_probes) decides
          continue;
        }
        centre();
        const vec3 xj = contact_position(model, state, j);
        const real dx = xj[0] - xi[0], dy = xj[1] - xi[1], dz = xj[2] - xi[2];
        const real distance = std::sqrt(dx * dx + dy * dy + dz * dz);
        pair_stiffness_[e] = distance < law.contact_radius && distance > 0
                                 ? static_cast<float>(contact::pair_stiffness(law, volume[i], volume[j]))
                                 : 0.0f;
        touching = touching || (pair_stiffness_[e] > 0 && !law.node_pair && node_body_[i] != node_body_[j]);
        if (pair_stiffness_[e] > 0 && !law.node_pair)
          deepest = std::max(deepest, 1 - distance / law.contact_radius);
      }
      if (touching) touching_nodes.push_back(i);
      deepest = std::max(deepest, measure_probes(model, state, i, probe_scratch));
      for (index_t e = wall_offsets_[i]; e < wall_offsets_[i + 1]; ++e) {
        const Wall& wall = walls_[wall_entry_[e][0]];
        const contact::PairLaw& law = slot_law(wall_slot_[e]);
        found.clear();
        wall.contacts(wall_entry_[e][1], wall.to_reference(centre().data(), t), law.contact_radius,
                      dimension_, found);
        WallPoints& points = wall_points_[e];
        points.count = static_cast<std::uint8_t>(std::min(found.size(), points.points.size()));
        for (std::size_t k = 0; k < points.count; ++k) {
          points.points[k] = {found[k].distance, wall.rotate_to_world(found[k].normal, t)};
        }
        wall_entry_stiffness_[e] = static_cast<real>(points.count) * wall_spring_stiffness(model, i, e);
      }
    }
#pragma omp critical
    {
      touching_nodes_.insert(touching_nodes_.end(), touching_nodes.begin(), touching_nodes.end());
      statistics_.deepest_overlap = std::max(statistics_.deepest_overlap, deepest);
    }
  }
  std::sort(touching_nodes_.begin(), touching_nodes_.end());  // the same for any thread count
}

real ContactModel::measure_probes(const Model& model, const State& state, index_t i, ProbeScratch& scratch) {
  // Node i's probes of other bodies' surfaces (contact/surface_law.hpp): each group's points
  // in reach that face the probe, their sums, then the gap, its gradient and the push, then
  // each probe entry's share of the probe's stiffness (its in-contact flag). Returns the
  // deepest overlap over Rc. A group with no point in reach is apart (push 0) and costs one
  // distance per entry.
  const auto [group_begin, group_end] = groups_of(i);
  if (group_begin == group_end) return 0;
  const bool surface = on_surface(model, i);
  const vec3 p = centres_.at_surface(model, state, i);
  const index_t first = pair_offsets_[i], last = pair_offsets_[i + 1];
  scratch.points.assign(last - first, nullptr);  // the points in reach (null: none)
  scratch.weights.assign(last - first, 0.0);
  // The distance of each group's nearest point in reach (-1: none yet).
  scratch.nearest.assign(group_end - group_begin, -1);
  for (index_t e = first; e < last; ++e) {  // the points in reach, and each group's nearest
    const index_t g = entry_group_[e];
    if (g == no_group) continue;
    const index_t j = pair_partner_[e];
    const real support = contact::surface_support_factor * particle_side_[model.node_particle()[j]].mesh_size;
    const contact::SurfacePoint& point = surface_point(j);
    const vec d{p[0] - point.position[0], p[1] - point.position[1], p[2] - point.position[2]};
    const real distance = std::sqrt(dot(d, d));
    if (!(distance < support)) continue;
    scratch.points[e - first] = &point;
    real& best = scratch.nearest[g - group_begin];
    if (best < 0) {  // the group's first point in reach: set the probe up
      ProbeState& probe = probes_[g];
      probe = ProbeState{};
      const contact::PairLaw& law = slot_law(pair_slot_[e]);
      const contact::Law& own = laws_[model.node_material()[i] * material_count_ + model.node_material()[j]];
      probe.point = p;
      probe.support = support;
      probe.radius = surface ? 0.0 : node_radius(own, model, i, j, law.contact_radius);
      probe.stiffness = probe_stiffness(model, i, j, law);
      probe.contact_radius = law.contact_radius;
    }
    if (best < 0 || distance < best) {
      best = distance;
      probes_[g].facing = point.normal;
    }
  }
  for (index_t e = first; e < last; ++e) {
    const contact::SurfacePoint* point = scratch.points[e - first];
    if (point == nullptr) continue;
    ProbeState& probe = probes_[entry_group_[e]];
    if (!contact::faces(*point, probe.facing)) continue;
    const contact::PointTerms t = contact::point_terms(*point, p, probe.support);
    scratch.weights[e - first] = t.weight;
    probe.sums.add(t);
  }
  real deepest = 0;
  for (index_t g = group_begin; g < group_end; ++g) {
    ProbeState& probe = probes_[g];
    probe.push = probe.taper = 0;
    if (scratch.nearest[g - group_begin] < 0 || !probe.sums.reached()) continue;
    const real overlap = probe.radius - probe.sums.gap();
    if (!(overlap > 0)) continue;
    probe.gradient = probe.sums.gradient();
    probe.push = probe.stiffness * overlap * contact::surface_taper(probe.sums.weight);
    probe.taper = 0.5 * probe.stiffness * overlap * overlap * contact::surface_taper_slope(probe.sums.weight);
    probe.friction = probe.foot = {0, 0, 0};
    // The overlap that carries force (a probe tapered past the edge of its points does not).
    deepest = std::max(deepest, probe.push / (probe.stiffness * probe.contact_radius));
  }
  for (index_t e = first; e < last; ++e) {
    const index_t g = entry_group_[e];
    if (g == no_group) continue;
    const ProbeState& probe = probes_[g];
    pair_stiffness_[e] =
        probe.push == 0
            ? 0.0f
            : static_cast<float>(probe.stiffness * scratch.weights[e - first] / probe.sums.weight);
  }
  return deepest;
}

real ContactModel::surface_share(const ProbeState& probe, const contact::SurfacePoint& point) const {
  if (!contact::faces(point, probe.facing)) return 0;
  const vec d{probe.point[0] - point.position[0], probe.point[1] - point.position[1],
              probe.point[2] - point.position[2]};
  return contact::surface_weight(std::sqrt(dot(d, d)) / probe.support) / probe.sums.weight;
}

void ContactModel::sum_slot_stiffness() {
  // K per pair of bodies, summed in entry order: each node pair of the sphere law is listed
  // twice; a surface probe's entries share its stiffness.
  std::fill(slot_stiffness_.begin(), slot_stiffness_.end(), 0.0);
  std::uint64_t touching = 0, wall_touching = 0;
  for (std::size_t e = 0; e < pair_stiffness_.size(); ++e) {
    const bool probe = probe_entry(e);
    slot_stiffness_[pair_slot_[e]] += (probe ? 1.0 : 0.5) * pair_stiffness_[e];
    touching += pair_stiffness_[e] > 0 && !probe ? 1 : 0;
  }
  touching /= 2;
  for (const ProbeState& probe : probes_) touching += probe.push > 0 ? 1 : 0;
  for (std::size_t e = 0; e < wall_entry_stiffness_.size(); ++e) {
    slot_stiffness_[wall_slot_[e]] += wall_entry_stiffness_[e];
    wall_touching += wall_entry_stiffness_[e] > 0 ? 1 : 0;
  }
  statistics_.node_contacts = touching;
  statistics_.wall_contacts = wall_touching;
  assign_springs();
  // The touching bodies (in a collision, or in a gap of one) and the slots in contact, numbered
  // in slot order.
  for (const index_t b : touching_bodies_) body_touch_[b] = not_touching;
  touching_bodies_.clear();
  auto touch = [&](index_t body) {
    if (body_touch_[body] != not_touching) return;
    body_touch_[body] = static_cast<index_t>(touching_bodies_.size());
    touching_bodies_.push_back(body);
  };
  index_t in_contact = 0;
  for (std::size_t slot = 0; slot < slots_.size(); ++slot) {
    slot_touch_[slot] = slot_stiffness_[slot] > 0 ? in_contact++ : not_touching;
    if (slot_stiffness_[slot] == 0 && !(collisions_.approach(slot) > 0)) continue;
    touch(slots_[slot][0]);
    if (slot < particle_slot_count_) touch(slots_[slot][1]);
  }
  body_motion_.resize(touching_bodies_.size());
  body_load_.resize(touching_bodies_.size());
  release_excess(body_motion_);
  release_excess(body_load_);
  slot_force_.assign(in_contact, 0.0);
  slot_normal_.assign(in_contact, vec3{0, 0, 0});
  slot_point_.assign(in_contact, vec3{0, 0, 0});
  slot_surface_normal_.assign(in_contact, vec3{0, 0, 0});
  slot_load_.assign(in_contact, vec3{0, 0, 0});
  release_excess(slot_force_);
  for (auto* v : {&slot_normal_, &slot_point_, &slot_surface_normal_, &slot_load_}) release_excess(*v);
}

void ContactModel::measure_bodies(const Model& model, const State& state) {
  const std::int64_t count = static_cast<std::int64_t>(touching_bodies_.size());
#pragma omp parallel for schedule(dynamic, 16)
  for (std::int64_t k = 0; k < count; ++k) {
    const index_t b = touching_bodies_[k];
    body_load_[k] = {0, 0, 0, 0, 0, 0};
    body_motion_[k] = measure_body(model, state, body_nodes_.data() + body_node_offsets_[b],
                                   body_node_offsets_[b + 1] - body_node_offsets_[b], dimension_);
  }
}

void ContactModel::measure_surface_normals(const Model& model, const State& state) {
  // The surface normal of every node in a node pair in contact between two bodies (listed by
  // measure_contacts, in node order, for the look-ups of pair_surface_normal), in parallel.
  touching_normals_.resize(touching_nodes_.size());
  release_excess(touching_nodes_);
  release_excess(touching_normals_);
  const std::int64_t count = static_cast<std::int64_t>(touching_nodes_.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t k = 0; k < count; ++k)
    touching_normals_[k] = surface_normal(model, state, touching_nodes_[k]);
}

void ContactModel::sum_slot_springs(const Model& model, const State& state) {
  // Spring force, spring-weighted normal (from the first body to the second, or from the wall to
  // the particle) and spring-weighted contact point per slot, summed in node order.
  for (const index_t i : contact_nodes_) {
    const vec3 xi = contact_position(model, state, i);
    for (index_t e = pair_offsets_[i]; e < pair_offsets_[i + 1]; ++e) {
      const index_t j = pair_partner_[e];
      const std::size_t slot = pair_slot_[e];
      if (pair_stiffness_[e] == 0 || probe_entry(e) || node_body_[i] == node_body_[j] ||
          node_body_[i] != slots_[slot][0])
        continue;
      const index_t touch = slot_touch_[slot];
      const PairGeometry g = pair_geometry(model, state, i, e);
      const real spring = contact::normal_force(entry_stiffness(model, i, e), g.overlap);
      const vec surface = slot_law(slot).node_pair ? g.normal : pair_surface_normal(i, j, g.normal);
      slot_force_[touch] += spring;
      for (int k = 0; k < 3; ++k) {
        slot_normal_[touch][k] += spring * g.normal[k];
        slot_point_[touch][k] += spring * (xi[k] + g.lever_i * g.normal[k]);
        slot_surface_normal_[touch][k] += spring * surface[k];
      }
    }
    for (index_t e = wall_offsets_[i]; e < wall_offsets_[i + 1]; ++e) {
      const std::size_t slot = wall_slot_[e];
      if (wall_entry_stiffness_[e] == 0) continue;
      const index_t touch = slot_touch_[slot];
      const contact::PairLaw& law = slot_law(slot);
      const WallPoints& points = wall_points_[e];
      for (std::size_t k = 0; k < points.count; ++k) {
        const real overlap = law.contact_radius - points.points[k].distance;
        const real spring = contact::normal_force(wall_spring_stiffness(model, i, e), overlap);
        const real lever = law.contact_radius - 0.5 * overlap;
        slot_force_[touch] += spring;
        for (int c = 0; c < 3; ++c) {
          slot_normal_[touch][c] += spring * points.points[k].normal[c];
          slot_surface_normal_[touch][c] += spring * points.points[k].normal[c];
          slot_point_[touch][c] += spring * (xi[c] - lever * points.points[k].normal[c]);
        }
      }
    }
  }
}

void ContactModel::sum_probe_springs() {
  // The surface probes' pushes, in group order: the force k delta |G| along the surface's normal
  // (from the slot's first body to its second), at the probe point.
  for (std::size_t g = 0; g < groups_.size(); ++g) {
    const ProbeState& probe = probes_[g];
    if (probe.push == 0) continue;
    const std::size_t slot = groups_[g].slot;
    const index_t touch = slot_touch_[slot];
    const real size = std::sqrt(dot(probe.gradient, probe.gradient));
    const real force = probe.push * size;
    // G points out of the target body; the slot's normal from its first body to its second.
    const real sign = groups_[g].body == slots_[slot][0] ? 1.0 : -1.0;
    slot_force_[touch] += force;
    for (int k = 0; k < 3; ++k) {
      const real along = sign * probe.gradient[k] / size;
      slot_normal_[touch][k] += force * along;
      slot_surface_normal_[touch][k] += force * along;
      slot_point_[touch][k] += force * probe.point[k];
    }
  }
}

real ContactModel::spring_energy(const Model& model, const State& state) const {
  if (!built_) return 0;
  real energy = 0;
  for (const index_t i : contact_nodes_) {
    for (index_t e = pair_offsets_[i]; e < pair_offsets_[i + 1]; ++e) {
      if (pair_partner_[e] < i) continue;        // each pair once: the lists hold both directions
      if (surface_entry(model, i, e)) continue;  // the probes below
      const real overlap = pair_geometry(model, state, i, e).overlap;
      if (overlap > 0) energy += 0.5 * entry_stiffness(model, i, e) * overlap * overlap;
    }
    for (index_t e = wall_offsets_[i]; e < wall_offsets_[i + 1]; ++e) {
      const contact::PairLaw& law = slot_law(wall_slot_[e]);
      const WallPoints& points = wall_points_[e];
      for (std::size_t k = 0; k < points.count; ++k) {
        const real overlap = law.contact_radius - points.points[k].distance;
        if (overlap > 0) energy += 0.5 * wall_spring_stiffness(model, i, e) * overlap * overlap;
      }
    }
  }
  // The surface probes, from their last evaluation: k delta^2 tau / 2 = P^2 / (2 k tau).
  for (const ProbeState& probe : probes_) {
    if (probe.push > 0)
      energy += 0.5 * probe.push * probe.push / (probe.stiffness * contact::surface_taper(probe.sums.weight));
  }
  return energy;
}

void ContactModel::slot_dashpots(const State& state, real dt) {
  // Damping between bodies (see contact_law.hpp): per pair of touching bodies, a dashpot
  // 2 zeta sqrt(M K_s) along the mean contact normal on the approach speed of the bodies at the
  // contact point, applied to each body at that point as a rigid-body load. K_s = F / x is the
  // secant stiffness of the collision (contact force over the approach since the bodies
  // touched); the sum of the contact springs K overestimates it when the bodies deform, and the
  // dashpot would then overdamp.
  const real t = state.time;
  std::fill(wall_damping_.begin(), wall_damping_.end(), std::array<real, 6>{0, 0, 0, 0, 0, 0});
  for (std::size_t slot = 0; slot < slots_.size(); ++slot) {
    const bool wall_slot = slot >= particle_slot_count_;
    const index_t p = slots_[slot][0], q = slots_[slot][1];
    if (!wall_slot && p == q) {  // fragments of one body: damped node pair by node pair
      collisions_.close(slot);
      continue;
    }
    const index_t touch = slot_touch_[slot];
    // A collision lasts until the bodies are back where they first touched (approach x = 0),
    // not while springs are in contact: the surface nodes of deformable bodies chatter (touch,
    // part, touch again) within one collision when the contact is stiffer than the material,
    // and a dashpot restarted at each touch would damp the collision many times over.
    const bool in_contact = slot_in_contact(slot);
    if (!in_contact && !(collisions_.approach(slot) > 0)) {  // apart: the collision is over
      collisions_.close(slot);
      continue;
    }
    contact::Collision& collision = collisions_.open(slot);
    if (in_contact) {
      const vec& sum = slot_surface_normal_[touch];
      const real norm = std::sqrt(dot(sum, sum));
      for (int k = 0; k < 3; ++k) collision.normal[k] = sum[k] / norm;
    }
    const vec normal = collision.normal;
    // The contact point: spring-weighted, or the first body's centre in a gap of the collision.
    const vec point = in_contact ? slot_contact_point(touch) : body_motion_[body_touch_[p]].centre;
    const vec velocity_p = rigid_velocity(p, point);
    const vec velocity_q = wall_slot ? walls_[q].velocity_at(point.data(), t) : rigid_velocity(q, point);
    const vec relative{velocity_p[0] - velocity_q[0], velocity_p[1] - velocity_q[1],
                       velocity_p[2] - velocity_q[2]};
    // Closing speed along the normal (which points from p to q, or from the wall to p).
    const real approach = wall_slot ? -dot(relative, normal) : dot(relative, normal);
    collision.approach += approach * dt;
    if (!in_contact) {  // a gap within the collision: no spring, no dashpot
      collision.approach = std::max(0.0, collision.approach);
      continue;
    }
    const real zeta = damping_ratio(slot, collision, approach * dt);
    const real K = slot_stiffness_[slot];
    const real secant = collision.approach > 0 ? std::min(K, slot_force_[touch] / collision.approach) : K;
    const real mass = slot_reduced_mass(slot);
    const real duration = std::numbers::pi * std::sqrt(mass / secant);
    if (duration > 0) collision.phase = static_cast<float>(collision.phase + dt / duration);
    if (zeta == 0) continue;
    const real damping = 2.0 * zeta * std::sqrt(mass * secant) * approach;
    for (int k = 0; k < 3; ++k) slot_load_[touch][k] += damping * normal[k];
    if (wall_slot) {  // the wall takes the opposite force, at the contact point
      add_body_load(p, point, {damping * normal[0], damping * normal[1], damping * normal[2]});
      const vec arm{point[0] - walls_[q].center[0], point[1] - walls_[q].center[1],
                    point[2] - walls_[q].center[2]};
      const vec on_wall{-damping * normal[0], -damping * normal[1], -damping * normal[2]};
      const vec torque = cross(arm, on_wall);
      for (int k = 0; k < 3; ++k) {
        wall_damping_[q][k] += on_wall[k];
        wall_damping_[q][3 + k] += torque[k];
      }
    } else {
      add_body_load(p, point, {-damping * normal[0], -damping * normal[1], -damping * normal[2]});
      add_body_load(q, point, {damping * normal[0], damping * normal[1], damping * normal[2]});
    }
  }
}

void ContactModel::slot_rolling_resistance(const State& state, real dt) {
  // Rolling resistance per pair of touching bodies (contact_law.hpp): the rolling spring on
  // their relative rotation, its torque M on the first body and -M on the second (or the wall),
  // as rigid-body couples.
  if (!any_rolling_) return;
  for (std::size_t slot = 0; slot < slots_.size(); ++slot) {
    if (!resists_rolling(slot)) {
      // In a gap of the collision (chattering surface nodes part for a few steps) the spring
      // keeps its rotation and acts again when they touch; once the bodies are apart it starts
      // again at the next touch.
      contact::Collision* collision = collisions_.find(slot);
      if (collision && !(collision->approach > 0)) collision->rolling = {0, 0, 0};
      continue;
    }
    const vec torque = slot_rolling_torque(state, slot, dt);
    const index_t p = slots_[slot][0], q = slots_[slot][1];
    for (int k = 0; k < 3; ++k) body_load_[body_touch_[p]][3 + k] += torque[k];
    for (int k = 0; k < 3; ++k) {
      if (slot >= particle_slot_count_) {
        wall_damping_[q][3 + k] -= torque[k];
      } else {
        body_load_[body_touch_[q]][3 + k] -= torque[k];
      }
    }
  }
}

bool ContactModel::resists_rolling(std::size_t slot) const {
  auto turns = [&](index_t body) {
    return body_motion_[body_touch_[body]].inverse_inertia != std::array<real, 6>{0, 0, 0, 0, 0, 0};
  };
  const bool wall_slot = slot >= particle_slot_count_;
  const index_t p = slots_[slot][0], q = slots_[slot][1];
  if (!(slot_law(slot).rolling_friction > 0) || (!wall_slot && p == q) || !slot_in_contact(slot))
    return false;
  return turns(p) && (wall_slot || turns(q));
}

bool ContactModel::slot_in_contact(std::size_t slot) const {
  const index_t touch = slot_touch_[slot];
  if (touch == not_touching) return false;
  const vec& sum = slot_surface_normal_[touch];
  return dot(sum, sum) > 0 && slot_force_[touch] > 0;
}

vec3 ContactModel::slot_rolling_torque(const State& state, std::size_t slot, real dt) {
  const contact::PairLaw& law = slot_law(slot);
  const bool wall_slot = slot >= particle_slot_count_;
  const index_t p = slots_[slot][0], q = slots_[slot][1];
  const index_t touch = slot_touch_[slot];
  const BodyMotion& first = body_motion_[body_touch_[p]];
  const BodyMotion* second = wall_slot ? nullptr : &body_motion_[body_touch_[q]];
  const real force = slot_force_[touch];
  const vec point = slot_contact_point(touch);
  auto distance = [&](const vec& centre) {
    const vec arm{point[0] - centre[0], point[1] - centre[1], point[2] - centre[2]};
    return std::sqrt(dot(arm, arm));
  };
  const real rp = distance(first.centre), rq = wall_slot ? 0.0 : distance(second->centre);
  const real radius = wall_slot ? rp : rp * rq / (rp + rq);
  contact::Collision& collision = collisions_.open(slot);  // its normal is this step's (slot_dashpots)
  const vec normal = collision.normal;
  const vec spin_q = wall_slot ? walls_[q].angular_velocity(state.time) : second->angular_velocity;
  const vec spin{first.angular_velocity[0] - spin_q[0], first.angular_velocity[1] - spin_q[1],
                 first.angular_velocity[2] - spin_q[2]};
  const real stiffness = law.tangential_stiffness_ratio * slot_stiffness_[slot] * radius * radius;
  vec torque{0, 0, 0};
  const bool rolls = contact::rolling_torque(stiffness, law.rolling_friction, radius, force, normal.data(),
                                             spin.data(), dt, collision.rolling.data(), torque.data());
  // The dashpot, while the spring holds: C_r = 2 eta_r sqrt(I_r k_r) on the rolling speed.
  const real twist = dot(spin, normal);
  const vec roll{spin[0] - twist * normal[0], spin[1] - twist * normal[1], spin[2] - twist * normal[2]};
  const real speed = std::sqrt(dot(roll, roll));
  if (rolls || !(speed > 0) || !(law.rolling_damping > 0)) return torque;
  const vec axis{roll[0] / speed, roll[1] / speed, roll[2] / speed};
  real compliance = 1 / rolling_inertia(p, first, axis, rp);
  if (!wall_slot) compliance += 1 / rolling_inertia(q, *second, axis, rq);
  const real damping = 2 * law.rolling_damping * std::sqrt(stiffness / compliance);
  for (int k = 0; k < 3; ++k) torque[k] -= damping * roll[k];
  return torque;
}

real ContactModel::rolling_inertia(index_t body, const BodyMotion& motion, const vec3& axis,
                                   real lever) const {
  // I about the axis through the centre, 1 / (a . I^-1 a), plus m r^2 (about the contact point);
  // a body that moves as told (every node prescribed) is as heavy as a wall.
  const real inverse = dot(axis, symmetric_times(motion.inverse_inertia, axis));
  if (body_kinematic_[body] || !(inverse > 0)) return std::numeric_limits<real>::infinity();
  return 1 / inverse + body_mass_[body] * lever * lever;
}

vec3 ContactModel::slot_contact_point(index_t touch) const {
  const real force = slot_force_[touch];
  return {slot_point_[touch][0] / force, slot_point_[touch][1] / force, slot_point_[touch][2] / force};
}

vec3 ContactModel::rigid_velocity(index_t body, const vec3& point) const {
  const BodyMotion& motion = body_motion_[body_touch_[body]];
  const vec turn = cross(motion.angular_velocity, {point[0] - motion.centre[0], point[1] - motion.centre[1],
                                                   point[2] - motion.centre[2]});
  return {motion.velocity[0] + turn[0], motion.velocity[1] + turn[1], motion.velocity[2] + turn[2]};
}

void ContactModel::add_body_load(index_t body, const vec3& point, const vec3& force) {
  const index_t touch = body_touch_[body];
  const BodyMotion& motion = body_motion_[touch];
  const vec torque =
      cross({point[0] - motion.centre[0], point[1] - motion.centre[1], point[2] - motion.centre[2]}, force);
  for (int k = 0; k < 3; ++k) {
    body_load_[touch][k] += force[k];
    body_load_[touch][3 + k] += torque[k];
  }
}

vec3 ContactModel::pair_surface_normal(index_t i, index_t j, const vec3& line) const {
  // The mean of the two surfaces' normals, n_i - n_j (n_j points out of the other body), where
  // both nodes lie on surfaces that face each other (|n_i - n_j| > 1, within 90 degrees of the
  // line of the nodes); the line itself otherwise.
  auto normal = [&](index_t node) {
    const auto at = std::lower_bound(touching_nodes_.begin(), touching_nodes_.end(), node);
    if (at == touching_nodes_.end() || *at != node) return vec{0, 0, 0};  // not measured: the line
    return touching_normals_[static_cast<std::size_t>(at - touching_nodes_.begin())];
  };
  const vec ni = normal(i), nj = normal(j);
  const vec sum{ni[0] - nj[0], ni[1] - nj[1], ni[2] - nj[2]};
  const real norm = std::sqrt(dot(sum, sum));
  if (!(norm > 1.0) || !(dot(sum, line) > 0)) return line;
  return {sum[0] / norm, sum[1] / norm, sum[2] / norm};
}

void ContactModel::slot_redirects() {
  // The node springs of a collision push along the lines of their node pairs, which the node
  // layout tilts (bumps of size h on a curved surface). Their resultant F is turned into the
  // spring-weighted normal of the two surfaces, S: each body gets the difference D = |F| S - F
  // (and its opposite) at the contact point p as a rigid-body load, less its part along the
  // bodies' relative velocity at p, so that it does no work (the loads' power is D . (V_q(p) -
  // V_p(p)), V the bodies' rigid-body velocities): turning the force cannot feed energy into a
  // packing at rest. The nodes keep central forces, and the bodies get equal and opposite loads
  // at one point (momentum and angular momentum conserved). The turn is for impacts: it fades
  // out once a collision has lasted longer than an impact does (impact_share), because in a
  // lasting contact it feeds energy into the bodies (a pile at rest kept contact forces 9-37 %
  // off its weight at any damping; ARCHITECTURE.md).
  for (std::size_t slot = 0; slot < particle_slot_count_; ++slot) {
    const index_t touch = slot_touch_[slot];
    const index_t p = slots_[slot][0], q = slots_[slot][1];
    if (touch == not_touching || p == q || slot_force_[touch] == 0) continue;
    if (slot_law(slot).node_pair) continue;
    const vec& resultant = slot_normal_[touch];  // the springs' force on q
    const vec& surface = slot_surface_normal_[touch];
    const real size = std::sqrt(dot(resultant, resultant)), surface_size = std::sqrt(dot(surface, surface));
    // Turned only by the tilts the node layout gives (up to 30 degrees for a first touch of
    // two node spheres); a larger angle means surfaces the normals do not describe (corners).
    if (!(size > 0) || !(surface_size > 0) || dot(resultant, surface) < 0.7 * size * surface_size) continue;
    const vec point = slot_contact_point(touch);
    vec turn;
    for (int k = 0; k < 3; ++k) turn[k] = size * surface[k] / surface_size - resultant[k];
    const vec vq = rigid_velocity(q, point), vp = rigid_velocity(p, point);
    const vec relative{vq[0] - vp[0], vq[1] - vp[1], vq[2] - vp[2]};
    const real speed2 = dot(relative, relative);
    if (speed2 > 0) {
      const real along = dot(turn, relative) / speed2;
      for (int k = 0; k < 3; ++k) turn[k] -= along * relative[k];
    }
    const real fade = contact::impact_share(collisions_.get(slot).phase);
    for (int k = 0; k < 3; ++k) turn[k] *= fade;
    for (int k = 0; k < 3; ++k) slot_load_[touch][k] += turn[k];
    add_body_load(q, point, turn);
    add_body_load(p, point, {-turn[0], -turn[1], -turn[2]});
  }
}

real ContactModel::damping_ratio(std::size_t slot, contact::Collision& collision, real advance) {
  // The springs' work since the bodies touched, and while they approach, the exponent of the
  // force law it implies: W = F x / (p + 1) for F = k x^p.
  const bool wall_slot = slot >= particle_slot_count_;
  const index_t p = slots_[slot][0], q = slots_[slot][1];
  const std::size_t law = wall_slot ? q * material_count_ + body_material_[p]
                                    : body_material_[p] * material_count_ + body_material_[q];
  if (slot_law(slot).node_pair) {  // PeriDEM's law keeps the linear zeta
    return (wall_slot ? wall_laws_ : laws_)[law].damping_ratio;
  }
  const real force = slot_force_[slot_touch_[slot]], approach = collision.approach;
  collision.work += force * advance;
  if (advance > 0 && collision.work > 0 && approach > 0) {
    collision.exponent = static_cast<float>(std::clamp(force * approach / collision.work - 1, 1.0, 3.0));
  }
  return (wall_slot ? wall_damping_tables_ : damping_tables_)[law].at(collision.exponent);
}

void ContactModel::probe_frictions(const Model& model, const State& state, real dt) {
  const std::int64_t count = static_cast<std::int64_t>(contact_nodes_.size());
#pragma omp parallel
  {
    std::vector<real> shares;  // scratch of this thread
#pragma omp for schedule(static)
    for (std::int64_t k = 0; k < count; ++k) probe_friction(model, state, contact_nodes_[k], dt, shares);
  }
}

void ContactModel::probe_friction(const Model& model, const State& state, index_t i, real dt,
                                  std::vector<real>& shares) {
  const auto [group_begin, group_end] = groups_of(i);
  if (group_begin == group_end) return;
  const index_t material = model.node_material()[i];
  const index_t first = pair_offsets_[i], last = pair_offsets_[i + 1];
  shares.resize(last - first);  // w_k / S of each entry, set for a group's entries before use
  for (index_t g = group_begin; g < group_end; ++g) {
    ProbeState& probe = probes_[g];
    if (probe.push == 0) continue;
    const contact::Law& law = laws_[material * material_count_ + body_material_[groups_[g].body]];
    if (law.friction == 0 && !law.peridem_friction) continue;
    // The slip of p against the target's surface there, each side moving with its nodes and
    // its body's rotation: v_i + w_A x (p - y_i) - sum_k (w_k / S) (v_k + w_B x (s_k - y_k)).
    // The friction force acts on the nodes (the probe's, and the targets' in shares w_k / S),
    // and the couples that put it at p go to the bodies as loads (probe_couples): the springs
    // see no anchor's vibration.
    const real* y = state.positions.data();
    const real* u = state.velocities.data();
    const vec& spin_target = body_spin(groups_[g].body);
    vec3 target_velocity{0, 0, 0};
    for (index_t e = first; e < last; ++e) {
      if (entry_group_[e] != g) continue;
      const index_t j = pair_partner_[e];
      const contact::SurfacePoint& point = surface_point(j);
      const real fraction = shares[e - first] = surface_share(probe, point);
      if (fraction == 0) continue;
      const vec turn = cross(spin_target, {point.position[0] - y[3 * j], point.position[1] - y[3 * j + 1],
                                           point.position[2] - y[3 * j + 2]});
      for (int c = 0; c < 3; ++c) {
        probe.foot[c] += fraction * y[3 * j + c];
        target_velocity[c] += fraction * (u[3 * j + c] + turn[c]);
      }
    }
    const real size = std::sqrt(dot(probe.gradient, probe.gradient));
    const vec normal{probe.gradient[0] / size, probe.gradient[1] / size, probe.gradient[2] / size};
    const real normal_force = probe.push * size;
    const vec turn =
        cross(body_spin(node_body_[i]),
              {probe.point[0] - y[3 * i], probe.point[1] - y[3 * i + 1], probe.point[2] - y[3 * i + 2]});
    const real slip[3] = {u[3 * i] + turn[0] - target_velocity[0],
                          u[3 * i + 1] + turn[1] - target_velocity[1],
                          u[3 * i + 2] + turn[2] - target_velocity[2]};
    if (law.peridem_friction) {
      const real along = slip[0] * normal[0] + slip[1] * normal[1] + slip[2] * normal[2];
      const real tangential[3] = {slip[0] - along * normal[0], slip[1] - along * normal[1],
                                  slip[2] - along * normal[2]};
      real force[3];
      contact::peridem_friction_force(law.friction, normal_force, tangential, force);
      probe.friction = {force[0], force[1], force[2]};
      continue;
    }
    const real kt = law.tangential_stiffness_ratio * probe.stiffness;
    for (index_t e = first; e < last; ++e) {
      if (entry_group_[e] != g || pair_stiffness_[e] == 0) continue;
      real force[3];
      contact::tangential_force(kt, law.friction, normal_force, normal.data(), slip, dt,
                                springs_[pair_spring_[e]].data(), force);
      for (int c = 0; c < 3; ++c) probe.friction[c] += shares[e - first] * force[c];
    }
  }
}

void ContactModel::target_forces(const contact::SurfacePoint& point, real size, index_t group, vec3& on_point,
                                 vec3& on_normal, vec3& on_friction) const {
  // The exact reaction of a target's surface point and normal to the probe's energy (see
  // contact/surface_law.hpp), and its share w / S of the friction force, opposite (on the
  // node; probe_couples adds the couple).
  const ProbeState& probe = probes_[group];
  on_point = on_normal = on_friction = {0, 0, 0};
  if (!contact::faces(point, probe.facing)) return;
  const contact::PointTerms t = contact::point_terms(point, probe.point, probe.support);
  if (t.weight == 0) return;
  const real gap = probe.sums.gap(), weight = probe.sums.weight;
  const vec3 share = contact::point_share(t, gap, weight);
  const real fraction = t.weight / weight;
  for (int c = 0; c < 3; ++c) {
    on_point[c] = -probe.push * share[c] + probe.taper * t.weight_gradient[c];
    on_friction[c] = -fraction * probe.friction[c];
    on_normal[c] = probe.push * fraction * t.normal_sensitivity[c] / size;
  }
}

void ContactModel::node_forces(const Model& model, State& state, real dt) {
  // Each node gathers its own contact forces and updates its own friction springs: forces on
  // its contact centre (sphere pairs, walls), on its surface point (as a probe, and as a target
  // of other bodies' probes) and on its normal. An anchored node's forces on a point y + l n
  // go to the node, and their levers (l / |A|) (1 - n n^T) F on A; forces on A go -W to the
  // node here and w_k to its anchors after (in node order, so the sums are the same for any
  // thread count; surface_centres.hpp).
  const std::int64_t count = static_cast<std::int64_t>(contact_nodes_.size());
  if (centres_.any()) anchor_forces_.assign(contact_nodes_.size(), vec3{0, 0, 0});
#pragma omp parallel for schedule(static)
  for (std::int64_t k = 0; k < count; ++k) {
    const index_t i = contact_nodes_[k];
    vec at_centre{0, 0, 0}, at_surface{0, 0, 0}, on_vector{0, 0, 0};
    for (index_t e = pair_offsets_[i]; e < pair_offsets_[i + 1]; ++e) {
      if (pair_stiffness_[e] == 0 || probe_entry(e)) continue;
      const vec force = pair_force(model, state, i, e, dt);
      for (int c = 0; c < 3; ++c) at_centre[c] += force[c];
    }
    vec at_node{0, 0, 0};  // friction, with its couple as a rigid-body load
    for (index_t e = wall_offsets_[i]; e < wall_offsets_[i + 1]; ++e) {
      wall_entry_reaction_[e] = {0, 0, 0, 0, 0, 0};
      if (wall_entry_stiffness_[e] == 0) continue;
      vec on_centre, on_node;
      wall_force(model, state, i, e, dt, on_centre, on_node);
      for (int c = 0; c < 3; ++c) {
        at_centre[c] += on_centre[c];
        at_node[c] += on_node[c];
      }
    }
    const auto [group_begin, group_end] = groups_of(i);
    for (index_t g = group_begin; g < group_end; ++g) {
      const ProbeState& probe = probes_[g];
      if (probe.push == 0) continue;  // apart (its other fields may be an earlier step's)
      for (int c = 0; c < 3; ++c) {
        at_surface[c] += probe.push * probe.gradient[c] - probe.taper * probe.sums.spread[c];
        at_node[c] += probe.friction[c];
      }
    }
    const SurfaceAnchor* anchor = centres_.anchor(model, i);
    if (anchor != nullptr && !surface_slot_.empty() && surface_slot_[i] != no_group) {
      const contact::SurfacePoint& own = surface_point(i);
      const real size = surface_sizes_[surface_slot_[i]];
      for (index_t e = pair_offsets_[i]; e < pair_offsets_[i + 1]; ++e) {
        const index_t g = entry_target_[e];
        if (g == no_group || probes_[g].push == 0) continue;
        vec on_point, on_normal, on_friction;
        target_forces(own, size, g, on_point, on_normal, on_friction);
        for (int c = 0; c < 3; ++c) {
          at_surface[c] += on_point[c];
          on_vector[c] += on_normal[c];
          at_node[c] += on_friction[c];
        }
      }
    }
    vec total{0, 0, 0};
    for (int c = 0; c < 3; ++c) total[c] = at_centre[c] + at_surface[c] + at_node[c];
    if (anchor != nullptr) {
      // The levers of the forces on the centre and on the surface point (both on the normal).
      const SurfaceCentres::Seen seen = centres_.seen(model, i);
      vec along{0, 0, 0};
      for (int c = 0; c < 3; ++c)
        along[c] = seen.centre_length * at_centre[c] + seen.surface_length * at_surface[c];
      if (along != vec{0, 0, 0}) {
        const vec lever = centres_.lever(state, seen, i, 1.0, along);
        for (int c = 0; c < 3; ++c) on_vector[c] += lever[c];
      }
      anchor_forces_[k] = on_vector;
      real weights = 0;
      for (std::size_t a = 0; a < anchor->nodes.size() && anchor->nodes[a] != SurfaceAnchor::no_anchor; ++a)
        weights += anchor->weights[a];
      for (int c = 0; c < 3; ++c) total[c] -= weights * on_vector[c];
    }
    for (int c = 0; c < 3; ++c) state.forces[3 * i + c] += total[c] / model.volumes()[i];
  }
  if (!centres_.any()) return;
  for (std::int64_t k = 0; k < count; ++k) {
    const index_t i = contact_nodes_[k];
    const SurfaceAnchor* anchor = centres_.anchor(model, i);
    if (anchor == nullptr) continue;
    const index_t first = model.particles()[model.node_particle()[i]].first_node;
    for (std::size_t a = 0; a < anchor->nodes.size() && anchor->nodes[a] != SurfaceAnchor::no_anchor; ++a) {
      const index_t j = first + anchor->nodes[a];
      const real w = anchor->weights[a];
      for (int c = 0; c < 3; ++c) state.forces[3 * j + c] += w * anchor_forces_[k][c] / model.volumes()[j];
    }
  }
}

void ContactModel::probe_couples(const State& state) {
  // The friction force F_t acts on the probe's node y_i and, in shares, on the target's nodes
  // (at their mean y = foot): the probe's body takes (p - y_i) x F_t, the target's
  // (y - p) x F_t, so both act at p and their moments cancel.
  const real* x = state.positions.data();
  for (std::size_t g = 0; g < groups_.size(); ++g) {
    const ProbeState& probe = probes_[g];
    if (probe.push == 0 || probe.friction == vec3{0, 0, 0}) continue;
    const index_t i = groups_[g].probe;
    const vec own =
        cross({probe.point[0] - x[3 * i], probe.point[1] - x[3 * i + 1], probe.point[2] - x[3 * i + 2]},
              probe.friction);
    const vec target = cross(
        {probe.foot[0] - probe.point[0], probe.foot[1] - probe.point[1], probe.foot[2] - probe.point[2]},
        probe.friction);
    const index_t probe_touch = body_touch_[node_body_[i]], target_touch = body_touch_[groups_[g].body];
    for (int c = 0; c < 3; ++c) {
      body_load_[probe_touch][3 + c] += own[c];
      body_load_[target_touch][3 + c] += target[c];
    }
  }
}

real ContactModel::entry_stiffness(const Model& model, index_t i, index_t e) const {
  return contact::pair_stiffness(slot_law(pair_slot_[e]), model.volumes()[i],
                                 model.volumes()[pair_partner_[e]]);
}

real ContactModel::wall_spring_stiffness(const Model& model, index_t i, index_t e) const {
  return contact::pair_stiffness(slot_law(wall_slot_[e]), model.volumes()[i], model.volumes()[i]);
}

ContactModel::PairGeometry ContactModel::pair_geometry(const Model& model, const State& state, index_t i,
                                                       index_t e) const {
  const index_t j = pair_partner_[e];
  const contact::Law& law = laws_[model.node_material()[i] * material_count_ + model.node_material()[j]];
  const real contact_radius = slot_law(pair_slot_[e]).contact_radius;
  const vec3 xi = contact_position(model, state, i), xj = contact_position(model, state, j);
  const vec d{xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]};  // as in A
  const real distance = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  PairGeometry g;
  g.normal = {d[0] / distance, d[1] / distance, d[2] / distance};
  g.overlap = contact_radius - distance;
  g.lever_i = node_radius(law, model, i, j, contact_radius) - 0.5 * g.overlap;
  g.lever_j = node_radius(law, model, j, i, contact_radius) - 0.5 * g.overlap;
  return g;
}

vec3 ContactModel::pair_force(const Model& model, const State& state, index_t i, index_t e, real dt) {
  // Spring along the line of the contact centres, the fragment dashpot, and friction at the
  // contact point p = c_i + lever_i n, whose slip adds each body's rotation about the centre to
  // the centres' velocities (the centre lies inside its particle, p on the surface).
  const index_t j = pair_partner_[e];
  const contact::Law& law = laws_[model.node_material()[i] * material_count_ + model.node_material()[j]];
  const PairGeometry g = pair_geometry(model, state, i, e);
  const vec& n = g.normal;  // from i to j
  const vec vi = contact_velocity(model, state, i), vj = contact_velocity(model, state, j);
  const vec relative{vi[0] - vj[0], vi[1] - vj[1], vi[2] - vj[2]};
  const real approach = dot(relative, n);
  const real k = entry_stiffness(model, i, e);
  real push = contact::normal_force(k, g.overlap);
  if (node_body_[i] == node_body_[j]) {  // unbonded nodes of one body: a node-pair dashpot
    // Its share of the body pair's dashpot, 2 zeta k sqrt(M / K), but at most what removes half
    // the pair's approach speed in one step (c dt / m_ij <= 1/2): where few node pairs carry K,
    // the body's mass M over a node's would make the explicit dashpot unstable.
    const real K = slot_stiffness_[pair_slot_[e]];
    const real mi = model.node_density()[i] * model.volumes()[i],
               mj = model.node_density()[j] * model.volumes()[j];
    const real stable = dt > 0 ? 0.5 * mi * mj / ((mi + mj) * dt) : 0.0;
    const real c =
        std::min(2.0 * law.damping_ratio * k * std::sqrt(slot_reduced_mass(pair_slot_[e]) / K), stable);
    push = std::max(0.0, push + contact::damping_force(c, approach));
  }
  real friction[3] = {0, 0, 0};
  if (law.peridem_friction) {
    const vec peridem = peridem_pair_friction(law, push, relative, n);
    for (int c = 0; c < 3; ++c) friction[c] = peridem[c];
  } else if (law.friction > 0) {
    const vec turn_i =
        cross(body_spin(node_body_[i]), {g.lever_i * n[0], g.lever_i * n[1], g.lever_i * n[2]});
    const vec turn_j =
        cross(body_spin(node_body_[j]), {-g.lever_j * n[0], -g.lever_j * n[1], -g.lever_j * n[2]});
    const real slip[3] = {(vi[0] + turn_i[0]) - (vj[0] + turn_j[0]),
                          (vi[1] + turn_i[1]) - (vj[1] + turn_j[1]),
                          (vi[2] + turn_i[2]) - (vj[2] + turn_j[2])};
    contact::tangential_force(law.tangential_stiffness_ratio * k, law.friction, push, n.data(), slip, dt,
                              springs_[pair_spring_[e]].data(), friction);
  }
  return {-push * n[0] + friction[0], -push * n[1] + friction[1], -push * n[2] + friction[2]};
}

vec3 ContactModel::peridem_pair_friction(const contact::Law& law, real push, const vec3& relative,
                                         const vec3& normal) const {
  const real approach = dot(relative, normal);
  const real tangential[3] = {relative[0] - approach * normal[0], relative[1] - approach * normal[1],
                              relative[2] - approach * normal[2]};
  vec friction{0, 0, 0};
  contact::peridem_friction_force(law.friction, push, tangential, friction.data());
  return friction;
}

vec3 ContactModel::evaluated_pair_force(const Model& model, const State& state, index_t i, index_t e) const {
  const index_t j = pair_partner_[e];
  const contact::Law& law = laws_[model.node_material()[i] * material_count_ + model.node_material()[j]];
  const PairGeometry g = pair_geometry(model, state, i, e);
  const vec& n = g.normal;
  const real push = contact::normal_force(entry_stiffness(model, i, e), g.overlap);
  vec friction{0, 0, 0};
  if (law.peridem_friction) {
    const vec vi = contact_velocity(model, state, i), vj = contact_velocity(model, state, j);
    friction = peridem_pair_friction(law, push, {vi[0] - vj[0], vi[1] - vj[1], vi[2] - vj[2]}, n);
  } else if (law.friction > 0 && pair_spring_[e] != no_spring) {
    const real kt = law.tangential_stiffness_ratio * entry_stiffness(model, i, e);
    for (int c = 0; c < 3; ++c) friction[c] = -kt * springs_[pair_spring_[e]][c];
  }
  return {-push * n[0] + friction[0], -push * n[1] + friction[1], -push * n[2] + friction[2]};
}

ContactNetwork ContactModel::network(const Model& model, const State& state) const {
  // The force on each slot's first body, summed in node order (pair and wall entries, whose
  // springs make their slots touch), then in group order (probes), then the slot's loads (the
  // dashpot and the turn, recorded on q).
  ContactNetwork net;
  if (!built_) return net;
  std::vector<vec3> on_first(slot_load_.size(), vec3{0, 0, 0});
  for (const index_t i : contact_nodes_) {
    for (index_t e = pair_offsets_[i]; e < pair_offsets_[i + 1]; ++e) {
      const std::size_t slot = pair_slot_[e];
      const index_t j = pair_partner_[e];
      if (pair_stiffness_[e] == 0 || probe_entry(e) || node_body_[i] == node_body_[j] ||
          node_body_[i] != slots_[slot][0])
        continue;
      const vec force = evaluated_pair_force(model, state, i, e);
      for (int c = 0; c < 3; ++c) on_first[slot_touch_[slot]][c] += force[c];
    }
    for (index_t e = wall_offsets_[i]; e < wall_offsets_[i + 1]; ++e) {
      if (wall_entry_stiffness_[e] == 0) continue;
      for (int c = 0; c < 3; ++c) on_first[slot_touch_[wall_slot_[e]]][c] -= wall_entry_reaction_[e][c];
    }
  }
  for (std::size_t g = 0; g < groups_.size(); ++g) {
    const ProbeState& probe = probes_[g];
    const std::size_t slot = groups_[g].slot;
    if (probe.push == 0 || slot_touch_[slot] == not_touching) continue;
    const real sign = node_body_[groups_[g].probe] == slots_[slot][0] ? 1.0 : -1.0;
    for (int c = 0; c < 3; ++c)
      on_first[slot_touch_[slot]][c] +=
          sign * (probe.push * probe.gradient[c] - probe.taper * probe.sums.spread[c] + probe.friction[c]);
  }
  auto first_node = [&](index_t body) { return body_nodes_[body_node_offsets_[body]]; };
  for (std::size_t slot = 0; slot < slots_.size(); ++slot) {
    const bool wall_slot = slot >= particle_slot_count_;
    const index_t p = slots_[slot][0], q = slots_[slot][1];
    if (!slot_in_contact(slot) || (!wall_slot && p == q)) continue;
    const index_t touch = slot_touch_[slot];
    const vec& sum = slot_surface_normal_[touch];
    const real size = std::sqrt(dot(sum, sum)), sign = wall_slot ? 1.0 : -1.0;  // from b towards a
    const vec point = slot_contact_point(touch);
    net.particle_a.push_back(body_particle_[p]);
    net.node_a.push_back(first_node(p));
    net.particle_b.push_back(wall_slot ? q : body_particle_[q]);
    net.node_b.push_back(wall_slot ? ~index_t{0} : first_node(q));
    net.wall.push_back(wall_slot ? 1 : 0);
    for (int c = 0; c < 3; ++c) {
      net.point.push_back(point[c]);
      net.normal.push_back(sign * sum[c] / size);
      net.force.push_back(on_first[touch][c] + (wall_slot ? 1.0 : -1.0) * slot_load_[touch][c]);
    }
  }
  return net;
}

ContactModel::WallGeometry ContactModel::wall_geometry(const Model& model, index_t i, index_t e) const {
  // Friction acts at the deepest point: p = c_i - lever n, n from the wall towards the node.
  const contact::PairLaw& resolved = slot_law(wall_slot_[e]);
  const WallPoints& points = wall_points_[e];
  const WallContact& deepest = points.points[deepest_point(points.points.data(), points.count)];
  const real lever = resolved.contact_radius - 0.5 * (resolved.contact_radius - deepest.distance);
  WallGeometry g;
  g.normal = deepest.normal;
  g.arm = {-lever * g.normal[0], -lever * g.normal[1], -lever * g.normal[2]};
  g.stiffness = wall_spring_stiffness(model, i, e);
  return g;
}

void ContactModel::wall_force(const Model& model, const State& state, index_t i, index_t e, real dt,
                              vec3& on_centre, vec3& on_node) {
  // Springs at every contact point of the entry, on the node's contact centre; friction at the
  // deepest point p, on the node with its couple (p - x_i) x F_t (friction_couple), from the
  // slip of p moving with the node and its body's rotation. The wall takes the opposite force
  // at p.
  const vec xi = contact_position(model, state, i);
  const Wall& wall = walls_[wall_entry_[e][0]];
  const contact::Law& law = wall_laws_[wall_entry_[e][0] * material_count_ + model.node_material()[i]];
  const contact::PairLaw& resolved = slot_law(wall_slot_[e]);
  const WallPoints& points = wall_points_[e];
  const WallGeometry g = wall_geometry(model, i, e);
  on_centre = on_node = {0, 0, 0};
  real push_total = 0;
  for (std::size_t point = 0; point < points.count; ++point) {
    const real push =
        contact::normal_force(g.stiffness, resolved.contact_radius - points.points[point].distance);
    push_total += push;
    for (int c = 0; c < 3; ++c) on_centre[c] += push * points.points[point].normal[c];
  }
  const vec point{xi[0] + g.arm[0], xi[1] + g.arm[1], xi[2] + g.arm[2]};
  const vec wall_velocity = wall.velocity_at(point.data(), state.time);
  const real* x = state.positions.data();
  const vec lever{point[0] - x[3 * i], point[1] - x[3 * i + 1], point[2] - x[3 * i + 2]};
  const vec turn = cross(body_spin(node_body_[i]), lever);
  const real* v = state.velocities.data();
  const vec moving{v[3 * i] + turn[0], v[3 * i + 1] + turn[1], v[3 * i + 2] + turn[2]};
  real friction[3] = {0, 0, 0};
  if (law.peridem_friction) {
    const vec relative{moving[0] - wall_velocity[0], moving[1] - wall_velocity[1],
                       moving[2] - wall_velocity[2]};
    const real speed = dot(relative, g.normal);
    const real tangential[3] = {relative[0] - speed * g.normal[0], relative[1] - speed * g.normal[1],
                                relative[2] - speed * g.normal[2]};
    contact::peridem_friction_force(law.friction, push_total, tangential, friction);
  } else if (law.friction > 0) {
    const real slip[3] = {moving[0] - wall_velocity[0], moving[1] - wall_velocity[1],
                          moving[2] - wall_velocity[2]};
    contact::tangential_force(law.tangential_stiffness_ratio * g.stiffness, law.friction, push_total,
                              g.normal.data(), slip, dt, springs_[wall_spring_[e]].data(), friction);
  }
  on_node = {friction[0], friction[1], friction[2]};
  const vec force{on_centre[0] + on_node[0], on_centre[1] + on_node[1], on_centre[2] + on_node[2]};
  const vec torque =
      cross({point[0] - wall.center[0], point[1] - wall.center[1], point[2] - wall.center[2]}, force);
  wall_entry_reaction_[e] = {-force[0], -force[1], -force[2], -torque[0], -torque[1], -torque[2]};
}

vec3 ContactModel::friction_couple(const Model& model, const State& state, index_t i) const {
  // The couple of node i's friction forces about the point they are applied at (the contact
  // centre for node pairs, the node for walls), from the springs as pass C left them
  // (F_t = -kt xi, capped or not).
  vec couple{0, 0, 0};
  const auto& node_material = model.node_material();
  for (index_t e = pair_offsets_[i]; e < pair_offsets_[i + 1]; ++e) {
    if (pair_spring_[e] == no_spring || probe_entry(e)) continue;
    const contact::Law& law = laws_[node_material[i] * material_count_ + node_material[pair_partner_[e]]];
    if (law.peridem_friction || law.friction == 0) continue;
    const PairGeometry g = pair_geometry(model, state, i, e);
    const real kt = law.tangential_stiffness_ratio * entry_stiffness(model, i, e);
    const vec& xi = springs_[pair_spring_[e]];
    const vec moment = cross({g.lever_i * g.normal[0], g.lever_i * g.normal[1], g.lever_i * g.normal[2]},
                             {-kt * xi[0], -kt * xi[1], -kt * xi[2]});
    for (int c = 0; c < 3; ++c) couple[c] += moment[c];
  }
  for (index_t e = wall_offsets_[i]; e < wall_offsets_[i + 1]; ++e) {
    if (wall_spring_[e] == no_spring) continue;
    const contact::Law& law = wall_laws_[wall_entry_[e][0] * material_count_ + node_material[i]];
    if (law.peridem_friction || law.friction == 0) continue;
    const WallGeometry g = wall_geometry(model, i, e);
    const real kt = law.tangential_stiffness_ratio * g.stiffness;
    const vec& xi = springs_[wall_spring_[e]];
    const vec centre = contact_position(model, state, i);
    const real* x = state.positions.data();
    const vec lever{centre[0] + g.arm[0] - x[3 * i], centre[1] + g.arm[1] - x[3 * i + 1],
                    centre[2] + g.arm[2] - x[3 * i + 2]};  // p - x_i
    const vec moment = cross(lever, {-kt * xi[0], -kt * xi[1], -kt * xi[2]});
    for (int c = 0; c < 3; ++c) couple[c] += moment[c];
  }
  return couple;
}

void ContactModel::body_loads(const Model& model, State& state) {
  // Dashpot forces at contact points and the friction couples, as rigid-body loads: every node of
  // the body gets rho_i (F / M + alpha x (x_i - c)), alpha = I^-1 tau. They add up to F and tau.
  const auto& x = state.positions;
  auto& f = state.forces;
  const real* const density = model.node_density().data();
  const std::int64_t count = static_cast<std::int64_t>(touching_bodies_.size());
#pragma omp parallel for schedule(dynamic, 16)
  for (std::int64_t touch = 0; touch < count; ++touch) {
    const index_t b = touching_bodies_[touch];
    std::array<real, 6> total = body_load_[touch];
    for (index_t k = body_contact_offsets_[b]; k < body_contact_offsets_[b + 1]; ++k) {
      const vec couple = friction_couple(model, state, contact_nodes_[k]);
      for (int c = 0; c < 3; ++c) total[3 + c] += couple[c];
    }
    if (total == std::array<real, 6>{0, 0, 0, 0, 0, 0}) continue;
    const BodyMotion& motion = body_motion_[touch];
    const real mass = body_mass_[b];
    const vec acceleration{total[0] / mass, total[1] / mass, total[2] / mass};
    const vec turn = symmetric_times(motion.inverse_inertia, {total[3], total[4], total[5]});
    for (index_t k = body_node_offsets_[b]; k < body_node_offsets_[b + 1]; ++k) {
      const index_t i = body_nodes_[k];
      const vec spin = cross(turn, {x[3 * i] - motion.centre[0], x[3 * i + 1] - motion.centre[1],
                                    x[3 * i + 2] - motion.centre[2]});
      for (int c = 0; c < 3; ++c) f[3 * i + c] += density[i] * (acceleration[c] + spin[c]);
    }
  }
}

void ContactModel::sum_wall_reactions() {
  // Wall reactions, summed in entry order, plus the dashpots' share.
  wall_reactions_ = wall_damping_;
  for (std::size_t e = 0; e < wall_entry_.size(); ++e) {
    auto& reaction = wall_reactions_[wall_entry_[e][0]];
    for (int k = 0; k < 6; ++k) reaction[k] += wall_entry_reaction_[e][k];
  }
}

}  // namespace granulate
