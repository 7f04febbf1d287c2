// Loading: time functions, prescribed motion of node sets, force densities on node sets.
#pragma once

#include <array>
#include <vector>

#include "granulate/types.hpp"

namespace granulate {

/// A scalar function of time f(t) and its rate f'(t). With a, b its parameters:
///   constant:      f = a
///   linear:        f = a t
///   quadratic:     f = a t + b t^2
///   sine:          f = a sin(2 pi b t)               (b: frequency [Hz])
///   smooth_ramp:   f = a S(t / b), S(s) = 3s^2 - 2s^3 for s < 1, then 1   (b: ramp time [s])
///   velocity_ramp: f' = a S(t / b): the rate rises smoothly to a over b, then stays (b > 0)
struct TimeFunction {
  enum class Kind : std::uint8_t { constant, linear, quadratic, sine, smooth_ramp, velocity_ramp };
  Kind kind = Kind::constant;
  real a = 0;
  real b = 0;

  real value(real t) const;
  real rate(real t) const;
  /// Throws InputError when the parameters are meaningless (non-finite, non-positive ramp time).
  void validate() const;
};

/// Motion imposed on a node set, overriding the equations of motion of the selected components.
///   displacement: x_c = X_c + f(t) direction_c, v_c = f'(t) direction_c for c in components
///   rotation:     x = center + R(f(t)) (X - center), v = f'(t) axis x (x - center)
///                 (f is the angle [rad]; all components)
struct PrescribedMotion {
  enum class Kind : std::uint8_t { displacement, rotation };
  Kind kind = Kind::displacement;
  std::vector<index_t> nodes;
  std::uint8_t components = 0b111;  ///< bit k set: component k is prescribed
  std::array<real, 3> direction{0, 0, 0};
  std::array<real, 3> center{0, 0, 0};
  std::array<real, 3> axis{0, 0, 1};  ///< unit vector (normalised when added)
  TimeFunction function;
};

/// Force density b(t) = f(t) vector [N/m^3, also in 2D] added to every node of a set.
struct NodalForce {
  std::vector<index_t> nodes;
  std::array<real, 3> vector{0, 0, 0};
  TimeFunction function;
};

}  // namespace granulate
