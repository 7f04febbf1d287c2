// One contact step (add_forces) and its measuring phases: where contact sees each node, the
// geometry of a node pair and a node-wall contact, distances, springs and probes, each pair of
// bodies' stiffness, the touching bodies' rigid motion, normals and spring sums; spring energy.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "contact_vectors.hpp"
#include "granulate/contact/body_sums.hpp"
#include "granulate/contact/contact_model.hpp"
#include "granulate/in_parallel.hpp"

namespace granulate {
using namespace contact_vectors;

namespace {

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

}  // namespace

BodyMotion measure_body(const Model& model, const State& state, const index_t* nodes, index_t count,
                        int dimension) {
  if (measured_order_free(model, nodes, count))
    return measure_order_free(model, state, nodes, count, dimension);
  const auto& x = state.positions;
  const auto& v = state.velocities;
  const vec origin{x[3 * nodes[0]], x[3 * nodes[0] + 1], x[3 * nodes[0] + 2]};
  real mass = 0;
  vec first{0, 0, 0}, momentum{0, 0, 0}, spin{0, 0, 0};
  std::array<real, 6> second{0, 0, 0, 0, 0, 0};  // sum m r r^T: xx, yy, zz, xy, xz, yz
  for (index_t slot = 0; slot < count; ++slot) {
    const index_t i = nodes[slot];
    const real m = model.density(i) * model.volumes()[i];
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
  return motion_about(origin, mass, first, momentum, spin, second, dimension);
}

BodyMotion motion_about(const vec3& origin, real mass, const vec3& first, const vec3& momentum,
                        const vec3& spin, const std::array<real, 6>& second, int dimension) {
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

vec3 ContactModel::surface_normal_at(const Model& model, const State& state, index_t i) const {
  // The sum points into the body from a surface node.
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
  // kn min(V_i, h_t^d)^2 per (finer h)^(d-1) (V_i: stiffness_volume; h_t^d: the target body's
  // nominal node volume); a probe carries its own node's share of the surface, h_i^(d-1), and
  // its side's share of the contact.
  const real hi = particle_side_[model.node_particle()[i]].mesh_size;
  const real ht = particle_side_[model.node_particle()[target]].mesh_size;
  const real share = ht * ht / (hi * hi + ht * ht);
  const real area =
      dimension_ == 2 ? hi / std::min(hi, ht) : (hi * hi) / (std::min(hi, ht) * std::min(hi, ht));
  const real nominal = dimension_ == 2 ? ht * ht : ht * ht * ht;
  return share * area * contact::pair_stiffness(law, stiffness_volume(model, i), nominal);
}

real ContactModel::stiffness_volume(const Model& model, index_t i) const {
  const index_t p = model.node_particle()[i];
  if (!surface_particles_[p]) return model.volumes()[i];
  const real h = particle_side_[p].mesh_size;
  return std::sqrt(model.volumes()[i] * (dimension_ == 2 ? h * h : h * h * h));  // sqrt(V_i h^d)
}

real ContactModel::node_radius(const contact::Law& law, const Model& model, index_t i, index_t j,
                               real contact_radius) const {
  const auto& owner = model.node_particle();
  return contact::node_share(law, particle_side_[owner[i]], particle_side_[owner[j]], contact_radius);
}

real ContactModel::entry_stiffness(const Model& model, index_t i, index_t e) const {
  return contact::pair_stiffness(slot_law(pair_slot_[e]), model.volumes()[i],
                                 model.volumes()[pair_partner_[e]]);
}

real ContactModel::wall_spring_stiffness(const Model& model, index_t i, index_t e) const {
  const real volume = stiffness_volume(model, i);
  return contact::pair_stiffness(slot_law(wall_slot_[e]), volume, volume);
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
  g.centre_i = xi;
  g.normal = {d[0] / distance, d[1] / distance, d[2] / distance};
  g.overlap = contact_radius - distance - pair_rest(i, j, slot_law(pair_slot_[e]));
  g.lever_i = node_radius(law, model, i, j, contact_radius) - 0.5 * g.overlap;
  g.lever_j = node_radius(law, model, j, i, contact_radius) - 0.5 * g.overlap;
  return g;
}

ContactModel::WallGeometry ContactModel::wall_geometry(const Model& model, index_t i, index_t e,
                                                       const WallSpheres& spheres) const {
  // Friction acts at the deepest point of the deepest sphere: p = c - (r - overlap / 2) m, m from
  // the wall towards the node.
  const WallPoints& points = wall_points_[e];
  auto overlap = [&](std::size_t k) {
    return spheres.radius[sphere_of(points, k)] - points.points[k].distance;
  };
  std::size_t deepest = 0;
  for (std::size_t k = 1; k < points.count; ++k)
    if (overlap(k) > overlap(deepest)) deepest = k;
  const int sphere = sphere_of(points, deepest);
  const real radius = spheres.radius[sphere];
  const real lever = radius - 0.5 * (radius - points.points[deepest].distance);
  WallGeometry g;
  g.normal = points.points[deepest].normal;
  const vec arm{-lever * g.normal[0], -lever * g.normal[1], -lever * g.normal[2]};
  for (int c = 0; c < 3; ++c) g.point[c] = spheres.centre[sphere][c] + arm[c];
  g.stiffness = points.osculating > 0 ? wall_entry_stiffness_[e] : wall_spring_stiffness(model, i, e);
  return g;
}

ContactModel::WallSpheres ContactModel::wall_spheres(const Model& model, const State& state, index_t i,
                                                     index_t e) const {
  const WallPoints& points = wall_points_[e];
  WallSpheres spheres;
  spheres.centre[0] = contact_position(model, state, i);
  spheres.radius[0] = slot_law(wall_slot_[e]).contact_radius;
  if (points.osculating > 0) {
    spheres.centre[1] = points.osculating_centre;
    spheres.radius[1] = points.osculating_radius;
  }
  return spheres;
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

bool ContactModel::slot_in_contact(std::size_t slot) const {
  const index_t touch = slot_touch_[slot];
  if (touch == not_touching) return false;
  const vec& sum = slot_surface_normal_[touch];
  return dot(sum, sum) > 0 && slot_force_[touch] > 0;
}

void ContactModel::search(const Model& model, const State& state, std::uint64_t broken_bonds) {
  if (!active()) return;
  if (!centres_.found()) centres_.find(model, state, centring_depths(model), surface_particles_);
  centres_.fill_positions(model, state, positions_at_build_);
  rebuild(model, state, broken_bonds);
}

vec3 ContactModel::slot_contact_point(index_t touch) const {
  const real force = slot_force_[touch];
  return {slot_point_[touch][0] / force, slot_point_[touch][1] / force, slot_point_[touch][2] / force};
}

void ContactModel::add_forces(const Model& model, State& state, std::uint64_t broken_bonds) {
  if (!active()) return;
  const auto search_start = std::chrono::steady_clock::now();
  if (!centres_.found()) centres_.find(model, state, centring_depths(model), surface_particles_);
  real moved = 0;  // largest node displacement since listed
  const bool broke = broken_bonds != broken_at_build_;
  std::vector<index_t> relist;
  if (needs_search(model, state, broke, moved, relist)) {
    search(model, state, broken_bonds);
  } else if (broke || !relist.empty()) {
    update_lists(model, state, broken_bonds, moved, relist);
  }
  search_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - search_start).count();
  const real dt = has_last_time_ ? state.time - last_time_ : 0.0;
  last_time_ = state.time;
  has_last_time_ = true;
  if (any_surface_) measure_surface_points(model, state);  // A: the lists' surface points
  if (any_surface_) measure_body_rotations(model, state);  //    round bodies' rotations, for walls
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
  ghosts_.forget();          // the ghosts' motions were this state's
}

namespace {

/// B = sum m (y - c)(X - C)^T of a body (contact/body_rotation.hpp), from moments about its
/// first node in both frames, so far from the origin nothing cancels:
/// sum m (y - y_0)(X - X_0)^T - M d D^T, d = c - y_0, D = C - X_0.
contact::matrix3 body_moment(const Model& model, const State& state, const index_t* nodes, index_t count) {
  if (measured_order_free(model, nodes, count)) return moment_order_free(model, state, nodes, count);
  const real* y = state.positions.data();
  const real* X = model.reference_positions().data();
  const index_t first = nodes[0];
  real mass = 0;
  vec d{0, 0, 0}, D{0, 0, 0};
  contact::matrix3 moment{};
  for (index_t slot = 0; slot < count; ++slot) {
    const index_t i = nodes[slot];
    const real m = model.density(i) * model.volumes()[i];
    const vec a{y[3 * i] - y[3 * first], y[3 * i + 1] - y[3 * first + 1], y[3 * i + 2] - y[3 * first + 2]};
    const vec b{X[3 * i] - X[3 * first], X[3 * i + 1] - X[3 * first + 1], X[3 * i + 2] - X[3 * first + 2]};
    mass += m;
    for (int r = 0; r < 3; ++r) {
      d[r] += m * a[r];
      D[r] += m * b[r];
      for (int c = 0; c < 3; ++c) moment[3 * r + c] += m * a[r] * b[c];
    }
  }
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) moment[3 * r + c] -= d[r] * D[c] / mass;
  return moment;
}

}  // namespace

void ContactModel::measure_body_rotations(const Model& model, const State& state) {
  // The rotation of each body find_rotated_bodies listed, this step.
  const std::int64_t count = static_cast<std::int64_t>(rotated_bodies_.size());
  in_parallel([&] {
#pragma omp for schedule(dynamic, 16)
    for (std::int64_t k = 0; k < count; ++k) {
      const index_t b = rotated_bodies_[k];
      const auto rotation =
          contact::best_rotation(body_moment(model, state, body_nodes_.data() + body_node_offsets_[b],
                                             body_node_offsets_[b + 1] - body_node_offsets_[b]),
                                 dimension_);
      body_rotated_[k] = rotation ? 1 : 0;
      if (rotation) body_rotation_[k] = *rotation;
    }
  });
}

void ContactModel::measure_surface_points(const Model& model, const State& state) {
  // The surface points of the nodes with list entries, once per step, for every probe that
  // reaches them (surface_slot_ numbers them in node order).
  const std::int64_t count = static_cast<std::int64_t>(surface_nodes_.size());
  in_parallel([&] {
#pragma omp for schedule(static)
    for (std::int64_t k = 0; k < count; ++k) {
      const index_t j = surface_nodes_[k];
      const SurfaceCentres::Seen seen = centres_.seen(model, j);
      surface_points_[k] = surface_point_now(seen, state, j, surface_sizes_[k]);
      surface_stretches_[k] = static_cast<float>(SurfaceCentres::stretch(seen, surface_sizes_[k]));
    }
  });
}

contact::SurfacePoint ContactModel::surface_point_now(const SurfaceCentres::Seen& seen, const State& state,
                                                      index_t j, real& size) {
  const vec3 a = SurfaceCentres::anchored_vector(seen, state.positions, j);
  size = std::sqrt(dot(a, a));
  const real offset = SurfaceCentres::faded_length(seen, seen.surface_length, size);  // as point() has it
  contact::SurfacePoint point;
  for (int c = 0; c < 3; ++c) {
    point.normal[c] = a[c] / size;
    point.position[c] = state.positions[3 * j + c] + offset * point.normal[c];
  }
  point.curvature = seen.anchor->curvature / seen.mesh_size;
  return point;
}

void ContactModel::measure_contacts(const Model& model, const State& state) {
  // The only geometry pass: distance and spring stiffness of every pair entry in contact, and the
  // contact points (normals in the world frame) of every wall entry, and the nodes in contact with
  // another body. The later passes read these.
  const auto& volume = model.volumes();
  const std::int64_t n = model.node_count();
  touching_nodes_.clear();
  if (any_surface_ && opened_rest_.size() != static_cast<std::size_t>(n)) opened_rest_.assign(n, -1);
  std::vector<ProbeState> touching_probes;  // the surface probes that touch, from every thread
  std::vector<index_t> sphere_pair_nodes;   // the nodes touching in sphere pairs under the surface law
  in_parallel([&] {
    std::vector<WallContact> found;  // scratch of this thread
    ProbeScratch probe_scratch;
    std::vector<index_t> touching_nodes, sphere_pairs;
    real deepest = 0;  // overlap / Rc
#pragma omp for schedule(static) nowait
    for (std::int64_t ii = 0; ii < n; ++ii) {
      const index_t i = static_cast<index_t>(ii);
      if (pair_offsets_[i] == pair_offsets_[i + 1] && wall_offsets_[i] == wall_offsets_[i + 1]) {
        // Nothing in reach: the rest of a node that takes part falls to 0, as it would were the
        // node listed (the skin, which decides which nodes are, must change no force). A node
        // inside an intact surface keeps -1 until a crack opens it.
        if (!opened_rest_.empty() && opened_rest_[i] != 0 && (taking_part_.empty() || taking_part_[i]))
          opened_rest_[i] = 0;
        continue;
      }
      vec3 xi{0, 0, 0};
      bool have_xi = false;  // the contact centre, where a sphere pair or a wall needs it
      auto centre = [&]() -> const vec3& {
        if (!have_xi) xi = contact_position(model, state, i), have_xi = true;
        return xi;
      };
      bool touching = false;
      const bool counted = !ghosts_.ghost(model.node_particle()[i]);  // a ghost's owner counts it
      real pair_overlap = 0;     // the deepest of its sphere pairs under the surface law
      bool sphere_pair = false;  // whether one of them touches, before their rests
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
        if (pair_stiffness_[e] > 0 && !law.node_pair && !law.surface && counted)
          deepest = std::max(deepest, 1 - distance / law.contact_radius);
        if (law.surface) pair_overlap = std::max(pair_overlap, law.contact_radius - distance);
        if (law.surface && pair_stiffness_[e] > 0) sphere_pair = true;
      }
      if (touching) touching_nodes.push_back(i);
      const real probed = measure_probes(model, state, i, probe_scratch, pair_overlap);
      if (counted) deepest = std::max(deepest, probed);
      if (sphere_pair) sphere_pairs.push_back(i);
      for (index_t e = wall_offsets_[i]; e < wall_offsets_[i + 1]; ++e)
        measure_wall_points(model, state, i, e, centre(), found);
    }
#pragma omp critical
    {
      touching_nodes_.insert(touching_nodes_.end(), touching_nodes.begin(), touching_nodes.end());
      sphere_pair_nodes.insert(sphere_pair_nodes.end(), sphere_pairs.begin(), sphere_pairs.end());
      touching_probes.insert(touching_probes.end(), probe_scratch.touching.begin(),
                             probe_scratch.touching.end());
      statistics_.add_overlap(deepest, state.step);
    }
  });
  std::sort(touching_nodes_.begin(), touching_nodes_.end());  // the same for any thread count
  if (any_surface_) keep_touching_probes(touching_probes);
  release_rested_pairs(model, state, sphere_pair_nodes);
}

void ContactModel::measure_wall_points(const Model& model, const State& state, index_t i, index_t e,
                                       const vec3& centre, std::vector<WallContact>& found) {
  // A contact sphere touches where the wall is within rho of its centre. On a round particle
  // the node's osculating sphere (radius r) touches where the wall is within r of its centre,
  // each point weighted by its share w (surface_law.hpp) of the contact about the sphere's
  // nearest point, and the contact sphere keeps the rest, 1 - min(1, sum w): a contact
  // narrower than the points' spacing is carried by the osculating spheres, as by the circle
  // they share, a contact that has flattened over several points by each point's own sphere.
  // Walls that give only their nearest feature (polygons, triangle meshes) keep the contact
  // spheres: the feature nearest to a centre deep in the particle need not be the one under
  // the node.
  const Wall& wall = walls_[wall_entry_[e][0]];
  const WallSurface::Kind kind = wall.surfaces[wall_entry_[e][1]].kind;
  const SurfaceCentres::Seen seen = centres_.seen(model, i);
  WallPoints& points = wall_points_[e];
  points.count = points.osculating = 0;
  real share = 0;
  if (seen.osculating_radius > 0 && kind != WallSurface::Kind::polygon &&
      kind != WallSurface::Kind::triangles) {
    const real r = points.osculating_radius = seen.osculating_radius;
    const vec3 n = osculating_normal(model, state, seen, i);
    for (int c = 0; c < 3; ++c)  // o = y + (d - r) n
      points.osculating_centre[c] = state.positions[3 * i + c] + (seen.surface_length - r) * n[c];
    const real support = contact::surface_support_factor * seen.mesh_size;
    found.clear();
    wall.contacts(wall_entry_[e][1], wall.to_reference(points.osculating_centre.data(), state.time), r,
                  dimension_, found);
    for (const WallContact& contact : found) {
      if (points.count == points.points.size()) break;
      const vec3 m = wall.rotate_to_world(contact.normal, state.time);
      const vec3 chord{n[0] + m[0], n[1] + m[1], n[2] + m[2]};
      const real weight = contact::osculating_scale(dimension_) *
                          contact::surface_weight(r * std::sqrt(dot(chord, chord)) / support);
      if (weight == 0) continue;
      points.points[points.count] = {contact.distance, m};
      points.weights[points.count++] = weight;
      share += weight;
    }
    points.osculating = points.count;
  }
  const real rest = points.osculating > 0 ? std::max(0.0, 1 - share) : 1.0;
  if (rest > 0) {
    found.clear();
    wall.contacts(wall_entry_[e][1], wall.to_reference(centre.data(), state.time),
                  slot_law(wall_slot_[e]).contact_radius, dimension_, found);
    for (const WallContact& contact : found) {
      if (points.count == points.points.size()) break;
      points.points[points.count] = {contact.distance, wall.rotate_to_world(contact.normal, state.time)};
      points.weights[points.count++] = rest;
      share += rest;
    }
  }
  wall_entry_stiffness_[e] = share * wall_spring_stiffness(model, i, e);
}

vec3 ContactModel::osculating_normal(const Model& model, const State& state, const SurfaceCentres::Seen& seen,
                                     index_t i) const {
  // R n_0, the reference normal turned with the body, where the body has a rotation; the
  // anchored normal A / |A| otherwise.
  const index_t slot = body_rotation_slot_[node_body_[i]];
  const bool turned = slot != no_rotation && body_rotated_[slot] != 0;
  const vec3 a =
      SurfaceCentres::anchored_vector(seen, turned ? model.reference_positions() : state.positions, i);
  const real size = std::sqrt(dot(a, a));
  const vec3 n{a[0] / size, a[1] / size, a[2] / size};
  return turned ? contact::rotate(body_rotation_[slot], n) : n;
}

real ContactModel::measure_probes(const Model& model, const State& state, index_t i, ProbeScratch& scratch,
                                  real pair_overlap) {
  // Node i's probes of other bodies' surfaces (contact/surface_law.hpp): each group's points
  // in reach that face the probe, their sums, then the gap, its gradient and the push, then
  // each probe entry's share of the probe's stiffness (its in-contact flag). Returns the
  // deepest overlap over Rc. A group with no point in reach is apart (push 0) and costs one
  // distance per entry.
  const auto [group_begin, group_end] = groups_of(i);
  if (group_begin == group_end) {
    if (!opened_rest_.empty() && !on_surface(model, i)) settle_opened_rest(i, pair_overlap);
    return 0;
  }
  const bool surface = on_surface(model, i);
  const vec3 p = centres_.at_surface(model, state, i);
  // The fade of the probe's own point (1 for a node without one): phi, and d phi / d|A|.
  const index_t own_slot = surface ? surface_slot_[i] : no_group;
  const real stretch = own_slot == no_group ? 1.0 : surface_stretches_[own_slot];
  const real own_fade = contact::surface_fade(stretch);
  const real own_fade_slope =
      own_slot == no_group ? 0.0 : contact::surface_fade_slope(stretch) * stretch / surface_sizes_[own_slot];
  const index_t first = pair_offsets_[i], last = pair_offsets_[i + 1];
  scratch.points.assign(last - first, nullptr);  // the points in reach (null: none)
  scratch.weights.assign(last - first, 0.0);
  // The distance of each group's nearest point in reach (-1: none yet).
  scratch.nearest.assign(group_end - group_begin, -1);
  scratch.states.resize(group_end - group_begin);
  auto state_of = [&](index_t g) -> ProbeState& { return scratch.states[g - group_begin]; };
  for (index_t e = first; e < last; ++e) {  // the points in reach, and each group's nearest
    const index_t g = entry_group_[e];
    if (g == no_group) continue;
    const index_t j = pair_partner_[e];
    const real support = contact::surface_support_factor * particle_side_[model.node_particle()[j]].mesh_size;
    const contact::SurfacePoint& point = surface_point(j);
    const vec d{p[0] - point.position[0], p[1] - point.position[1], p[2] - point.position[2]};
    const real distance = std::sqrt(dot(d, d));
    if (!(distance < contact::reach_end * support) || surface_fade_of(j) == 0) continue;
    scratch.points[e - first] = &point;
    real& best = scratch.nearest[g - group_begin];
    if (best < 0) {  // the group's first point in reach: set the probe up
      ProbeState& probe = state_of(g);
      probe = ProbeState{};
      const contact::PairLaw& law = slot_law(pair_slot_[e]);
      const contact::Law& own = laws_[model.node_material()[i] * material_count_ + model.node_material()[j]];
      probe.group = g;
      probe.point = p;
      probe.support = support;
      probe.radius = surface ? 0.0 : node_radius(own, model, i, j, law.contact_radius);
      probe.stiffness = own_fade * probe_stiffness(model, i, j, law);
      probe.contact_radius = law.contact_radius;
      if (own_slot != no_group) {
        const vec3& n = surface_points_[own_slot].normal;
        probe.facing = {-n[0], -n[1], -n[2]};
        probe.smooth_facing = true;
      }
    }
    if (best < 0 || distance < best) {
      best = distance;
      if (!state_of(g).smooth_facing) state_of(g).facing = point.normal;
    }
  }
  for (index_t e = first; e < last; ++e) {
    const contact::SurfacePoint* point = scratch.points[e - first];
    if (point == nullptr) continue;
    ProbeState& probe = state_of(entry_group_[e]);
    const real share = contact::facing_share(*point, probe.facing, probe.smooth_facing);
    if (share == 0) continue;
    const contact::PointTerms t = contact::faded(contact::point_terms(*point, p, probe.support),
                                                 share * surface_fade_of(pair_partner_[e]));
    scratch.weights[e - first] = t.weight;
    probe.sums.add(t);
  }
  // A group's overlap before the rest (-inf: no point of it in reach).
  auto raw_overlap = [&](index_t g) {
    const ProbeState& probe = state_of(g);
    if (scratch.nearest[g - group_begin] < 0 || !probe.sums.reached())
      return -std::numeric_limits<real>::infinity();
    return probe.radius - probe.sums.gap();
  };
  real rest = 0;  // the overlap the probe counts from (0 for a surface point)
  if (!surface) {
    real raw = pair_overlap;
    for (index_t g = group_begin; g < group_end; ++g) raw = std::max(raw, raw_overlap(g));
    rest = settle_opened_rest(i, raw);
  }
  real deepest = 0;
  for (index_t g = group_begin; g < group_end; ++g) {
    ProbeState& probe = state_of(g);
    probe.push = 0;
    const real overlap = raw_overlap(g) - rest;
    if (!(overlap > 0)) continue;
    probe.gradient = probe.sums.gradient();
    probe.push = probe.stiffness * overlap * contact::surface_taper(probe.sums.weight);
    probe.taper = 0.5 * probe.stiffness * overlap * overlap * contact::surface_taper_slope(probe.sums.weight);
    if (!(probe.push > 0)) continue;  // tapered to nothing past the edge of its points
    // E = phi k0 delta^2 tau / 2: its derivative through the fade, along the own normal on A.
    probe.fade_force = own_fade_slope == 0 ? 0.0 : 0.5 * probe.push * overlap * own_fade_slope / own_fade;
    if (probe.smooth_facing) probe.facing_force = facing_force(i, g, probe, first, last);
    scratch.touching.push_back(probe);
    // The overlap that carries force (a probe tapered past the edge of its points does not).
    deepest = std::max(deepest, probe.push / (probe.stiffness * probe.contact_radius));
  }
  for (index_t e = first; e < last; ++e) {
    const index_t g = entry_group_[e];
    if (g == no_group) continue;
    const ProbeState& probe = state_of(g);
    pair_stiffness_[e] =
        probe.push > 0 ? static_cast<float>(probe.stiffness * scratch.weights[e - first] / probe.sums.weight)
                       : 0.0f;
  }
  return deepest;
}

real ContactModel::settle_opened_rest(index_t i, real deepest) {
  real& rest = opened_rest_[i];
  rest = rest < 0 ? deepest : std::min(rest, deepest);
  return rest;
}

void ContactModel::keep_touching_probes(std::vector<ProbeState>& measured) {
  std::sort(measured.begin(), measured.end(),
            [](const ProbeState& a, const ProbeState& b) { return a.group < b.group; });
  probes_.swap(measured);
  measured.clear();
  group_probe_.assign(groups_.size(), no_probe);
  for (std::size_t k = 0; k < probes_.size(); ++k) group_probe_[probes_[k].group] = static_cast<index_t>(k);
}

vec3 ContactModel::facing_force(index_t i, index_t g, const ProbeState& probe, index_t first,
                                index_t last) const {
  // The force on the probe's own A through its facing -n_p, n_p = A / |A|: each point's share
  // psi(n_k . (-n_p)) moves with n_p, dE/d(omega_k) = -P (d_k - g) / S + Q (omega_k = phi_k
  // psi_k w_k), so the force on n_p is sum_k (P (d_k - g) / S - Q) phi_k w_k psi'_k (-n_k),
  // and on A its tangential part over |A| (surface_centres.hpp).
  const real gap = probe.sums.gap(), weight = probe.sums.weight;
  vec3 on_normal{0, 0, 0};
  for (index_t e = first; e < last; ++e) {
    if (entry_group_[e] != g) continue;
    const index_t j = pair_partner_[e];
    const contact::SurfacePoint& point = surface_point(j);
    const real slope = contact::facing_share_slope(point, probe.facing, true);
    if (slope == 0) continue;
    const contact::PointTerms raw = contact::point_terms(point, probe.point, probe.support);
    if (raw.weight == 0) continue;
    const real coefficient =
        (probe.push * (raw.distance - gap) / weight - probe.taper) * surface_fade_of(j) * raw.weight * slope;
    for (int c = 0; c < 3; ++c) on_normal[c] -= coefficient * point.normal[c];
  }
  const contact::SurfacePoint& own = surface_point(i);
  const real size = surface_sizes_[surface_slot_[i]];
  const real along = dot(on_normal, own.normal);
  return {(on_normal[0] - along * own.normal[0]) / size, (on_normal[1] - along * own.normal[1]) / size,
          (on_normal[2] - along * own.normal[2]) / size};
}

real ContactModel::surface_share(const ProbeState& probe, index_t j) const {
  const contact::SurfacePoint& point = surface_point(j);
  const real share = contact::facing_share(point, probe.facing, probe.smooth_facing);
  if (share == 0) return 0;
  return share * surface_fade_of(j) * contact::point_terms(point, probe.point, probe.support).weight /
         probe.sums.weight;
}

void ContactModel::measure_bodies(const Model& model, const State& state) {
  // A ghost body takes the motion its owner gave (give_ghost_motions): this process may hold
  // only the ghost's nodes within reach of its own, the rest left where they were.
  const std::int64_t count = static_cast<std::int64_t>(touching_bodies_.size());
  std::vector<std::uint8_t> measured(ghosts_.any() ? count : 0, 1);
  in_parallel([&] {
#pragma omp for schedule(dynamic, 16)
    for (std::int64_t k = 0; k < count; ++k) {
      const index_t b = touching_bodies_[k];
      const index_t* nodes = body_nodes_.data() + body_node_offsets_[b];
      body_load_[k] = {0, 0, 0, 0, 0, 0};
      const BodyMotion* given = ghosts_.ghost(body_particle_[b]) ? ghosts_.given(nodes[0]) : nullptr;
      if (given) {
        body_motion_[k] = *given;
        measured[k] = 0;
      } else {
        body_motion_[k] =
            measure_body(model, state, nodes, body_node_offsets_[b + 1] - body_node_offsets_[b], dimension_);
      }
    }
  });
  if (ghosts_.any()) check_ghost_motions(measured);
}

void ContactModel::check_ghost_motions(const std::vector<std::uint8_t>& measured) const {
  auto unknown = [&](index_t body) {
    return ghosts_.ghost(body_particle_[body]) && measured[body_touch_[body]];
  };
  if (std::none_of(touching_bodies_.begin(), touching_bodies_.end(), unknown)) return;  // all given
  for (std::size_t slot = 0; slot < particle_slot_count_; ++slot) {
    const index_t p = slots_[slot][0], q = slots_[slot][1];
    if (body_touch_[p] == not_touching || body_touch_[q] == not_touching) continue;
    if (ghosts_.ghost(body_particle_[p]) && ghosts_.ghost(body_particle_[q])) continue;
    if (unknown(p) || unknown(q)) {
      const index_t ghost = unknown(p) ? p : q;
      throw std::runtime_error("contact: the motion of ghost body " + std::to_string(ghost) +
                               " (first node " + std::to_string(body_nodes_[body_node_offsets_[ghost]]) +
                               ") was not given, and it touches a body of this process");
    }
  }
}

void ContactModel::measure_surface_normals(const Model& model, const State& state) {
  // The surface normal of every node in a node pair in contact between two bodies (listed by
  // measure_contacts, in node order, for the look-ups of pair_surface_normal), in parallel; a
  // ghost node's as its owner gave it, if it did (give_ghost_surface_normals).
  touching_normals_.resize(touching_nodes_.size());
  release_excess(touching_nodes_);
  release_excess(touching_normals_);
  const std::int64_t count = static_cast<std::int64_t>(touching_nodes_.size());
  in_parallel([&] {
#pragma omp for schedule(static)
    for (std::int64_t k = 0; k < count; ++k) {
      const vec3* given = ghosts_.normal(touching_nodes_[k]);
      touching_normals_[k] = given ? *given : surface_normal_at(model, state, touching_nodes_[k]);
    }
  });
}

void ContactModel::release_rested_pairs(const Model& model, const State& state,
                                        const std::vector<index_t>& nodes) {
  // The sphere pairs under the surface law touch only past the larger rest of their nodes
  // (pair_geometry); the entries of those that do not are cleared, and those that do count in
  // the deepest overlap. Each pair is listed both ways with the same distance and rest, so the
  // partner, which is in `nodes` too, clears its entry alike. After the parallel pass, when
  // every rest of the step is settled: the same for any thread count.
  for (const index_t i : nodes) {
    for (index_t e = pair_offsets_[i]; e < pair_offsets_[i + 1]; ++e) {
      if (pair_stiffness_[e] == 0 || surface_entry(model, i, e) || !slot_law(pair_slot_[e]).surface) continue;
      const real overlap = pair_geometry(model, state, i, e).overlap;
      if (overlap > 0) {
        if (!ghosts_.ghost(model.node_particle()[i]))  // its owner counts it
          statistics_.add_overlap(overlap / slot_law(pair_slot_[e]).contact_radius, state.step);
      } else {
        pair_stiffness_[e] = 0;
      }
    }
  }
}

real ContactModel::spring_energy(const Model& model, const State& state) const {
  const index_t n = model.node_count();
  std::vector<real> energy(n);
  std::vector<std::uint32_t> pairs(n), walls(n);
  node_contact_terms(model, state, energy.data(), pairs.data(), walls.data());
  real total = 0;
  for (index_t i = 0; i < n; ++i) total += energy[i];
  return total;
}

void ContactModel::node_contact_terms(const Model& model, const State& state, real* energy,
                                      std::uint32_t* pairs, std::uint32_t* walls) const {
  const index_t n = model.node_count();
  std::fill(energy, energy + n, 0.0);
  std::fill(pairs, pairs + n, 0u);
  std::fill(walls, walls + n, 0u);
  if (!built_) return;
  for (const index_t i : contact_nodes_) {
    for (index_t e = pair_offsets_[i]; e < pair_offsets_[i + 1]; ++e) {
      if (pair_partner_[e] < i) continue;  // each pair once: the lists hold both directions
      if (e < pair_stiffness_.size() && pair_stiffness_[e] > 0 && !probe_entry(e)) ++pairs[i];
      if (surface_entry(model, i, e)) continue;  // the probes below
      const real overlap = pair_geometry(model, state, i, e).overlap;
      if (overlap > 0) energy[i] += 0.5 * entry_stiffness(model, i, e) * overlap * overlap;
    }
    for (index_t e = wall_offsets_[i]; e < wall_offsets_[i + 1]; ++e) {
      if (e < wall_entry_stiffness_.size() && wall_entry_stiffness_[e] > 0) ++walls[i];
      const WallPoints& points = wall_points_[e];
      const real contact_radius = slot_law(wall_slot_[e]).contact_radius;
      for (std::size_t k = 0; k < points.count; ++k) {
        const real overlap = (sphere_of(points, k) == 1 ? points.osculating_radius : contact_radius) -
                             points.points[k].distance;
        if (overlap > 0)
          energy[i] += 0.5 * points.weights[k] * wall_spring_stiffness(model, i, e) * overlap * overlap;
      }
    }
  }
  // The surface probes, from their last evaluation: k delta^2 tau / 2 = P^2 / (2 k tau).
  for (const ProbeState& probe : probes_) {
    const index_t i = groups_[probe.group].probe;
    ++pairs[i];
    energy[i] +=
        0.5 * probe.push * probe.push / (probe.stiffness * contact::surface_taper(probe.sums.weight));
  }
}

}  // namespace granulate
