// The terms of exact sums binned by exponent (granulate.exact_sum adds the bins up in Python
// ints): a float64 x is M 2^(S - 1127) with an integer M, |M| < 2^53, and 53 <= S <= 2098, so a
// sum of them is an integer times 2^-1127, exact whatever the order of its terms.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace granulate {

/// The bins in which ExactSumBins puts each array's terms: the sums of the terms' mantissa
/// halves per array and exponent, M = high 2^26 + low (high = floor(M / 2^26), 0 <= low <
/// 2^26), only the bins whose sums are not both zero. The sum of array a is
/// sum over its bins of (high 2^26 + low) 2^(S - 1127). Each half sums exactly in 64 bits for
/// up to 2^35 terms an array (2^35 halves below 2^27 in size).
struct ExactSumBins {
  std::vector<std::int64_t> array, exponent, high, low;  // one entry per bin kept
};

/// Every finite term of each array binned (ExactSumBins); nothing when a term is not finite
/// (inf or nan: the caller sums those itself).
std::optional<ExactSumBins> exact_sum_bins(std::span<const std::span<const double>> arrays);

}  // namespace granulate
