// The rigid-body motion of a body (a particle, or a fragment of one) that contact's dashpots,
// rolling resistance and turned forces act through.
#pragma once

#include <array>

#include "granulate/model.hpp"
#include "granulate/state.hpp"

namespace granulate {

using vec3 = std::array<real, 3>;

/// Rigid-body motion of a body in contact: centre of mass, mean velocity, angular velocity
/// omega = I^-1 L, and the inverse inertia tensor about the centre (symmetric: xx, yy, zz, xy,
/// xz, yz; zero for a body without rotational inertia, such as a one-node fragment).
struct BodyMotion {
  vec3 centre{0, 0, 0};
  vec3 velocity{0, 0, 0};
  vec3 angular_velocity{0, 0, 0};
  std::array<real, 6> inverse_inertia{0, 0, 0, 0, 0, 0};
};

/// The numbers of a BodyMotion in a flat array: centre, velocity, angular velocity (3 each),
/// inverse inertia (6).
inline constexpr int body_motion_size = 15;

/// Rigid-body motion of the body made of `count` nodes (in node order) at the state's positions
/// and velocities: one pass, moments about its first node, so far from the origin nothing
/// cancels; a body of a large particle order-free (body_sums.hpp). Centre c, velocity
/// V = sum m v / M, inertia I = sum m (|r|^2 1 - r r^T) and angular momentum
/// L = sum m r x (v - V) about c, omega = I^-1 L (m = rho V of each node).
BodyMotion measure_body(const Model& model, const State& state, const index_t* nodes, index_t count,
                        int dimension);

/// The motion from a body's sums about an origin o (r = y - o): mass M, first moment sum m r,
/// momentum sum m v, moment of momentum sum r x m v and second moments sum m r r^T (xx, yy,
/// zz, xy, xz, yz).
BodyMotion motion_about(const vec3& origin, real mass, const vec3& first, const vec3& momentum,
                        const vec3& spin, const std::array<real, 6>& second, int dimension);

}  // namespace granulate
