#include "granulate/contact/surface_centres.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

#include "granulate/in_parallel.hpp"

namespace granulate {

void SurfaceCentres::find(const Model& model, const State& state, std::vector<real> depth,
                          const std::vector<std::uint8_t>& outer_layers) {
  found_ = true;
  depth_ = std::move(depth);
  surface_ = outer_layers;
  any_ = std::any_of(depth_.begin(), depth_.end(), [](real s) { return s > 0; });
  std::vector<std::uint8_t> round_shape(model.shapes().size());
  for (std::size_t s = 0; s < round_shape.size(); ++s) round_shape[s] = is_round(model.shapes()[s]);
  any_linear_ = false;
  for (std::size_t p = 0; p < depth_.size(); ++p)
    any_linear_ = any_linear_ || (depth_[p] > 0 && !surface_[p]);
  round_.assign(surface_.size(), 0);
  for (index_t p = 0; p < round_.size(); ++p)
    round_[p] = surface_[p] && depth_[p] > 0 && round_shape[model.particles()[p].shape];
  // Which nodes are seen at anchors (1 byte each: most nodes have none, and contact asks for
  // every node every step); under the surface law, which looks them up many times per step,
  // each anchored node's place in its shape's anchors as well (4 bytes, where a pointer is 8).
  anchored_.assign(any_ ? model.node_count() : 0, 0);
  const bool cached = any_ && std::any_of(surface_.begin(), surface_.end(), [](std::uint8_t f) { return f; });
  anchor_slot_.assign(cached ? model.node_count() : 0, SurfaceAnchors::none);
  for (index_t i = 0; i < anchored_.size(); ++i) {
    const SurfaceAnchor* a = lookup(model, i);
    anchored_[i] = a != nullptr;
    if (cached && a != nullptr) {
      const Particle& particle = model.particles()[model.node_particle()[i]];
      anchor_slot_[i] = static_cast<index_t>(a - model.shapes()[particle.shape].anchors.anchors.data());
    }
  }
  spare_.clear();
  if (!any_ || state.bonds.broken(model.bond_offsets(), 0, model.node_count()) == 0) return;
  for (index_t i = 0; i < model.node_count(); ++i) {
    const SurfaceAnchor* a = anchor(model, i);
    if (a != nullptr && anchor_bond_broken(model, state, i, *a)) reanchor(model, state, i);
  }
}

bool SurfaceCentres::anchor_bond_broken(const Model& model, const State& state, index_t i,
                                        const SurfaceAnchor& a) {
  const index_t first = model.particles()[model.node_particle()[i]].first_node;
  const NodeBonds bonds = model.node_bonds(i);
  for (const index_t k : a.nodes) {
    const index_t b = k == SurfaceAnchor::no_anchor ? bonds.count : bonds.find(first + k);
    if (b != bonds.count && !state.bonds.intact(i, b)) return true;
  }
  return false;
}

std::vector<index_t> SurfaceCentres::bonded_within_reach(const Model& model, const State& state, index_t i) {
  const std::vector<real>& x = model.reference_positions();
  const real radius = anchor_reach * model.particles()[model.node_particle()[i]].mesh_size;
  const NodeBonds bonds = model.node_bonds(i);
  std::vector<std::pair<real, index_t>> near;
  for (index_t b = 0; b < bonds.count; ++b) {
    if (!state.bonds.intact(i, b)) continue;
    const index_t j = bonds.neighbor(b);
    real r2 = 0;
    for (int c = 0; c < 3; ++c) r2 += (x[3 * j + c] - x[3 * i + c]) * (x[3 * j + c] - x[3 * i + c]);
    if (r2 <= radius * radius) near.push_back({r2, j});
  }
  std::sort(near.begin(), near.end());
  std::vector<index_t> nodes;
  for (const auto& entry : near) nodes.push_back(entry.second);
  return nodes;
}

void SurfaceCentres::anchors_of(const Model& model, index_t i, std::vector<index_t>& out) const {
  const SurfaceAnchor* a = anchor(model, i);
  if (a == nullptr) return;
  const index_t first = model.particles()[model.node_particle()[i]].first_node;
  for (const index_t k : a->nodes) {
    if (k != SurfaceAnchor::no_anchor) out.push_back(first + k);
  }
}

bool SurfaceCentres::reanchor(const Model& model, const State& state, index_t i) {
  // The same anchored vector in the reference, A_0 = sum_k w_k (X_k - X_i) of the shape's
  // anchors, from all the intact bonds within 1.75 h, nearest first (ties by index). A function
  // of the bond states only, so a restore finds the same anchors: bonds only break, and the
  // first best span of a set is the first best of any subset that holds it, so anchors taken
  // earlier are those this would take now while their bonds hold.
  const index_t p = model.node_particle()[i];
  const SurfaceAnchor* primary = lookup(model, i);
  if (anchor_slot_.empty() || !surface_[p] || primary == nullptr) {  // outside the surface law
    detach(i);
    return false;
  }
  const Particle& particle = model.particles()[p];
  const std::vector<real>& x = model.reference_positions();
  Seen reference;
  reference.anchor = primary;
  reference.first = particle.first_node;
  const vec3 target = anchored_vector(reference, x, i);
  const std::vector<index_t> candidates = bonded_within_reach(model, state, i);
  SurfaceAnchor anchor = *primary;
  if (!span_anchors(x, i, candidates, target, model.dimension(), particle.first_node, anchor)) {
    detach(i);
    return false;
  }
  if (anchor_slot_[i] & spare_bit) {  // taken again: its earlier spare anchors are no one's
    spare_[anchor_slot_[i] & ~spare_bit] = anchor;
  } else {
    anchor_slot_[i] = spare_bit | static_cast<index_t>(spare_.size());
    spare_.push_back(anchor);
  }
  return true;
}

bool SurfaceCentres::is_round(const Shape& shape) {
  const auto& anchors = shape.anchors.anchors;
  return !anchors.empty() && std::all_of(anchors.begin(), anchors.end(), [](const SurfaceAnchor& a) {
    return a.curvature * round_radius_min <= 1 && a.curvature * round_radius_max >= 1;
  });
}

void SurfaceCentres::detach(index_t i) {
  anchored_[i] = 0;
  if (!anchor_slot_.empty()) anchor_slot_[i] = SurfaceAnchors::none;
}

const SurfaceAnchor* SurfaceCentres::lookup(const Model& model, index_t i) const {
  const index_t p = model.node_particle()[i];
  if (!(depth_[p] > 0)) return nullptr;
  const SurfaceAnchor* a = model.surface_anchor(i);
  return a != nullptr && (a->depth == 0 || surface_[p]) ? a : nullptr;
}

std::vector<index_t> SurfaceCentres::detach_anchored(const Model& model, const State& state,
                                                     std::span<const std::array<index_t, 2>> pairs) {
  // The new anchors depend on the bond states alone, so the order of `pairs` (the threads')
  // changes nothing but the places in spare_.
  std::vector<index_t> detached;
  if (!found_ || !any_) return detached;
  for (const auto& [i, j] : pairs) {
    for (const auto& [node, other] : {std::array<index_t, 2>{i, j}, std::array<index_t, 2>{j, i}}) {
      const SurfaceAnchor* a = anchor(model, node);
      if (a == nullptr) continue;
      const index_t local = other - model.particles()[model.node_particle()[node]].first_node;
      if (std::find(a->nodes.begin(), a->nodes.end(), local) != a->nodes.end() &&
          !reanchor(model, state, node))
        detached.push_back(node);
    }
  }
  return detached;
}

template <class T>
void SurfaceCentres::fill_positions(const Model& model, const State& state, std::vector<T>& x) const {
  x.resize(state.positions.size());
  const std::int64_t n = model.node_count();
  in_parallel([&] {
#pragma omp for schedule(static)
    for (std::int64_t i = 0; i < n; ++i) {
      const vec3 c = at_list(model, state, static_cast<index_t>(i));
      for (int k = 0; k < 3; ++k) x[3 * i + k] = static_cast<T>(c[k]);
    }
  });
}

template void SurfaceCentres::fill_positions(const Model&, const State&, std::vector<float>&) const;
template void SurfaceCentres::fill_positions(const Model&, const State&, std::vector<double>&) const;

}  // namespace granulate
