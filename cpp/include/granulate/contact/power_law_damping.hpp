// Damping ratios that give the requested restitution when the contact force is a power law of
// the approach.
//
// The body dashpot of ContactModel is 2 zeta sqrt(M K_s) dx/dt with K_s = F / x, the collision's
// secant stiffness. If the spring force grows as F = k x^p, the collision is scale-free: in
// units of the impact speed v and of the length (M v^2 / k)^(1 / (p + 1)) it reads
//     x'' = -max(0, x^p + 2 zeta x^((p - 1) / 2) x'),   x(0) = 0, x'(0) = 1,
// and the restitution e = -x'(t) when x is back to 0 depends on zeta and p only (Tsuji, Tanaka &
// Ishida 1992 give the same scale-freedom for Hertz's p = 3/2). The max keeps the force from
// pulling: as the bodies part, the dashpot would otherwise outgrow the spring and hold them
// together at the end of every collision (LIGGGHTS' limitForce clips the same way). Unclipped,
// p = 1 (linear springs) has zeta = -ln e / sqrt(pi^2 + ln^2 e), from which the tables below
// start; that zeta, clipped, gives e = 0.25, 0.55 and 0.90 for 0.1, 0.5 and 0.9, so the tables
// hold zeta fitted to the clipped collision for every p, 1 included. The node springs of a
// curved grain engage over a contact that widens with x, so a grain pressed on a plane or on
// another grain stiffens: p is about 3/2 in 2D and 2 in 3D, and the linear zeta gives e = 0.14
// and 0.18 for a requested 0.1 (unclipped).
#pragma once

#include <array>
#include <memory>

#include "granulate/types.hpp"

namespace granulate::contact {

/// Restitution of the scale-free collision above for damping ratio zeta and exponent p >= 1.
real power_law_restitution(real zeta, real exponent);

/// The damping ratio that gives restitution e (0 < e <= 1) for exponent p: the root of
/// power_law_restitution - e, to 1e-6 in zeta, searched in [low, high] if it lies there (else
/// in [0, 50]).
real power_law_damping_ratio(real restitution, real exponent, real low = 0, real high = 50);

/// zeta at one restitution for exponents 1, 1.1, ..., 3, interpolated linearly between them.
/// Each entry is a root search from the one before (power_law_damping_ratio), about a
/// millisecond; the entries are made when a collision first reaches their exponent, so a run
/// pays only for the exponents its contacts have (a 2D collision's p is about 1.5, a 3D one's
/// 2). Tables are shared by the laws of one restitution in a process, and filled under a lock
/// (at may be called from any thread): an entry's value does not depend on when it is made.
class DampingTable {
 public:
  static constexpr int size = 21;
  static constexpr real smallest_exponent = 1.0, exponent_step = 0.1;

  DampingTable() = default;
  /// The table of the restitution whose linear damping ratio is `linear_zeta` (zeta at p = 1).
  explicit DampingTable(real linear_zeta);
  /// zeta for exponent p, clamped to [1, 3] (0 for a table of no restitution).
  real at(real exponent) const;

 private:
  struct Entries;
  std::shared_ptr<Entries> entries_;
};

}  // namespace granulate::contact
