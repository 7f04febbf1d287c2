// The forces on the nodes: node-pair springs and friction, the surface probes' friction and
// couples, node-wall contact, the walls' reactions, and the contact network (per pair of bodies
// in contact the whole force of the last evaluation).
#include <algorithm>
#include <cmath>

#include "contact_vectors.hpp"
#include "granulate/contact/contact_model.hpp"
#include "granulate/in_parallel.hpp"

namespace granulate {
using namespace contact_vectors;

void ContactModel::probe_frictions(const Model& model, const State& state, real dt) {
  const std::int64_t count = static_cast<std::int64_t>(contact_nodes_.size());
  in_parallel([&] {
    std::vector<real> shares;  // scratch of this thread
#pragma omp for schedule(static)
    for (std::int64_t k = 0; k < count; ++k) probe_friction(model, state, contact_nodes_[k], dt, shares);
  });
}

void ContactModel::probe_friction(const Model& model, const State& state, index_t i, real dt,
                                  std::vector<real>& shares) {
  const auto [group_begin, group_end] = groups_of(i);
  if (group_begin == group_end) return;
  const index_t material = model.node_material()[i];
  const index_t first = pair_offsets_[i], last = pair_offsets_[i + 1];
  shares.resize(last - first);  // w_k / S of each entry, set for a group's entries before use
  for (index_t g = group_begin; g < group_end; ++g) {
    ProbeState* touching = touching_probe(g);
    if (touching == nullptr) continue;
    ProbeState& probe = *touching;
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
      const real fraction = shares[e - first] = surface_share(probe, j);
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

void ContactModel::target_forces(const contact::SurfacePoint& point, real size, real stretch,
                                 const ProbeState& probe, vec3& on_point, vec3& on_normal,
                                 vec3& on_friction) const {
  // The exact reaction of a target's surface point and normal to the probe's energy (see
  // contact/surface_law.hpp), and its share phi w / S of the friction force, opposite (on the
  // node; probe_couples adds the couple). Its weight phi w moves with n_k (m_k) and with |A|
  // through the fade: dE/d(phi w) = -P (d - g) / S + Q, times w phi' / |A_0| along n on A.
  on_point = on_normal = on_friction = {0, 0, 0};
  // Its share psi moves with n_k too: (P (d - g) / S - Q) phi w psi' facing on n_k.
  const real fade = contact::surface_fade(stretch);
  const real facing = contact::facing_share(point, probe.facing, probe.smooth_facing);
  if (fade == 0 || facing == 0) return;
  const contact::PointTerms raw = contact::point_terms(point, probe.point, probe.support);
  if (raw.weight == 0) return;
  const contact::PointTerms t = contact::faded(raw, fade * facing);
  const real gap = probe.sums.gap(), weight = probe.sums.weight;
  const vec3 share = contact::point_share(t, gap, weight);
  const real fraction = t.weight / weight;
  const real pull = probe.push * (t.distance - gap) / weight - probe.taper;  // -dE/d(omega)
  const real fade_slope = contact::surface_fade_slope(stretch);
  const real radial = fade_slope == 0 ? 0.0 : pull * raw.weight * facing * fade_slope * stretch / size;
  const real turn =
      pull * raw.weight * fade * contact::facing_share_slope(point, probe.facing, probe.smooth_facing);
  const real along = turn * contact::facing_cosine(point, probe.facing);  // its normal part
  for (int c = 0; c < 3; ++c) {
    on_point[c] = -probe.push * share[c] + probe.taper * t.weight_gradient[c];
    on_friction[c] = -fraction * probe.friction[c];
    on_normal[c] = (probe.push * fraction * t.normal_sensitivity[c] + pull * t.weight_normal[c]) / size +
                   radial * point.normal[c] + (turn * probe.facing[c] - along * point.normal[c]) / size;
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
  in_parallel([&] {
#pragma omp for schedule(static)
    for (std::int64_t k = 0; k < count; ++k) {
      const index_t i = contact_nodes_[k];
      const SurfaceAnchor* anchor = centres_.anchor(model, i);
      const NodeContactForces forces = gather_node_forces(model, state, i, anchor != nullptr, dt);
      vec total{0, 0, 0};
      for (int c = 0; c < 3; ++c) total[c] = forces.at_centre[c] + forces.at_surface[c] + forces.at_node[c];
      if (anchor != nullptr) {
        anchor_forces_[k] = anchored_vector_force(model, state, i, forces);
        real weights = 0;
        for (std::size_t a = 0; a < anchor->nodes.size() && anchor->nodes[a] != SurfaceAnchor::no_anchor; ++a)
          weights += anchor->weights[a];
        for (int c = 0; c < 3; ++c) total[c] -= weights * anchor_forces_[k][c];
      }
      for (int c = 0; c < 3; ++c) state.forces[3 * i + c] += total[c] / model.volumes()[i];
    }
  });
  if (centres_.any()) spread_anchor_forces(model, state);
}

ContactModel::NodeContactForces ContactModel::gather_node_forces(const Model& model, State& state, index_t i,
                                                                 bool anchored, real dt) {
  NodeContactForces forces;
  auto& [at_centre, at_surface, at_node, on_vector] = forces;
  for (index_t e = pair_offsets_[i]; e < pair_offsets_[i + 1]; ++e) {
    if (pair_stiffness_[e] == 0 || probe_entry(e)) continue;
    const vec force = pair_force(model, state, i, e, dt);
    for (int c = 0; c < 3; ++c) at_centre[c] += force[c];
  }
  for (index_t e = wall_offsets_[i]; e < wall_offsets_[i + 1]; ++e) {
    wall_entry_reaction_[e] = {0, 0, 0, 0, 0, 0};
    if (wall_entry_stiffness_[e] == 0) continue;
    wall_force(model, state, i, e, dt, forces);
  }
  const auto [group_begin, group_end] = groups_of(i);
  for (index_t g = group_begin; g < group_end; ++g) {
    const ProbeState* probe = touching_probe(g);
    if (probe == nullptr) continue;
    for (int c = 0; c < 3; ++c) {
      at_surface[c] += probe->push * probe->gradient[c] - probe->taper * probe->sums.spread[c];
      at_node[c] += probe->friction[c];
    }
    if (probe->fade_force != 0) {  // only on a node with a surface point, whose fade is below 1
      const vec3& n = surface_point(i).normal;
      for (int c = 0; c < 3; ++c) on_vector[c] -= probe->fade_force * n[c];
    }
    for (int c = 0; c < 3; ++c) on_vector[c] += probe->facing_force[c];
  }
  if (!anchored || surface_slot_.empty() || surface_slot_[i] == no_group) {
    return forces;
  }
  const contact::SurfacePoint& own = surface_point(i);
  const real size = surface_sizes_[surface_slot_[i]];
  const real stretch = surface_stretches_[surface_slot_[i]];
  for (index_t e = pair_offsets_[i]; e < pair_offsets_[i + 1]; ++e) {
    const index_t g = entry_target_[e];
    const ProbeState* probe = g == no_group ? nullptr : touching_probe(g);
    if (probe == nullptr) continue;
    vec on_point, on_normal, on_friction;
    target_forces(own, size, stretch, *probe, on_point, on_normal, on_friction);
    for (int c = 0; c < 3; ++c) {
      at_surface[c] += on_point[c];
      on_vector[c] += on_normal[c];
      at_node[c] += on_friction[c];
    }
  }
  return forces;
}

vec3 ContactModel::anchored_vector_force(const Model& model, const State& state, index_t i,
                                         const NodeContactForces& forces) const {
  // The levers of the forces on the centre and on the surface point (both on the normal).
  const SurfaceCentres::Seen seen = centres_.seen(model, i);
  vec on_vector = forces.on_vector;
  vec along{0, 0, 0};
  for (int c = 0; c < 3; ++c)
    along[c] = seen.centre_length * forces.at_centre[c] + seen.surface_length * forces.at_surface[c];
  if (along != vec{0, 0, 0}) {
    const vec lever = centres_.lever(state, seen, i, 1.0, along);
    for (int c = 0; c < 3; ++c) on_vector[c] += lever[c];
  }
  return on_vector;
}

void ContactModel::spread_anchor_forces(const Model& model, State& state) const {
  const std::int64_t count = static_cast<std::int64_t>(contact_nodes_.size());
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
  body_couple_sums_.start(touching_bodies_.size(),
                          [&](std::size_t touch) { return body_splittable_[touching_bodies_[touch]]; });
  auto add = [&](index_t touch, index_t i, const vec& couple) {
    if (body_couple_sums_.summed(touch)) {
      body_couple_sums_.add(touch, i, couple);
    } else {
      for (int c = 0; c < 3; ++c) body_load_[touch][3 + c] += couple[c];
    }
  };
  for (const ProbeState& probe : probes_) {
    if (probe.friction == vec3{0, 0, 0}) continue;
    const ProbeGroup& group = groups_[probe.group];
    const index_t i = group.probe;
    const vec own =
        cross({probe.point[0] - x[3 * i], probe.point[1] - x[3 * i + 1], probe.point[2] - x[3 * i + 2]},
              probe.friction);
    const vec target = cross(
        {probe.foot[0] - probe.point[0], probe.foot[1] - probe.point[1], probe.foot[2] - probe.point[2]},
        probe.friction);
    add(body_touch_[node_body_[i]], i, own);
    add(body_touch_[group.body], i, target);
  }
  body_couple_sums_.finish_sweep();  // body_loads' sweep next
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
    const real mi = model.density(i) * model.volumes()[i], mj = model.density(j) * model.volumes()[j];
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
  for (const ProbeState& probe : probes_) {
    const ProbeGroup& group = groups_[probe.group];
    const std::size_t slot = group.slot;
    if (slot_touch_[slot] == not_touching) continue;
    const real sign = node_body_[group.probe] == slots_[slot][0] ? 1.0 : -1.0;
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

void ContactModel::wall_force(const Model& model, const State& state, index_t i, index_t e, real dt,
                              NodeContactForces& forces) {
  // Springs at every contact point of the entry, on the centre of its sphere; friction at the
  // deepest point p, on the node with its couple (p - x_i) x F_t (contact_couple), from the
  // slip of p moving with the node and its body's rotation. The wall takes the opposite force
  // at p. An osculating sphere's springs act on the node too, and the rest of their energy's
  // derivative, through the body's rotation that turns o about y_i, is a couple on the body
  // (osculating_couple): a round particle's surface deforms under the load where it is
  // applied, and a circle's push passes through its centre.
  const Wall& wall = walls_[wall_entry_[e][0]];
  const contact::Law& law = wall_laws_[wall_entry_[e][0] * material_count_ + model.node_material()[i]];
  const WallPoints& points = wall_points_[e];
  const WallSpheres spheres = wall_spheres(model, state, i, e);
  const WallGeometry g = wall_geometry(model, i, e, spheres);
  const real k = wall_spring_stiffness(model, i, e);
  std::array<vec, 2> on_sphere{};
  real push_total = 0;
  for (std::size_t point = 0; point < points.count; ++point) {
    const int sphere = sphere_of(points, point);
    const real push = contact::normal_force(points.weights[point] * k,
                                            spheres.radius[sphere] - points.points[point].distance);
    push_total += push;
    for (int c = 0; c < 3; ++c) on_sphere[sphere][c] += push * points.points[point].normal[c];
  }
  const vec& point = g.point;
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
  vec force{0, 0, 0};
  for (int c = 0; c < 3; ++c) force[c] = on_sphere[0][c] + on_sphere[1][c] + friction[c];
  const vec torque =
      cross({point[0] - wall.center[0], point[1] - wall.center[1], point[2] - wall.center[2]}, force);
  for (int c = 0; c < 3; ++c) {
    forces.at_node[c] += friction[c] + on_sphere[1][c];
    forces.at_centre[c] += on_sphere[0][c];
  }
  wall_entry_reaction_[e] = {-force[0], -force[1], -force[2], -torque[0], -torque[1], -torque[2]};
}

vec3 ContactModel::contact_couple(const Model& model, const State& state, index_t i) const {
  // The couple of node i's friction forces about the point they are applied at (the contact
  // centre for node pairs, the node for walls), from the springs as pass C left them
  // (F_t = -kt xi, capped or not), and of its osculating wall springs, (o - y_i) x F.
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
    if (wall_points_[e].osculating > 0) {
      const vec moment = osculating_couple(model, state, i, e);
      for (int c = 0; c < 3; ++c) couple[c] += moment[c];
    }
    if (wall_spring_[e] == no_spring) continue;
    const contact::Law& law = wall_laws_[wall_entry_[e][0] * material_count_ + node_material[i]];
    if (law.peridem_friction || law.friction == 0) continue;
    const WallGeometry g = wall_geometry(model, i, e, wall_spheres(model, state, i, e));
    const real kt = law.tangential_stiffness_ratio * g.stiffness;
    const vec& xi = springs_[wall_spring_[e]];
    const real* x = state.positions.data();
    const vec lever{g.point[0] - x[3 * i], g.point[1] - x[3 * i + 1], g.point[2] - x[3 * i + 2]};  // p - x_i
    const vec moment = cross(lever, {-kt * xi[0], -kt * xi[1], -kt * xi[2]});
    for (int c = 0; c < 3; ++c) couple[c] += moment[c];
  }
  return couple;
}

vec3 ContactModel::osculating_couple(const Model& model, const State& state, index_t i, index_t e) const {
  // -dE/dtheta of the entry's energy for a rotation theta of the body, which turns each
  // osculating sphere's normal n (o = y + (d - r) n): E = k/2 [sum_j w_j delta_j^2 + rest
  // sum_c delta_c^2], rest = 1 - sum_j w_j while positive (the contact sphere's points c).
  // delta_j turns with o: (o - y) x F_j, F_j = k w_j delta_j m_j. w_j = c_d W(r |n + m_j| / a)
  // turns with n: dw_j/dtheta = c_d W' (r / a) (n x m_j) / |n + m_j|.
  const WallPoints& points = wall_points_[e];
  const real k = wall_spring_stiffness(model, i, e);
  const SurfaceCentres::Seen seen = centres_.seen(model, i);
  const real r = points.osculating_radius;
  const real support = contact::surface_support_factor * seen.mesh_size;
  const vec& centre = points.osculating_centre;
  const real* x = state.positions.data();
  const vec arm{centre[0] - x[3 * i], centre[1] - x[3 * i + 1], centre[2] - x[3 * i + 2]};
  const real length = seen.surface_length - r;  // o - y = (d - r) n
  const vec n{arm[0] / length, arm[1] / length, arm[2] / length};
  vec push{0, 0, 0}, weight_turn{0, 0, 0};  // sum_j F_j, and -dE/dtheta through the weights
  real share = 0, rest_energy = 0;
  vec share_turn{0, 0, 0};  // d(sum_j w_j)/dtheta
  for (std::size_t point = 0; point < points.count; ++point) {
    const vec& m = points.points[point].normal;
    if (point >= points.osculating) {
      const real overlap = slot_law(wall_slot_[e]).contact_radius - points.points[point].distance;
      rest_energy += 0.5 * k * overlap * overlap;
      continue;
    }
    const real overlap = r - points.points[point].distance;
    const real force = contact::normal_force(points.weights[point] * k, overlap);
    for (int c = 0; c < 3; ++c) push[c] += force * m[c];
    share += points.weights[point];
    const vec chord{n[0] + m[0], n[1] + m[1], n[2] + m[2]};
    const real size = std::sqrt(dot(chord, chord));
    if (!(size > 0)) continue;
    const real slope = contact::osculating_scale(dimension_) *
                       contact::surface_weight_slope(r * size / support) * r / (support * size);
    const vec turn = cross(n, m);
    for (int c = 0; c < 3; ++c) {
      weight_turn[c] -= 0.5 * k * overlap * overlap * slope * turn[c];
      share_turn[c] += slope * turn[c];
    }
  }
  vec couple = cross(arm, push);
  for (int c = 0; c < 3; ++c) {
    couple[c] += weight_turn[c];
    if (share < 1) couple[c] += rest_energy * share_turn[c];
  }
  return couple;
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
