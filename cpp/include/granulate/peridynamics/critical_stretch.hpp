// Bond-breaking criterion, separate from the force law: a bond breaks for good when its stretch
// exceeds s0 (tension only, PeriDEM's default), or when |s| exceeds s0 (breaking in compression).
#pragma once

#include <cmath>

#include "granulate/types.hpp"

namespace granulate {

struct CriticalStretch {
  real limit;                 ///< s0 (infinity: the material never breaks)
  bool break_in_compression;  ///< also break when s < -s0

  bool breaks(real stretch) const {
    return break_in_compression ? std::abs(stretch) > limit : stretch > limit;
  }
};

}  // namespace granulate
