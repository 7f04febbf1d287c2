// Influence functions J(r / horizon) of peridynamic bonds.
#pragma once

#include <cmath>

#include "granulate/types.hpp"

namespace granulate {

/// Shape of the influence function J(xi), xi = r / horizon in [0, 1].
///   constant:  J = 1
///   linear:    J = 1 - xi                         (PeriDEM's type 1)
///   gaussian:  J = exp(-xi^2 / 0.16)              (width 0.4 horizon)
///   inverse:   J = 1 / xi                         (Madenci & Oterkus' omega = delta / r)
enum class InfluenceKind : std::uint8_t { constant, linear, gaussian, inverse };

/// J(xi) for xi = r / horizon; dimensionless.
inline real influence(InfluenceKind kind, real xi) {
  switch (kind) {
    case InfluenceKind::constant: return 1.0;
    case InfluenceKind::linear: return 1.0 - xi;
    case InfluenceKind::gaussian: return std::exp(-xi * xi / 0.16);
    case InfluenceKind::inverse: return 1.0 / xi;
  }
  return 1.0;
}

}  // namespace granulate
