// A large body's rigid motion and rotation measured order-free, so that a distributed run may
// cut it among processes and still measure it as one process does (docs/parallel.md).
//
// The nodes are summed block by block (the body's nodes within one block of kRunBlock node
// indices, summed in node order), and the blocks' sums are added exactly (ExactAccumulator):
// a process holding whole blocks makes the same block sums, and processes' exact sums add up
// to the whole body's, which round to the same bits. Two passes, so that nothing
// cancels: the centres (current c and reference C) from moments about the reference position o
// of the body's smallest node, which every process knows; then the moments about c and C.
// A body within one block (one node, say) is measured in one pass about its first node
// (measure_body), as every small body is: one process holds it whole.
#pragma once

#include <array>

#include "granulate/contact/body_motion.hpp"
#include "granulate/contact/body_rotation.hpp"
#include "granulate/exact_accumulator.hpp"

namespace granulate {

/// A particle of at least this many nodes may be cut among processes (splittable): its bodies
/// (itself and its fragments) are measured order-free when they span more than one block, and
/// the contact's sums over their nodes are block sums (block_sums.hpp). Those of smaller
/// particles are summed in node order.
inline constexpr index_t splittable_particle_nodes = 4096;

/// Whether particle p is splittable.
bool splittable(const Model& model, index_t p);
/// Whether the body of `count` nodes (in node order) is measured order-free: a splittable
/// particle's, in more than one block.
bool measured_order_free(const Model& model, const index_t* nodes, index_t count);
/// The mass of a body of `count` nodes (in node order), sum rho V, order-free.
real order_free_mass(const Model& model, const index_t* nodes, index_t count);

/// Pass 1, per node of mass m, position y and reference position X about o: m; m (y - o) (3);
/// m (X - o) (3).
using CentreSums = ExactSums<7>;
/// Pass 2 for the motion, about c: m; m r (3); m v (3); r x m v (3); m r r^T as xx, yy, zz, xy,
/// xz, yz (6); r = y - c.
using MotionSums = ExactSums<16>;
/// Pass 2 for the rotation (body_rotation.hpp), a = y - c, b = X - C: m; m a (3); m b (3);
/// m a b^T (9, row-major).
using MomentSums = ExactSums<16>;

/// A body's current and reference centres of mass [m].
struct BodyCentres {
  vec3 current{0, 0, 0}, reference{0, 0, 0};
};

/// The reference position of the body's smallest node: the origin of its first pass.
vec3 body_origin(const Model& model, index_t first_node);

/// Pass 1 over `count` nodes (in node order) of one body: all of them, or a process's whole
/// blocks of them.
CentreSums centre_sums(const Model& model, const State& state, const index_t* nodes, index_t count,
                       const vec3& origin);
BodyCentres centres_from(const CentreSums& sums, const vec3& origin);

/// Pass 2 for the motion, and the motion from its sums (as measure_body makes it from its own).
MotionSums motion_sums(const Model& model, const State& state, const index_t* nodes, index_t count,
                       const vec3& centre);
BodyMotion motion_from(const MotionSums& sums, const vec3& centre, int dimension);

/// Pass 2 for the rotation, and B = sum m a b^T - d D^T / M (d = sum m a, D = sum m b), the
/// moment best_rotation takes.
MomentSums moment_sums(const Model& model, const State& state, const index_t* nodes, index_t count,
                       const BodyCentres& centres);
contact::matrix3 moment_from(const MomentSums& sums);

/// Both passes over every node of a body, in one process.
BodyMotion measure_order_free(const Model& model, const State& state, const index_t* nodes, index_t count,
                              int dimension);
contact::matrix3 moment_order_free(const Model& model, const State& state, const index_t* nodes,
                                   index_t count);

}  // namespace granulate
