#include "granulate/contact/surface_centres.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace granulate {

void SurfaceCentres::find(const Model& model, const State& state, std::vector<real> depth,
                          const std::vector<std::uint8_t>& outer_layers) {
  found_ = true;
  depth_ = std::move(depth);
  surface_ = outer_layers;
  any_ = std::any_of(depth_.begin(), depth_.end(), [](real s) { return s > 0; });
  // Which nodes are seen at anchors (1 byte each: most nodes have none, and contact asks for
  // every node every step); under the surface law, which look them up many times per step, a
  // pointer per node as well.
  anchored_.assign(any_ ? model.node_count() : 0, 0);
  const bool cached = any_ && std::any_of(surface_.begin(), surface_.end(), [](std::uint8_t f) { return f; });
  anchors_.assign(cached ? model.node_count() : 0, nullptr);
  for (index_t i = 0; i < anchored_.size(); ++i) {
    const SurfaceAnchor* a = lookup(model, i);
    anchored_[i] = a != nullptr;
    if (cached) anchors_[i] = a;
  }
  if (!any_ || state.bonds.broken(model.bond_offsets(), 0, model.node_count()) == 0) return;
  for (index_t i = 0; i < model.node_count(); ++i) {
    const SurfaceAnchor* a = anchor(model, i);
    if (a == nullptr) continue;
    const index_t first = model.particles()[model.node_particle()[i]].first_node;
    const NodeBonds bonds = model.node_bonds(i);
    for (const index_t k : a->nodes) {
      const index_t b = k == SurfaceAnchor::no_anchor ? bonds.count : bonds.find(first + k);
      if (b != bonds.count && !state.bonds.intact(i, b)) detach(i);  // the bond broke
    }
  }
}

void SurfaceCentres::detach(index_t i) {
  anchored_[i] = 0;
  if (!anchors_.empty()) anchors_[i] = nullptr;
}

const SurfaceAnchor* SurfaceCentres::lookup(const Model& model, index_t i) const {
  const index_t p = model.node_particle()[i];
  if (!(depth_[p] > 0)) return nullptr;
  const SurfaceAnchor* a = model.surface_anchor(i);
  return a != nullptr && (a->depth == 0 || surface_[p]) ? a : nullptr;
}

void SurfaceCentres::detach_anchored(const Model& model, std::span<const std::array<index_t, 2>> pairs) {
  if (!found_ || !any_) return;
  for (const auto& [i, j] : pairs) {
    for (const auto& [node, other] : {std::array<index_t, 2>{i, j}, std::array<index_t, 2>{j, i}}) {
      const SurfaceAnchor* a = anchor(model, node);
      if (a == nullptr) continue;
      const index_t local = other - model.particles()[model.node_particle()[node]].first_node;
      if (std::find(a->nodes.begin(), a->nodes.end(), local) != a->nodes.end()) detach(node);
    }
  }
}

SurfaceCentres::Seen SurfaceCentres::seen(const Model& model, index_t i) const {
  Seen s;
  s.anchor = anchor(model, i);
  if (s.anchor == nullptr) return s;
  const index_t p = model.node_particle()[i];
  const Particle& particle = model.particles()[p];
  s.first = particle.first_node;
  s.mesh_size = particle.mesh_size;
  s.along_normal = surface_[p] != 0;
  s.surface_length = s.anchor->depth * particle.mesh_size;
  s.centre_length = (s.anchor->depth - 0.5 * depth_[p] * s.anchor->reach) * particle.mesh_size;
  return s;
}

SurfaceCentres::vec3 SurfaceCentres::anchored_vector(const Seen& s, const std::vector<real>& field,
                                                     index_t i) {
  vec3 sum{0, 0, 0};
  if (s.anchor == nullptr) return sum;
  const real* f = field.data();
  const SurfaceAnchor& a = *s.anchor;
  for (std::size_t k = 0; k < a.nodes.size() && a.nodes[k] != SurfaceAnchor::no_anchor; ++k) {
    const index_t j = s.first + a.nodes[k];
    for (int d = 0; d < 3; ++d) sum[d] += a.weights[k] * (f[3 * j + d] - f[3 * i + d]);
  }
  return sum;
}

namespace {

/// The factor f of the linear form y_i + f A_i outside the surface law: length / ((h/2) |o_i|).
real linear_scale(const SurfaceCentres::Seen& s, real length) {
  return length / (0.5 * s.mesh_size * s.anchor->reach);
}

real norm(const SurfaceCentres::vec3& a) {
  return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
}

}  // namespace

SurfaceCentres::vec3 SurfaceCentres::point(const State& state, const Seen& s, index_t i, real length) const {
  const real* y = state.positions.data();
  vec3 q{y[3 * i], y[3 * i + 1], y[3 * i + 2]};
  if (length == 0 || s.anchor == nullptr) return q;
  const vec3 a = anchored_vector(s, state.positions, i);
  const real scale = s.along_normal ? length / norm(a) : linear_scale(s, length);
  for (int d = 0; d < 3; ++d) q[d] += scale * a[d];
  return q;
}

SurfaceCentres::vec3 SurfaceCentres::point_velocity(const State& state, const Seen& s, index_t i,
                                                    real length) const {
  const real* v = state.velocities.data();
  vec3 u{v[3 * i], v[3 * i + 1], v[3 * i + 2]};
  if (length == 0 || s.anchor == nullptr) return u;
  const vec3 rate = anchored_vector(s, state.velocities, i);
  if (!s.along_normal) {
    const real scale = linear_scale(s, length);
    for (int d = 0; d < 3; ++d) u[d] += scale * rate[d];
    return u;
  }
  const vec3 a = anchored_vector(s, state.positions, i);
  const real size = norm(a);
  const real along = (a[0] * rate[0] + a[1] * rate[1] + a[2] * rate[2]) / (size * size);
  for (int d = 0; d < 3; ++d) u[d] += length * (rate[d] - along * a[d]) / size;
  return u;
}

SurfaceCentres::vec3 SurfaceCentres::lever(const State& state, const Seen& s, index_t i, real length,
                                           const vec3& force) const {
  if (length == 0 || s.anchor == nullptr) return {0, 0, 0};
  if (!s.along_normal) {
    const real scale = linear_scale(s, length);
    return {scale * force[0], scale * force[1], scale * force[2]};
  }
  const vec3 a = anchored_vector(s, state.positions, i);
  const real size2 = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
  const real size = std::sqrt(size2);
  const real along = (a[0] * force[0] + a[1] * force[1] + a[2] * force[2]) / size2;
  return {length * (force[0] - along * a[0]) / size, length * (force[1] - along * a[1]) / size,
          length * (force[2] - along * a[2]) / size};
}

void SurfaceCentres::fill_positions(const Model& model, const State& state, std::vector<real>& x) const {
  x.resize(state.positions.size());
  const std::int64_t n = model.node_count();
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    const vec3 c = at_list(model, state, static_cast<index_t>(i));
    for (int k = 0; k < 3; ++k) x[3 * i + k] = c[k];
  }
}

}  // namespace granulate
