// The bodies of ghost particles in a distributed run (granulate.parallel): a process holds
// another process's particle as a ghost for the contact of its own bodies with it, but only the
// ghost's nodes within reach of its own are kept current. A ghost body's rigid-body motion,
// which needs all its nodes, comes from the owner instead, named by the body's smallest node;
// so do the surface normals of its nodes near this process's (sums over their bonds, which
// read nodes farther away).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "granulate/contact/body_motion.hpp"

namespace granulate {

class GhostBodies {
 public:
  /// Per particle: 1 for a ghost; empty when there are none (a serial run).
  void set_particles(std::vector<std::uint8_t> ghost) {
    ghost_ = std::move(ghost);
    forget();
  }
  bool any() const { return !ghost_.empty(); }
  bool ghost(index_t particle) const { return !ghost_.empty() && ghost_[particle]; }
  /// The motions of ghost bodies for the next evaluation, each named by its smallest node
  /// (sorted here; each node once).
  void give(std::vector<std::pair<index_t, BodyMotion>> motions) { given_ = sorted(std::move(motions)); }
  /// The motion given for the body whose smallest node is `first`, or null.
  const BodyMotion* given(index_t first) const { return entry(given_, first); }
  /// The surface normals of ghost nodes for the next evaluation (sorted here; each node once).
  void give_normals(std::vector<std::pair<index_t, std::array<real, 3>>> normals) {
    normals_ = sorted(std::move(normals));
  }
  /// The surface normal given for node i, or null.
  const std::array<real, 3>* normal(index_t i) const { return entry(normals_, i); }
  /// Drops the motions and normals given (after the evaluation that used them: they hold for
  /// one state).
  void forget() {
    given_.clear();
    normals_.clear();
  }

 private:
  /// `entries` sorted by node.
  template <class T>
  static std::vector<std::pair<index_t, T>> sorted(std::vector<std::pair<index_t, T>> entries) {
    std::sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    return entries;
  }
  /// The value of `node` among sorted `entries`, or null.
  template <class T>
  static const T* entry(const std::vector<std::pair<index_t, T>>& entries, index_t node) {
    const auto it = std::lower_bound(entries.begin(), entries.end(), node,
                                     [](const auto& e, index_t key) { return e.first < key; });
    return it != entries.end() && it->first == node ? &it->second : nullptr;
  }
  std::vector<std::uint8_t> ghost_;
  std::vector<std::pair<index_t, BodyMotion>> given_;             // by smallest node
  std::vector<std::pair<index_t, std::array<real, 3>>> normals_;  // by node
};

}  // namespace granulate
