// Built with -ffp-contract=off (CMakeLists.txt): each product is rounded before it is added, as
// in the NumPy formulas this replaced, so a sum does not depend on the compiler's fusing.
#include "granulate/particle_sums.hpp"

#include <array>

namespace granulate {

ParticleSums particle_sums(std::span<const std::uint32_t> owner, std::span<const real> mass,
                           std::span<const real> positions, std::span<const real> velocities,
                           std::size_t count) {
  ParticleSums s{std::vector<real>(count, 0.0),     std::vector<real>(3 * count, 0.0),
                 std::vector<real>(3 * count, 0.0), std::vector<real>(3 * count, 0.0),
                 std::vector<real>(6 * count, 0.0), std::vector<real>(count, 0.0)};
  for (std::size_t i = 0; i < owner.size(); ++i) {
    const std::size_t p = owner[i];
    s.mass[p] += mass[i];
    for (int k = 0; k < 3; ++k) {
      s.centre[3 * p + k] += mass[i] * positions[3 * i + k];
      s.velocity[3 * p + k] += mass[i] * velocities[3 * i + k];
    }
  }
  for (std::size_t p = 0; p < count; ++p) {
    for (int k = 0; k < 3; ++k) {
      s.centre[3 * p + k] /= s.mass[p];
      s.velocity[3 * p + k] /= s.mass[p];
    }
  }
  for (std::size_t i = 0; i < owner.size(); ++i) {
    const std::size_t p = owner[i];
    const real m = mass[i];
    std::array<real, 3> a{}, u{};
    for (int k = 0; k < 3; ++k) {
      a[k] = positions[3 * i + k] - s.centre[3 * p + k];
      u[k] = velocities[3 * i + k] - s.velocity[3 * p + k];
    }
    const std::array<real, 3> moment{a[1] * u[2] - a[2] * u[1], a[2] * u[0] - a[0] * u[2],
                                     a[0] * u[1] - a[1] * u[0]};
    for (int k = 0; k < 3; ++k) s.momentum[3 * p + k] += m * moment[k];
    const real r2 = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
    real* const inertia = &s.inertia[6 * p];
    inertia[0] += m * (r2 - a[0] * a[0]);
    inertia[1] += m * (r2 - a[1] * a[1]);
    inertia[2] += m * (r2 - a[2] * a[2]);
    inertia[3] += m * (0.0 - a[0] * a[1]);
    inertia[4] += m * (0.0 - a[0] * a[2]);
    inertia[5] += m * (0.0 - a[1] * a[2]);
    s.spread[p] += m * r2;
  }
  return s;
}

}  // namespace granulate
