// The extension of a bond, shared by the bond loops (simulation_forces.cpp) and the
// diagnostics that read bond stretches (simulation.cpp).
#pragma once

#include <cmath>
#include <cstddef>

#include "granulate/types.hpp"

namespace granulate {

/// |x_j - x_i| - length [m] for positions x (nodes x 3); inline: it is the inner step of the
/// bond loops.
inline real bond_extension(index_t i, index_t j, real length, const real* x) {
  const real* const xi = x + 3 * std::size_t{i};
  const real* const xj = x + 3 * std::size_t{j};
  const real dx = xj[0] - xi[0], dy = xj[1] - xi[1], dz = xj[2] - xi[2];
  return std::sqrt(dx * dx + dy * dy + dz * dz) - length;
}

}  // namespace granulate
