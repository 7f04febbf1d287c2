// Exact sums (exact_accumulator.hpp).
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "check.hpp"
#include "granulate/exact_accumulator.hpp"

using namespace granulate;

namespace {

__extension__ typedef __int128 int128;  // the reference sums' integers

real exact_sum(const std::vector<real>& terms) {
  ExactAccumulator sum;
  for (const real x : terms) sum.add(x);
  return sum.rounded();
}

bool same_bits(real a, real b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

}  // namespace

TEST_CASE("exact sums: cancellation, ties to even, subnormals, overflow, non-finite terms") {
  const real big = std::numeric_limits<real>::max(), tiny = std::numeric_limits<real>::denorm_min();
  const real inf = std::numeric_limits<real>::infinity();
  CHECK(exact_sum({1e300, 1.0, -1e300}) == 1.0);
  CHECK(exact_sum({1.0, 1e-300, -1.0}) == 1e-300);
  CHECK(exact_sum({0.1, 0.2, -0.3}) == 0x1p-55);                                          // math.fsum's
  CHECK(exact_sum({1.0, std::ldexp(1.0, -53)}) == 1.0);                                   // tie: to even
  CHECK(exact_sum({1.0, std::ldexp(1.0, -53), std::ldexp(1.0, -120)}) == 1.0 + 0x1p-52);  // past it: up
  CHECK(exact_sum({1.0 + 0x1p-52, std::ldexp(1.0, -53)}) == 1.0 + 0x1p-51);               // tie: odd, up
  CHECK(exact_sum({-1.0 - 0x1p-52, -std::ldexp(1.0, -53)}) == -1.0 - 0x1p-51);            // the same below 0
  CHECK(exact_sum({-1.0, -std::ldexp(1.0, -53), std::ldexp(1.0, -120)}) == -1.0);         // short of the tie
  CHECK(exact_sum({tiny, tiny, tiny}) == 3 * tiny);
  CHECK(exact_sum({0x1p-1022, -tiny}) == 0x1p-1022 - tiny);
  CHECK(exact_sum({big, big, -big}) == big);
  CHECK(exact_sum({big, big}) == inf);
  CHECK(exact_sum({-big, -big}) == -inf);
  CHECK(exact_sum({inf, 1.0, -3.0}) == inf);
  CHECK(std::isnan(exact_sum({inf, -inf, 1.0})));
  CHECK(same_bits(exact_sum({-0.0}), 0.0));
  CHECK(same_bits(exact_sum({1.5, -1.5}), 0.0));
  CHECK(same_bits(exact_sum({}), 0.0));
  CHECK(exact_sum({3.25}) == 3.25);
}

TEST_CASE("exact sums of random terms equal an integer reference, and split anyhow they add up") {
  // Terms of 40-bit mantissas times 2^-60 .. 2^20: exact in a 128-bit integer of 2^-100, whose
  // conversion to double rounds to nearest, ties to even.
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<std::int64_t> mantissa(-(std::int64_t{1} << 40), std::int64_t{1} << 40);
  std::uniform_int_distribution<int> exponent(-60, 20);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<real> terms;
    int128 reference = 0;
    const int count = 1 + trial * 7;
    for (int k = 0; k < count; ++k) {
      const std::int64_t m = mantissa(rng);
      const int e = exponent(rng);
      terms.push_back(std::ldexp(static_cast<real>(m), e));
      reference += static_cast<int128>(m) << (e + 60);
    }
    const real expected = std::ldexp(static_cast<real>(reference), -60);
    ExactAccumulator whole, parts[3];
    for (std::size_t k = 0; k < terms.size(); ++k) {
      whole.add(terms[k]);
      parts[rng() % 3].add(terms[k]);
    }
    CHECK(same_bits(whole.rounded(), expected));
    // As processes would: digits summed digit by digit, or accumulators added.
    ExactAccumulator::Digits digits{};
    for (const auto& part : parts) {
      const auto d = part.digits();
      for (int k = 0; k < ExactAccumulator::digit_count; ++k) digits[k] += d[k];
    }
    CHECK(same_bits(ExactAccumulator::from_digits(digits, 0.0).rounded(), expected));
    ExactAccumulator joined = parts[2];
    joined.add(parts[0]);
    joined.add(parts[1]);
    CHECK(same_bits(joined.rounded(), expected));
  }
}
