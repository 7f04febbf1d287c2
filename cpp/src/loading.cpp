#include "granulate/loading.hpp"

#include <cmath>
#include <numbers>

namespace granulate {
namespace {

real smoothstep(real s) {
  return s >= 1 ? 1.0 : (s <= 0 ? 0.0 : s * s * (3.0 - 2.0 * s));
}

/// int_0^s smoothstep = s^3 - s^4/2 for s < 1, then 1/2 + (s - 1).
real smoothstep_integral(real s) {
  if (s <= 0) return 0;
  if (s >= 1) return 0.5 + (s - 1.0);
  return s * s * s - 0.5 * s * s * s * s;
}

}  // namespace

real TimeFunction::value(real t) const {
  switch (kind) {
    case Kind::constant: return a;
    case Kind::linear: return a * t;
    case Kind::quadratic: return a * t + b * t * t;
    case Kind::sine: return a * std::sin(2.0 * std::numbers::pi * b * t);
    case Kind::smooth_ramp: return a * smoothstep(t / b);
    case Kind::velocity_ramp: return a * b * smoothstep_integral(t / b);
  }
  return 0;
}

real TimeFunction::rate(real t) const {
  switch (kind) {
    case Kind::constant: return 0;
    case Kind::linear: return a;
    case Kind::quadratic: return a + 2.0 * b * t;
    case Kind::sine: return a * 2.0 * std::numbers::pi * b * std::cos(2.0 * std::numbers::pi * b * t);
    case Kind::smooth_ramp: {
      const real s = t / b;
      return (s <= 0 || s >= 1) ? 0.0 : a * 6.0 * s * (1.0 - s) / b;
    }
    case Kind::velocity_ramp: return a * smoothstep(t / b);
  }
  return 0;
}

void TimeFunction::validate() const {
  if (!std::isfinite(a) || !std::isfinite(b)) {
    throw InputError("time function parameters must be finite numbers");
  }
  if ((kind == Kind::smooth_ramp || kind == Kind::velocity_ramp) && !(b > 0)) {
    throw InputError("the ramp time of a smooth ramp must be positive");
  }
}

}  // namespace granulate
