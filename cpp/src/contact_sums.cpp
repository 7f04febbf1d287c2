// The sums per pair of touching bodies (slot) that pass B of a contact step makes: each slot's
// stiffness, the touching bodies and slots, and the slots' spring force, normal, contact point
// and surface normal from the node pairs, wall points and probes; a splittable particle's
// slots in block sums (contact/block_sums.hpp).
#include <algorithm>
#include <cmath>

#include "contact_vectors.hpp"
#include "granulate/contact/contact_model.hpp"

namespace granulate {
using namespace contact_vectors;

void ContactModel::sum_slot_stiffness() {
  // K per pair of bodies, summed in entry order (a splittable particle's slots in block sums):
  // each node pair of the sphere law is listed twice; a surface probe's entries share its
  // stiffness.
  std::fill(slot_stiffness_.begin(), slot_stiffness_.end(), 0.0);
  slot_stiffness_sums_.start(slots_.size());
  std::uint64_t touching = 0, wall_touching = 0;
  // Entry by entry; a block sum needs the entry's node: its list's, found by bisection (the
  // few entries in contact only).
  auto add = [&](std::size_t slot, std::size_t e, const std::vector<index_t>& offsets, real k) {
    if (k == 0) return;  // most entries: apart (and +0.0 changes no sum)
    if (!slot_splittable(slot)) {
      slot_stiffness_[slot] += k;
      return;
    }
    const auto node =
        std::upper_bound(offsets.begin(), offsets.end(), static_cast<index_t>(e)) - offsets.begin() - 1;
    slot_stiffness_sums_.add(slot, static_cast<index_t>(node), {k});
  };
  for (std::size_t e = 0; e < pair_stiffness_.size(); ++e) {
    const bool probe = probe_entry(e);
    add(pair_slot_[e], e, pair_offsets_, (probe ? 1.0 : 0.5) * pair_stiffness_[e]);
    touching += pair_stiffness_[e] > 0 && !probe ? 1 : 0;
  }
  for (std::size_t e = 0; e < wall_entry_stiffness_.size(); ++e) {
    add(wall_slot_[e], e, wall_offsets_, wall_entry_stiffness_[e]);
    wall_touching += wall_entry_stiffness_[e] > 0 ? 1 : 0;
  }
  touching /= 2;
  touching += probes_.size();
  slot_stiffness_sums_.finish_sweep();
  for (const std::size_t slot : slot_stiffness_sums_.items())
    slot_stiffness_[slot] = slot_stiffness_sums_.rounded(slot)[0];
  statistics_.node_contacts = touching;
  statistics_.wall_contacts = wall_touching;
  assign_springs();
  find_touching();
}

void ContactModel::find_touching() {
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
  fit_exactly(body_motion_);
  fit_exactly(body_load_);
  slot_force_.assign(in_contact, 0.0);
  slot_normal_.assign(in_contact, vec3{0, 0, 0});
  slot_point_.assign(in_contact, vec3{0, 0, 0});
  slot_surface_normal_.assign(in_contact, vec3{0, 0, 0});
  slot_load_.assign(in_contact, vec3{0, 0, 0});
  fit_exactly(slot_force_);
  for (auto* v : {&slot_normal_, &slot_point_, &slot_surface_normal_, &slot_load_}) fit_exactly(*v);
}

void ContactModel::sum_slot_springs(const Model& model, const State& state) {
  // Spring force, spring-weighted normal (from the first body to the second, or from the wall to
  // the particle) and spring-weighted contact point per slot, summed in node order (a
  // splittable particle's slots in block sums).
  slot_spring_sums_.start(slot_force_.size());
  for (const index_t i : contact_nodes_) {
    for (index_t e = pair_offsets_[i]; e < pair_offsets_[i + 1]; ++e) {
      const index_t j = pair_partner_[e];
      const std::size_t slot = pair_slot_[e];
      if (pair_stiffness_[e] == 0 || probe_entry(e) || node_body_[i] == node_body_[j] ||
          node_body_[i] != slots_[slot][0])
        continue;
      const PairGeometry g = pair_geometry(model, state, i, e);
      const real spring = contact::normal_force(entry_stiffness(model, i, e), g.overlap);
      const vec surface = slot_law(slot).node_pair ? g.normal : pair_surface_normal(i, j, g.normal);
      const vec point{g.centre_i[0] + g.lever_i * g.normal[0], g.centre_i[1] + g.lever_i * g.normal[1],
                      g.centre_i[2] + g.lever_i * g.normal[2]};
      add_slot_spring(slot, i, spring, g.normal, point, surface);
    }
    for (index_t e = wall_offsets_[i]; e < wall_offsets_[i + 1]; ++e) {
      const std::size_t slot = wall_slot_[e];
      if (wall_entry_stiffness_[e] == 0) continue;
      const WallPoints& points = wall_points_[e];
      const WallSpheres spheres = wall_spheres(model, state, i, e);
      for (std::size_t k = 0; k < points.count; ++k) {
        const int sphere = sphere_of(points, k);
        const real overlap = spheres.radius[sphere] - points.points[k].distance;
        const real spring =
            contact::normal_force(points.weights[k] * wall_spring_stiffness(model, i, e), overlap);
        const real lever = spheres.radius[sphere] - 0.5 * overlap;
        const vec& normal = points.points[k].normal;
        const vec point{spheres.centre[sphere][0] - lever * normal[0],
                        spheres.centre[sphere][1] - lever * normal[1],
                        spheres.centre[sphere][2] - lever * normal[2]};
        add_slot_spring(slot, i, spring, normal, point, normal);
      }
    }
  }
  slot_spring_sums_.finish_sweep();  // the probes' sweep next
}

void ContactModel::add_slot_spring(std::size_t slot, index_t i, real spring, const vec3& normal,
                                   const vec3& point, const vec3& surface) {
  const index_t touch = slot_touch_[slot];
  if (slot_splittable(slot)) {
    slot_spring_sums_.add(touch, i,
                          {spring, spring * normal[0], spring * normal[1], spring * normal[2],
                           spring * point[0], spring * point[1], spring * point[2], spring * surface[0],
                           spring * surface[1], spring * surface[2]});
    return;
  }
  slot_force_[touch] += spring;
  for (int k = 0; k < 3; ++k) {
    slot_normal_[touch][k] += spring * normal[k];
    slot_point_[touch][k] += spring * point[k];
    slot_surface_normal_[touch][k] += spring * surface[k];
  }
}

void ContactModel::sum_probe_springs() {
  // The surface probes' pushes, in group order: the force k delta |G| along the surface's normal
  // (from the slot's first body to its second), at the probe point.
  for (const ProbeState& probe : probes_) {
    const ProbeGroup& group = groups_[probe.group];
    const real size = std::sqrt(dot(probe.gradient, probe.gradient));
    // G points out of the target body; the slot's normal from its first body to its second.
    const real sign = group.body == slots_[group.slot][0] ? 1.0 : -1.0;
    const vec along{sign * probe.gradient[0] / size, sign * probe.gradient[1] / size,
                    sign * probe.gradient[2] / size};
    add_slot_spring(group.slot, group.probe, probe.push * size, along, probe.point, along);
  }
  slot_spring_sums_.finish_sweep();
  for (const std::size_t touch : slot_spring_sums_.items()) {
    const auto sums = slot_spring_sums_.rounded(touch);
    slot_force_[touch] = sums[0];
    for (int k = 0; k < 3; ++k) {
      slot_normal_[touch][k] = sums[1 + k];
      slot_point_[touch][k] = sums[4 + k];
      slot_surface_normal_[touch][k] = sums[7 + k];
    }
  }
}

}  // namespace granulate
