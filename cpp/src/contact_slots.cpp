// Per pair of touching bodies (slot): the body dashpots, rolling resistance, each collision's force
// turned to the surface normal, and the rigid-body loads they put on the bodies.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "contact_vectors.hpp"
#include "granulate/contact/contact_model.hpp"
#include "granulate/in_parallel.hpp"

namespace granulate {
using namespace contact_vectors;

void ContactModel::slot_dashpots(const State& state, real dt) {
  // Damping between bodies (see contact_law.hpp): per pair of touching bodies, a dashpot
  // 2 zeta sqrt(M K_s) along the mean contact normal on the approach speed of the bodies at the
  // contact point, applied to each body at that point as a rigid-body load. K_s = F / x is the
  // secant stiffness of the collision (contact force over the approach since the bodies
  // touched); the sum of the contact springs K overestimates it when the bodies deform, and the
  // dashpot would then overdamp.
  const real t = state.time;
  std::fill(wall_damping_.begin(), wall_damping_.end(), std::array<real, 6>{0, 0, 0, 0, 0, 0});
  wall_slot_terms_.assign(slots_.size() - particle_slot_count_, {0, 0, 0, 0, 0, 0, 0, 0, 0});
  for (std::size_t slot = 0; slot < slots_.size(); ++slot) {
    const bool wall_slot = slot >= particle_slot_count_;
    const index_t p = slots_[slot][0], q = slots_[slot][1];
    if (!wall_slot && p == q) {  // fragments of one body: damped node pair by node pair
      collisions_.close(slot);
      continue;
    }
    const index_t touch = slot_touch_[slot];
    // A collision lasts until the bodies are back where they first touched (approach x = 0),
    // or have slid apart in a gap (slid_apart), not while springs are in contact: the surface
    // nodes of deformable bodies chatter (touch, part, touch again) within one collision when
    // the contact is stiffer than the material, and a dashpot restarted at each touch would damp
    // the collision many times over.
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
      if (slid_apart(slot, collision, relative, dt)) collisions_.close(slot);
      continue;
    }
    collision.slide = {0, 0, 0};
    const real zeta = damping_ratio(slot, collision, approach * dt);
    const real K = slot_stiffness_[slot];
    const real secant = collision.approach > 0 ? std::min(K, slot_force_[touch] / collision.approach) : K;
    const real mass = slot_reduced_mass(slot);
    const real duration = std::numbers::pi * std::sqrt(mass / secant);
    if (duration > 0) collision.phase = static_cast<float>(collision.phase + dt / duration);
    if (zeta == 0) continue;
    // As the bodies part, the dashpot pulls no harder than the springs push: the contact force
    // never holds them together (power_law_damping.hpp fits zeta to that). PeriDEM's law is not
    // clipped.
    real damping = 2.0 * zeta * std::sqrt(mass * secant) * approach;
    if (!slot_law(slot).node_pair) damping = std::max(damping, -slot_force_[touch]);
    for (int k = 0; k < 3; ++k) slot_load_[touch][k] += damping * normal[k];
    if (wall_slot) {  // the wall takes the opposite force, at the contact point
      add_body_load(p, point, {damping * normal[0], damping * normal[1], damping * normal[2]});
      const vec arm{point[0] - walls_[q].center[0], point[1] - walls_[q].center[1],
                    point[2] - walls_[q].center[2]};
      const vec on_wall{-damping * normal[0], -damping * normal[1], -damping * normal[2]};
      const vec torque = cross(arm, on_wall);
      auto& terms = wall_slot_terms_[slot - particle_slot_count_];
      for (int k = 0; k < 3; ++k) {
        wall_damping_[q][k] += on_wall[k];
        wall_damping_[q][3 + k] += torque[k];
        terms[k] = on_wall[k];
        terms[3 + k] = torque[k];
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
        wall_slot_terms_[slot - particle_slot_count_][6 + k] = torque[k];
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

bool ContactModel::slid_apart(std::size_t slot, contact::Collision& collision, const vec3& relative,
                              real dt) const {
  // x is measured along the collision's last normal, so bodies that slide apart sideways in a
  // gap keep x > 0: their collision would never end, and the next touch, elsewhere, would take
  // its dashpot from a stale x (F / x too soft). Their sideways travel since the last touch ends
  // it past the contact radius; a distance to the other body would need the lists beyond that
  // radius, which the skin sets.
  const vec& n = collision.normal;
  const real along = dot(relative, n);
  real travel = 0;
  for (int k = 0; k < 3; ++k) {
    collision.slide[k] = static_cast<float>(collision.slide[k] + (relative[k] - along * n[k]) * dt);
    travel += static_cast<real>(collision.slide[k]) * collision.slide[k];
  }
  return std::sqrt(travel) > slot_law(slot).contact_radius;
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

void ContactModel::body_loads(const Model& model, State& state) {
  // Dashpot forces at contact points and the contact couples, as rigid-body loads: every node of
  // the body gets rho_i (F / M + alpha x (x_i - c)), alpha = I^-1 tau. They add up to F and tau.
  const auto& x = state.positions;
  auto& f = state.forces;
  const std::int64_t count = static_cast<std::int64_t>(touching_bodies_.size());
  in_parallel([&] {
#pragma omp for schedule(dynamic, 16)
    for (std::int64_t touch = 0; touch < count; ++touch) {
      const index_t b = touching_bodies_[touch];
      std::array<real, 6> total = body_load_[touch];
      const bool summed = body_couple_sums_.summed(touch);
      for (index_t k = body_contact_offsets_[b]; k < body_contact_offsets_[b + 1]; ++k) {
        const vec couple = contact_couple(model, state, contact_nodes_[k]);
        if (summed) {
          body_couple_sums_.add(touch, contact_nodes_[k], couple);
        } else {
          for (int c = 0; c < 3; ++c) total[3 + c] += couple[c];
        }
      }
      if (summed) {  // the slots' loads, then the couples' block sums
        body_couple_sums_.finish_sweep(touch);
        const auto couples = body_couple_sums_.rounded(touch);
        for (int c = 0; c < 3; ++c) total[3 + c] += couples[c];
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
        for (int c = 0; c < 3; ++c) f[3 * i + c] += model.density(i) * (acceleration[c] + spin[c]);
      }
    }
  });
}

}  // namespace granulate
