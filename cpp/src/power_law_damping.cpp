#include "granulate/contact/power_law_damping.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <mutex>
#include <numbers>

namespace granulate::contact {
namespace {

// x'' of the scale-free collision (zero outside contact), with x^p = (x^((p - 1) / 2))^2 x; the
// force, spring and dashpot, never pulls (see power_law_damping.hpp).
real acceleration(real x, real speed, real zeta, real exponent) {
  if (x <= 0) return 0;
  const real root = std::pow(x, 0.5 * (exponent - 1));
  return -std::max(0.0, root * root * x + 2 * zeta * root * speed);
}

// Restitution of the linear spring-dashpot with damping ratio zeta (the inverse of
// damping_ratio_from_restitution).
real linear_restitution(real zeta) {
  if (zeta <= 0) return 1;
  if (zeta >= 1) return 0;
  return std::exp(-std::numbers::pi * zeta / std::sqrt(1 - zeta * zeta));
}

}  // namespace

real power_law_restitution(real zeta, real exponent) {
  // Fourth-order Runge-Kutta, 500 steps per time unit (the undamped linear collision lasts pi);
  // the crossing of x = 0 is found by linear interpolation of the last step. A collision that
  // has not ended after 40 time units is overdamped: it creeps back to x = 0 at no speed.
  const real dt = 2e-3;
  real x = 0, v = 1;
  for (int step = 0; step < 20000; ++step) {
    const real a1 = acceleration(x, v, zeta, exponent);
    const real a2 = acceleration(x + 0.5 * dt * v, v + 0.5 * dt * a1, zeta, exponent);
    const real a3 = acceleration(x + 0.5 * dt * (v + 0.5 * dt * a1), v + 0.5 * dt * a2, zeta, exponent);
    const real a4 = acceleration(x + dt * (v + 0.5 * dt * a2), v + dt * a3, zeta, exponent);
    const real x_next = x + dt * v + dt * dt / 6 * (a1 + a2 + a3);
    const real v_next = v + dt / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
    if (x_next <= 0 && step > 0) {
      const real share = x / (x - x_next);
      return std::max(0.0, -(v + share * (v_next - v)));
    }
    x = x_next;
    v = v_next;
  }
  return 0;
}

real power_law_damping_ratio(real restitution, real exponent, real low, real high) {
  if (restitution >= 1) return 0;
  // f(zeta) = e(zeta) - e falls as zeta grows (f(0) = 1 - e). Regula falsi, Illinois variant
  // (the end that stays put twice in a row has its f halved), on a bracket [low, high]: the
  // given one if f changes sign on it, else [0, 50] (zeta = 4 still gives e = 0.014 at p = 1).
  auto f = [&](real zeta) {
    return zeta == 0 ? 1 - restitution : power_law_restitution(zeta, exponent) - restitution;
  };
  real f_low = f(low), f_high = f(high);
  if (!(f_low > 0 && f_high <= 0)) {
    low = 0, high = 50;
    f_low = f(low), f_high = f(high);
  }
  int kept = 0;  // +1: low moved last, -1: high moved last
  for (int k = 0; k < 200 && high - low > 1e-6; ++k) {
    const real zeta = (low * f_high - high * f_low) / (f_high - f_low);
    const real value = f(zeta);
    if (value > 0) {
      low = zeta, f_low = value;
      if (kept == 1) f_high *= 0.5;
      kept = 1;
    } else {
      high = zeta, f_high = value;
      if (kept == -1) f_low *= 0.5;
      kept = -1;
    }
  }
  return 0.5 * (low + high);
}

/// One restitution's entries: entry k is zeta at exponent 1 + 0.1 k; those below `made` are
/// final.
struct DampingTable::Entries {
  explicit Entries(real zeta_at_one)
      : linear_zeta(zeta_at_one), restitution(linear_restitution(zeta_at_one)) {}

  /// Entry k, made first (with every one before it) when it is not yet.
  real entry(int k) {
    if (k < made.load(std::memory_order_acquire)) return zeta[k];
    const std::lock_guard<std::mutex> lock(mutex);
    for (int next = made.load(std::memory_order_relaxed); next <= k; ++next) {
      zeta[next] = make(next);
      made.store(next + 1, std::memory_order_release);
    }
    return zeta[k];
  }

  /// Entry k from the one before: the force that cannot pull takes more damping than the
  /// linear formula's (from linear_zeta up), and zeta grows with p (bracketed from the
  /// previous exponent's).
  real make(int k) const {
    if (linear_zeta == 0) return 0;
    if (k == 0) return power_law_damping_ratio(restitution, 1.0, linear_zeta, 2 * linear_zeta + 1e-3);
    const real previous = zeta[k - 1];
    return power_law_damping_ratio(restitution, smallest_exponent + k * exponent_step, previous,
                                   1.5 * previous + 1e-3);
  }

  const real linear_zeta, restitution;
  std::array<real, size> zeta{};
  std::atomic<int> made{0};
  std::mutex mutex;
};

DampingTable::DampingTable(real linear_zeta) {
  // One table per restitution in the process, shared by every law of it.
  static std::mutex mutex;
  static std::map<real, std::shared_ptr<Entries>> made;
  const std::lock_guard<std::mutex> lock(mutex);
  auto& entries = made[linear_zeta];
  if (!entries) entries = std::make_shared<Entries>(linear_zeta);
  entries_ = entries;
}

real DampingTable::at(real exponent) const {
  if (!entries_) return 0;
  const real position = std::clamp((exponent - smallest_exponent) / exponent_step, 0.0, real(size - 1));
  const int k = std::min(static_cast<int>(position), size - 2);
  const real share = position - k;
  const real above = entries_->entry(k + 1);  // makes entry k too
  return (1 - share) * entries_->entry(k) + share * above;
}

}  // namespace granulate::contact
