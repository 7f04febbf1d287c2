// The surface of a particle as contact sees it: the nodes on or just below the surface (an
// imported mesh's or a grid's boundary vertices; a lattice's or conforming discretisation's
// outermost layer), each with a point on the surface, the outward normal there and the
// surface's curvature.
//
// A node a carries its surface offset o_a (n . o_a = 1 for the outward normal n of every
// boundary face at a mesh vertex; the unit normal of the shape's surface for a node below it)
// and its depth d_a below the surface (0 for a mesh vertex). To follow the particle as it
// moves, turns and deforms, (h/2) o_a is written as a combination of d bond vectors to nearby
// nodes of the same particle (its anchors, d = the dimension):
//   A_a = (h/2) o_a = sum_k w_k (X_k - X_a)   in the shape's frame, so at any time
//   A_a(t) = sum_k w_k (y_k - y_a),
// exact for any affine motion of the neighbourhood (translation, rotation, scale, strain) and
// shared by every particle placed from the shape (the weights do not change under rotation and
// scale). The anchors are the nearby pair (triple in 3D) whose bond directions span the plane
// (space) best. From A_a: the normal n_a = A_a / |A_a|, the surface point s_a = y_a + d_a n_a,
// and the centre of the node's contact sphere of radius rho, rho |o_a| below s_a (see
// contact/surface_centres.hpp).
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
  float depth = 0;      ///< d_a / h: the surface point is y_a + d_a n_a (0: on the surface)
  float reach = 1;      ///< |o_a|: the centre lies reach x rho from the surface point
  float curvature = 0;  ///< mean curvature of the surface at s_a times h (> 0 convex, 0 flat)
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
/// depths n [m] (empty: every node on the surface), mesh size h; a node whose neighbours within
/// 1.75 h do not span the plane (space) gets none, and contact centres it on itself. The
/// curvature of each anchored node is estimated from its anchored neighbours within 2 h whose
/// normals are within 30 degrees of its own (see surface_curvature).
SurfaceAnchors build_surface_anchors(std::span<const real> positions, std::span<const real> offsets,
                                     std::span<const real> depths, real mesh_size, int dimension);

/// The anchors of node a for the anchored vector `target` = sum_k w_k (x_k - x_a) [m], from
/// `candidates` (nodes of x, n x 3, nearest first): the pair (triple in 3D) whose bond directions
/// span best, as build_surface_anchors chooses them, and the weights that give `target`; the
/// anchors' indices are stored less `first`. Only the nodes and weights of `anchor` are set;
/// false (anchor unchanged) if no candidates span the plane (space).
bool span_anchors(std::span<const real> x, index_t a, std::span<const index_t> candidates,
                  const std::array<real, 3>& target, int dimension, index_t first, SurfaceAnchor& anchor);

/// Mean curvature kappa at surface point a from nearby surface points b with unit normals:
///   kappa = sum_b w_ab (n_b - n_a) . (s_b - s_a) / sum_b w_ab |s_b - s_a|^2,
/// w_ab = W(|s_b - s_a| / radius) (Wendland C2), over the b with n_a . n_b > cos 30 degrees (an
/// edge or corner of a polyhedron is not averaged into its faces). Exact (1/R) for points on a
/// sphere or circle of radius R with radial normals, 0 on a plane; the mean of the normal
/// curvatures over the neighbours' directions elsewhere. 0 without such neighbours.
real surface_curvature(std::span<const real> points, std::span<const real> normals, index_t a,
                       std::span<const index_t> neighbours, real radius);

}  // namespace granulate
