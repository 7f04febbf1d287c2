#include "granulate/exact_sum.hpp"

#include <bit>

namespace granulate {
namespace {

constexpr int exponent_bins = 2099;  // S = 0 .. 2098 (S >= 53 for every finite float)
constexpr int low_bits = 26;

}  // namespace

std::optional<ExactSumBins> exact_sum_bins(std::span<const std::span<const double>> arrays) {
  std::vector<std::int64_t> high(arrays.size() * exponent_bins, 0), low(high.size(), 0);
  for (std::size_t a = 0; a < arrays.size(); ++a) {
    std::int64_t* const highs = high.data() + a * exponent_bins;
    std::int64_t* const lows = low.data() + a * exponent_bins;
    for (const double x : arrays[a]) {
      const auto bits = std::bit_cast<std::uint64_t>(x);
      const auto biased = static_cast<int>((bits >> 52) & 0x7ff);
      if (biased == 0x7ff) return std::nullopt;  // inf or nan
      const auto fraction = static_cast<std::int64_t>(bits & ((std::uint64_t{1} << 52) - 1));
      // Normal: x = (2^52 + fraction) 2^(biased - 1075); subnormal: fraction 2^-1074.
      const std::int64_t magnitude = biased == 0 ? fraction : fraction | (std::int64_t{1} << 52);
      const std::int64_t mantissa = (bits >> 63) ? -magnitude : magnitude;
      const int shift = biased == 0 ? 53 : biased + 52;  // x = mantissa 2^(shift - 1127)
      const std::int64_t upper = mantissa >> low_bits;   // floor, for negative mantissas too
      highs[shift] += upper;
      lows[shift] += mantissa - upper * (std::int64_t{1} << low_bits);
    }
  }
  ExactSumBins bins;
  for (std::size_t k = 0; k < high.size(); ++k) {
    if (high[k] == 0 && low[k] == 0) continue;
    bins.array.push_back(static_cast<std::int64_t>(k / exponent_bins));
    bins.exponent.push_back(static_cast<std::int64_t>(k % exponent_bins));
    bins.high.push_back(high[k]);
    bins.low.push_back(low[k]);
  }
  return bins;
}

}  // namespace granulate
