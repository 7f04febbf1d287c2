// Where contact centres the spheres of nodes that lie on their particle's surface (the vertices
// on an imported mesh's or a grid's boundary; see surface_anchors.hpp).
//
// A lattice's outer nodes lie h/2 inside the surface; a boundary vertex lies on it. Its sphere is
// centred one contact radius rho below every face at the node, at the virtual node
//   c_i = y_i - s_p sum_k w_k (y_k - y_i),   s_p = rho / (h/2),
// over its anchors k (weights w_k for a depth of h/2, scaled to rho). c_i moves at the matching
// velocity, and a force F on it goes (1 + s W) F to the node and -s w_k F to anchor k (W = sum
// w_k): that is F at c_i in momentum, moment and work. A node whose bond to one of its anchors
// breaks is detached: its sphere is centred on itself from then on.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "granulate/model.hpp"
#include "granulate/state.hpp"
#include "granulate/surface_anchors.hpp"

namespace granulate {

class SurfaceCentres {
 public:
  using vec3 = std::array<real, 3>;

  /// Sets each particle's depth s_p (0: its nodes are not centred; one per particle) and the
  /// detached nodes from the bond states (at the first evaluation, and after a restore).
  void find(const Model& model, const State& state, std::vector<real> depth);
  bool found() const { return found_; }
  void forget() { found_ = false; }
  bool any() const { return any_; }

  /// Detaches the nodes whose bond to one of their anchors is among `pairs` (bonds that broke).
  void detach_anchored(const Model& model, std::span<const std::array<index_t, 2>> pairs);

  /// The anchors of node i if its sphere is centred, else null.
  const SurfaceAnchor* anchor(const Model& model, index_t i) const;
  /// s_p of node i's particle.
  real depth(const Model& model, index_t i) const { return depth_[model.node_particle()[i]]; }
  /// A nodal vector field (positions, velocities; n x 3) at node i's centre: f_i - s_p sum_k
  /// w_k (f_k - f_i), or f_i for a node that is not centred.
  vec3 at_centre(const Model& model, const std::vector<real>& field, index_t i) const;
  /// Every node's contact position, into x (n x 3).
  void fill_positions(const Model& model, const State& state, std::vector<real>& x) const;

  std::size_t memory_bytes() const {
    return depth_.capacity() * sizeof(real) + detached_.capacity() * sizeof(std::uint8_t);
  }

 private:
  void detach(const Model& model, index_t i);

  bool found_ = false;
  bool any_ = false;
  std::vector<real> depth_;             // per particle
  std::vector<std::uint8_t> detached_;  // per node, once a node is detached
};

}  // namespace granulate
