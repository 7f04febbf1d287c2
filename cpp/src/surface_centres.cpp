#include "granulate/contact/surface_centres.hpp"

#include <algorithm>

namespace granulate {

void SurfaceCentres::find(const Model& model, const State& state, std::vector<real> depth) {
  found_ = true;
  depth_ = std::move(depth);
  detached_.clear();
  any_ = std::any_of(depth_.begin(), depth_.end(), [](real s) { return s > 0; });
  if (!any_ || state.bonds.broken(model.bond_offsets(), 0, model.node_count()) == 0) return;
  for (index_t i = 0; i < model.node_count(); ++i) {
    const SurfaceAnchor* a = anchor(model, i);
    if (a == nullptr) continue;
    const index_t first = model.particles()[model.node_particle()[i]].first_node;
    const NodeBonds bonds = model.node_bonds(i);
    for (const index_t k : a->nodes) {
      const index_t b = k == SurfaceAnchor::no_anchor ? bonds.count : bonds.find(first + k);
      if (b != bonds.count && !state.bonds.intact(i, b)) detach(model, i);  // the bond broke
    }
  }
}

void SurfaceCentres::detach(const Model& model, index_t i) {
  if (detached_.empty()) detached_.assign(model.node_count(), 0);
  detached_[i] = 1;
}

void SurfaceCentres::detach_anchored(const Model& model, std::span<const std::array<index_t, 2>> pairs) {
  if (!found_ || !any_) return;
  for (const auto& [i, j] : pairs) {
    for (const auto& [node, other] : {std::array<index_t, 2>{i, j}, std::array<index_t, 2>{j, i}}) {
      const SurfaceAnchor* a = anchor(model, node);
      if (a == nullptr) continue;
      const index_t local = other - model.particles()[model.node_particle()[node]].first_node;
      if (std::find(a->nodes.begin(), a->nodes.end(), local) != a->nodes.end()) detach(model, node);
    }
  }
}

const SurfaceAnchor* SurfaceCentres::anchor(const Model& model, index_t i) const {
  if (!any_ || !(depth_[model.node_particle()[i]] > 0)) return nullptr;
  if (!detached_.empty() && detached_[i]) return nullptr;
  return model.surface_anchor(i);
}

SurfaceCentres::vec3 SurfaceCentres::at_centre(const Model& model, const std::vector<real>& field,
                                               index_t i) const {
  const real* f = field.data();
  vec3 c{f[3 * i], f[3 * i + 1], f[3 * i + 2]};
  const SurfaceAnchor* a = anchor(model, i);
  if (a == nullptr) return c;
  const index_t p = model.node_particle()[i];
  const index_t first = model.particles()[p].first_node;
  for (std::size_t k = 0; k < a->nodes.size() && a->nodes[k] != SurfaceAnchor::no_anchor; ++k) {
    const index_t j = first + a->nodes[k];
    const real w = depth_[p] * a->weights[k];
    for (int d = 0; d < 3; ++d) c[d] -= w * (f[3 * j + d] - f[3 * i + d]);
  }
  return c;
}

void SurfaceCentres::fill_positions(const Model& model, const State& state, std::vector<real>& x) const {
  if (!any_) {
    x = state.positions;
    return;
  }
  x.resize(state.positions.size());
  const std::int64_t n = model.node_count();
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    const vec3 c = at_centre(model, state.positions, static_cast<index_t>(i));
    for (int k = 0; k < 3; ++k) x[3 * i + k] = c[k];
  }
}

}  // namespace granulate
