// Basic types shared by the whole core.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace granulate {

/// One precision for every floating-point quantity of the core.
using real = double;
/// Node, bond and particle indices (32 bit: 4 billion bonds is far beyond one machine).
using index_t = std::uint32_t;

/// Bad input: names the offending value and the fix. Python sees it as granulate.InputError.
class InputError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// The time integration became unstable (non-finite values or runaway motion).
class InstabilityError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Plane assumption of a two-dimensional model; ignored in 3D. `peridem` reproduces PeriDEM's 2D
/// LPS for comparisons: the 3D coefficients (theta = 3/m sum J r e V, kappa_d = K, a_d = 15) and
/// the 3D critical stretch s0 = sqrt(Gc / ((3G + (3/4)^4 (K - 5G/3)) delta)), which do not give
/// the requested 2D moduli or fracture energy (tests/validation prove the strain/stress forms).
enum class PlaneMode : std::uint8_t { strain, stress, peridem };

}  // namespace granulate
