// Contact centres of nodes that lie on their particle's surface (the vertices on an imported
// mesh's or a grid's boundary).
//
// A lattice's or conforming discretisation's outer nodes lie h/2 inside the surface, so a contact
// sphere of radius about h/2 centred on each node reaches the surface. A boundary vertex lies on
// the surface itself; its sphere is centred inside, h/2 below every boundary face at the vertex
// (contact scales that to the node's contact radius, so the sphere just reaches the faces):
// c = y - (h/2) o in the shape's frame, o the surface offset (n . o = 1 for each face normal n
// at the node; see granulate.meshes.boundary_offsets).
// To follow the particle as it moves, turns and deforms, (h/2) o is written as a combination of
// d bond vectors to nearby nodes of the same particle (its anchors, d = the dimension):
//   (h/2) o = sum_k w_k (X_k - X_a)   in the shape's frame, so at any time
//   c = y_a - sum_k w_k (y_k - y_a),
// exact for any affine motion of the neighbourhood (translation, rotation, scale, strain) and
// shared by every particle placed from the shape (the weights do not change under rotation and
// scale). The anchors are the nearby pair (triple in 3D) whose bond directions span the plane
// (space) best.
#pragma once

#include <array>
#include <span>
#include <vector>

#include "granulate/types.hpp"

namespace granulate {

/// The anchors of one surface node: shape-local node indices and weights (see above); unused
/// slots (index no_anchor) in 2D.
struct SurfaceAnchor {
  static constexpr index_t no_anchor = ~index_t{0};
  std::array<index_t, 3> nodes{no_anchor, no_anchor, no_anchor};
  std::array<float, 3> weights{0, 0, 0};
};

/// The anchors of a shape's surface nodes.
struct SurfaceAnchors {
  static constexpr index_t none = ~index_t{0};
  std::vector<index_t> slot;           ///< per shape node: its anchor, or none (empty: no node)
  std::vector<SurfaceAnchor> anchors;  ///< per surface node
  const SurfaceAnchor* of(index_t node) const {
    return slot.empty() || slot[node] == none ? nullptr : &anchors[slot[node]];
  }
  std::size_t memory_bytes() const {
    return slot.capacity() * sizeof(index_t) + anchors.capacity() * sizeof(SurfaceAnchor);
  }
};

/// Anchors for the nodes with a non-zero offset: positions and offsets n x 3 (shape frame),
/// mesh size h; a node whose neighbours within 1.75 h do not span the plane (space) gets none,
/// and contact centres it on itself. InputError if the offsets are not finite.
SurfaceAnchors build_surface_anchors(std::span<const real> positions, std::span<const real> offsets,
                                     real mesh_size, int dimension);

}  // namespace granulate
