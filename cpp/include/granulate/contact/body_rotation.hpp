// The rotation of a deformable body: the rotation R that best carries its reference shape onto
// its current one, in the least-squares sense (Kabsch 1976; Higham 1986 for the iteration).
//
// With c and C the current and reference centres of mass, the moment
//   B = sum_i m_i (y_i - c) (X_i - C)^T
// has the polar decomposition B = R S (S symmetric positive definite), and R minimises
// sum_i m_i |(y_i - c) - R (X_i - C)|^2. R is a function of the positions alone, so anything
// built on it (a round particle's osculating spheres, contact/surface_centres.hpp) has a
// potential, and its derivative is a rigid rotation of the body: a couple on it.
//
// In 2D (the x-y plane) R turns by theta = atan2(B_yx - B_xy, B_xx + B_yy). In 3D, Newton's
// iteration X <- (g X + X^-T / g) / 2, g = (|X^-1|_F / |X|_F)^(1/2), from X = B converges
// quadratically to R while det B > 0. A body whose B vanishes (one node) has no rotation, nor
// in 3D one whose B is singular or reflecting (two nodes, a sheet of nodes).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "granulate/types.hpp"

namespace granulate::contact {

using matrix3 = std::array<real, 9>;  // row-major

inline real determinant(const matrix3& a) {
  return a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
         a[2] * (a[3] * a[7] - a[4] * a[6]);
}

/// The inverse's transpose, a^-T = cofactor(a) / det a.
inline matrix3 inverse_transpose(const matrix3& a, real det) {
  return {(a[4] * a[8] - a[5] * a[7]) / det, (a[5] * a[6] - a[3] * a[8]) / det,
          (a[3] * a[7] - a[4] * a[6]) / det, (a[2] * a[7] - a[1] * a[8]) / det,
          (a[0] * a[8] - a[2] * a[6]) / det, (a[1] * a[6] - a[0] * a[7]) / det,
          (a[1] * a[5] - a[2] * a[4]) / det, (a[2] * a[3] - a[0] * a[5]) / det,
          (a[0] * a[4] - a[1] * a[3]) / det};
}

inline real frobenius(const matrix3& a) {
  real sum = 0;
  for (const real v : a) sum += v * v;
  return std::sqrt(sum);
}

/// R of B = R S (see above); none if B is singular or reflecting.
inline std::optional<matrix3> best_rotation(const matrix3& moment, int dimension) {
  if (dimension == 2) {
    const real s = moment[3] - moment[1], c = moment[0] + moment[4];
    const real size = std::hypot(s, c);
    if (!(size > 0)) return std::nullopt;
    return matrix3{c / size, -s / size, 0, s / size, c / size, 0, 0, 0, 1};
  }
  matrix3 x = moment;
  const real scale = frobenius(x);
  if (!(scale > 0)) return std::nullopt;
  for (real& v : x) v /= scale;
  for (int iteration = 0; iteration < 60; ++iteration) {
    const real det = determinant(x);
    if (!(det > 1e-12)) return std::nullopt;
    const matrix3 inverse = inverse_transpose(x, det);
    const real g = std::sqrt(frobenius(inverse) / frobenius(x));
    matrix3 next;
    real change = 0;
    for (int k = 0; k < 9; ++k) {
      next[k] = 0.5 * (g * x[k] + inverse[k] / g);
      change = std::max(change, std::abs(next[k] - x[k]));
    }
    x = next;
    if (change < 1e-15) break;  // converged (round-off may keep the last change near 1e-16)
  }
  return x;
}

/// R v.
inline std::array<real, 3> rotate(const matrix3& r, const std::array<real, 3>& v) {
  return {r[0] * v[0] + r[1] * v[1] + r[2] * v[2], r[3] * v[0] + r[4] * v[1] + r[5] * v[2],
          r[6] * v[0] + r[7] * v[1] + r[8] * v[2]};
}

}  // namespace granulate::contact
