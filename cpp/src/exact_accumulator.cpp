#include "granulate/exact_accumulator.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

namespace granulate {

namespace {

constexpr std::int64_t digit_base = std::int64_t{1} << 32;

/// Carries digits[low, high] so that each lies in [0, 2^32) but the highest, which may be
/// negative (it holds the sign); returns the new highest digit (carries may reach further up).
int carry(ExactAccumulator::Digits& digits, int low, int high) {
  constexpr int top = ExactAccumulator::digit_count - 1;
  std::int64_t carried = 0;
  int k = low;
  for (; k < top && (k <= high || (carried != 0 && carried != -1)); ++k) {
    const std::int64_t d = digits[k] + carried;
    carried = d >> 32;  // floor(d / 2^32): arithmetic shift
    digits[k] = d - carried * digit_base;
  }
  if (k == top) {
    digits[top] += carried;
    return top;
  }
  if (carried == -1) digits[k - 1] -= digit_base;  // a negative sum: its top digit below zero
  return k - 1;
}

/// The nearest float to N 2^-1074, N >= 0 in carried digits [0, high] (digits[high] > 0), ties
/// to even.
real round_magnitude(const ExactAccumulator::Digits& digits, int high) {
  auto digit = [&](int k) { return k >= 0 ? static_cast<std::uint64_t>(digits[k]) : 0; };
  const int zeros = std::countl_zero(static_cast<std::uint32_t>(digits[high]));
  const int top_bit = 32 * high + 31 - zeros;
  if (top_bit < 53) return std::ldexp(static_cast<real>(digit(1) << 32 | digit(0)), -1074);  // exact
  // The 64 bits from the top one down, from the top three digits; the rest sticky.
  const std::uint64_t third = digit(high - 2);
  const std::uint64_t bits =
      (digit(high) << 32 | digit(high - 1)) << zeros | (zeros ? third >> (32 - zeros) : 0);
  bool sticky = static_cast<std::uint32_t>(third << zeros) != 0;
  for (int k = high - 3; k >= 0 && !sticky; --k) sticky = digits[k] != 0;
  std::uint64_t mantissa = bits >> 11;  // 53 bits, the top one set
  const std::uint64_t rest = bits & 0x7ff;
  if (rest > 0x400 || (rest == 0x400 && (sticky || (mantissa & 1)))) ++mantissa;
  return std::ldexp(static_cast<real>(mantissa), top_bit - 52 - 1074);  // inf past the range
}

}  // namespace

void ExactAccumulator::add(const ExactAccumulator& other) {
  special_ += other.special_;
  if (other.high_ < other.low_) return;  // no finite term
  normalise();
  const Digits theirs = other.digits();
  const int low = std::min(low_, other.low_);
  int high = digit_count - 1;  // their carries may reach past their high_
  while (high > low && theirs[high] == 0 && high > high_) --high;
  for (int k = low; k <= high; ++k) digit_[k] += theirs[k];
  low_ = low;
  high_ = carry(digit_, low, high);
}

void ExactAccumulator::clear() {
  if (high_ >= low_) std::fill(digit_.begin() + low_, digit_.begin() + high_ + 1, 0);
  low_ = digit_count;
  high_ = -1;
  unnormalised_ = 0;
  special_ = 0;
}

void ExactAccumulator::normalise() {
  if (high_ >= low_) high_ = carry(digit_, low_, high_);
  unnormalised_ = 0;
}

ExactAccumulator::Digits ExactAccumulator::digits() const {
  Digits carried = digit_;
  if (high_ >= low_) carry(carried, low_, high_);
  return carried;
}

ExactAccumulator ExactAccumulator::from_digits(const Digits& digits, real special) {
  ExactAccumulator sum;
  sum.digit_ = digits;
  sum.special_ = special;
  for (int k = 0; k < digit_count; ++k) {
    if (digits[k] == 0) continue;
    sum.low_ = std::min(sum.low_, k);
    sum.high_ = k;
  }
  sum.normalise();
  return sum;
}

real ExactAccumulator::rounded() const {
  if (special_ != 0 || std::isnan(special_)) return special_;
  if (high_ < low_) return 0.0;
  Digits n = digit_;
  int high = carry(n, low_, high_);
  while (high >= low_ && n[high] == 0) --high;
  if (high < low_) return 0.0;
  const bool negative = n[high] < 0;
  if (negative) {  // the magnitude: -N, carried again
    for (int k = low_; k <= high; ++k) n[k] = -n[k];
    high = carry(n, low_, high);
    while (n[high] == 0) --high;
  }
  const real magnitude = round_magnitude(n, high);
  return negative ? -magnitude : magnitude;
}

}  // namespace granulate
