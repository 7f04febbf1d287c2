// An exact sum of float64s in one fixed-point number, rounded once: the same bits whatever the
// order of its terms and however they were split among processes, and cheap enough to add a
// few numbers a block of nodes every step (a body's rigid motion, contact/body_sums.hpp).
//
// A finite float64 x is M 2^(p - 1074) with an integer M, |M| < 2^53, and 0 <= p <= 2045, so a
// sum of them is an integer N times 2^-1074. N is kept in base 2^32, each digit in an int64 so
// that adding a term touches three digits and carries nothing: 2^30 terms fit before the digits
// are carried (normalised). `rounded` gives N 2^-1074 to the nearest float, ties to even, as
// math.fsum does; exact zero is +0.0.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>

#include "granulate/types.hpp"

namespace granulate {

class ExactAccumulator {
 public:
  /// Digits of 32 bits from 2^-1074 up: 2144 bits, room for sums up to 2^1069 (rounded to inf).
  static constexpr int digit_count = 67;
  using Digits = std::array<std::int64_t, digit_count>;

  /// Adds x exactly; a non-finite x (inf, nan) makes the sum what float addition would make it.
  void add(real x) {
    if (!std::isfinite(x)) {
      special_ += x;
      return;
    }
    if (unnormalised_++ == carry_every) {
      normalise();
      unnormalised_ = 1;
    }
    const std::uint64_t bits = std::bit_cast<std::uint64_t>(x);
    const int exponent = static_cast<int>(bits >> 52 & 0x7ff);  // 0 for subnormals and zeros
    const std::uint64_t magnitude =
        (bits & ((std::uint64_t{1} << 52) - 1)) | (exponent ? std::uint64_t{1} << 52 : 0);
    if (magnitude == 0) return;
    const int position = exponent > 0 ? exponent - 1 : 0;  // x = magnitude 2^(position - 1074)
    const int k = position / 32, shift = position % 32;    // magnitude 2^shift: digits k .. k + 2
    const std::uint64_t low = magnitude << shift, high = shift ? magnitude >> (64 - shift) : 0;
    const std::int64_t parts[3] = {static_cast<std::int64_t>(low & 0xffffffff),
                                   static_cast<std::int64_t>(low >> 32), static_cast<std::int64_t>(high)};
    if (bits >> 63) {
      for (int d = 0; d < 3; ++d) digit_[k + d] -= parts[d];
    } else {
      for (int d = 0; d < 3; ++d) digit_[k + d] += parts[d];
    }
    low_ = std::min(low_, k);
    high_ = std::max(high_, k + 2);
  }
  /// Adds another accumulator's terms.
  void add(const ExactAccumulator& other);
  /// The sum rounded to the nearest float (ties to even); +0.0 for an exact zero.
  real rounded() const;
  /// Back to an empty sum (zero), touching only the digits in use.
  void clear();

  /// The sum as carried digits (each in [0, 2^32) but the highest, which holds the sign) and
  /// the non-finite part: what a process sends. Digits of several processes add digit by digit
  /// (an MPI_SUM of int64) into an exact sum of all their terms (from_digits).
  Digits digits() const;
  real special() const { return special_; }
  static ExactAccumulator from_digits(const Digits& digits, real special);

 private:
  void normalise();

  static constexpr std::uint32_t carry_every = std::uint32_t{1} << 30;  // terms between carries
  Digits digit_{};
  int low_ = digit_count, high_ = -1;  // the digits touched: [low_, high_]
  std::uint32_t unnormalised_ = 0;     // terms added since the digits were last carried
  real special_ = 0;                   // the sum of the non-finite terms (inf, -inf, nan; else 0)
};

/// `width` exact sums side by side.
template <int width>
struct ExactSums {
  std::array<ExactAccumulator, width> sum;
  void add(const ExactSums& other) {
    for (int k = 0; k < width; ++k) sum[k].add(other.sum[k]);
  }
  std::array<real, width> rounded() const {
    std::array<real, width> value;
    for (int k = 0; k < width; ++k) value[k] = sum[k].rounded();
    return value;
  }
  void clear() {
    for (auto& one : sum) one.clear();
  }
};

}  // namespace granulate
