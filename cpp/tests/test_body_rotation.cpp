// A body's rotation (contact/body_rotation.hpp): the rotational part of its moment B.
#include <array>
#include <cmath>
#include <random>

#include "check.hpp"
#include "granulate/contact/body_rotation.hpp"

using namespace granulate;
using contact::matrix3;

namespace {

matrix3 product(const matrix3& a, const matrix3& b) {
  matrix3 c{};
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k)
      for (int s = 0; s < 3; ++s) c[3 * r + s] += a[3 * r + k] * b[3 * k + s];
  return c;
}

/// The rotation by `angle` about the unit `axis` (Rodrigues).
matrix3 rotation(const std::array<real, 3>& axis, real angle) {
  const real c = std::cos(angle), s = std::sin(angle), t = 1 - c;
  const real x = axis[0], y = axis[1], z = axis[2];
  return {t * x * x + c,     t * x * y - s * z, t * x * z + s * y, t * x * y + s * z, t * y * y + c,
          t * y * z - s * x, t * x * z - s * y, t * y * z + s * x, t * z * z + c};
}

/// B = R S for a random symmetric positive S (a body's second moment).
matrix3 moment_of(const matrix3& turn, std::mt19937& rng) {
  std::uniform_real_distribution<real> u(-1, 1);
  matrix3 a;
  for (real& v : a) v = u(rng);
  matrix3 s = product(a, {a[0], a[3], a[6], a[1], a[4], a[7], a[2], a[5], a[8]});  // a a^T
  for (int k = 0; k < 3; ++k) s[4 * k] += 0.1;
  return product(turn, s);
}

}  // namespace

TEST_CASE("a body's rotation is the rotational part of its moment, in 3D") {
  // R of B = R S for random R and S, to 1e-12; none for a singular or reflecting B.
  std::mt19937 rng(7);
  std::normal_distribution<real> normal(0, 1);
  for (int trial = 0; trial < 50; ++trial) {
    std::array<real, 3> axis{normal(rng), normal(rng), normal(rng)};
    const real size = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    for (real& v : axis) v /= size;
    const matrix3 turn = rotation(axis, 3 * normal(rng));
    const auto found = contact::best_rotation(moment_of(turn, rng), 3);
    CHECK(found.has_value());
    if (!found) continue;
    for (int k = 0; k < 9; ++k) CHECK_NEAR((*found)[k], turn[k], 0, 1e-12);
  }
  CHECK(!contact::best_rotation(matrix3{1, 0, 0, 0, 1, 0, 0, 0, 0}, 3));   // a sheet of nodes
  CHECK(!contact::best_rotation(matrix3{1, 0, 0, 0, 1, 0, 0, 0, -1}, 3));  // a mirror image
  CHECK(!contact::best_rotation(matrix3{}, 3));                            // one node
}

TEST_CASE("a body's rotation in 2D is the angle of its moment") {
  // B = R(theta) S in the plane: R(theta) for any theta, S's eigenvalues far apart or not.
  for (const real theta : {0.0, 0.3, -1.2, 3.0}) {
    const matrix3 turn = rotation({0, 0, 1}, theta);
    const matrix3 s{2.0, 0.5, 0, 0.5, 0.3, 0, 0, 0, 0};
    const auto found = contact::best_rotation(product(turn, s), 2);
    CHECK(found.has_value());
    if (!found) continue;
    for (int k = 0; k < 9; ++k) CHECK_NEAR((*found)[k], turn[k], 0, 1e-14);
  }
  CHECK(!contact::best_rotation(matrix3{}, 2));
}
