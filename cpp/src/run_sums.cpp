// Built with -ffp-contract=off (CMakeLists.txt): each product is rounded before it is added, so a
// sum does not depend on the compiler's fusing.
#include "granulate/run_sums.hpp"

#include <array>

namespace granulate {

namespace {

/// The runs of `nodes` in their `groups`, each summing `width` terms a node that
/// terms(i, out) writes into out.
template <class Terms>
RunSums runs_of(std::span<const std::int64_t> groups, std::span<const std::int64_t> nodes, std::size_t width,
                Terms terms) {
  RunSums runs;
  std::vector<real> node_terms(width);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const bool joins = i > 0 && nodes[i] == nodes[i - 1] + 1 && groups[i] == groups[i - 1] &&
                       nodes[i] / kRunBlock == nodes[i - 1] / kRunBlock;
    if (!joins) {
      runs.first.push_back(nodes[i]);
      runs.length.push_back(0);
      runs.group.push_back(groups[i]);
      runs.sums.resize(runs.sums.size() + width, 0.0);
    }
    ++runs.length.back();
    terms(i, node_terms.data());
    real* sum = runs.sums.data() + runs.sums.size() - width;
    for (std::size_t k = 0; k < width; ++k) sum[k] += node_terms[k];
  }
  return runs;
}

}  // namespace

RunSums run_sums(std::span<const std::int64_t> groups, std::span<const std::int64_t> nodes,
                 std::span<const real> values, std::size_t width) {
  return runs_of(groups, nodes, width, [&](std::size_t i, real* out) {
    for (std::size_t k = 0; k < width; ++k) out[k] = values[i * width + k];
  });
}

RunSums first_runs(std::span<const std::int64_t> groups, std::span<const std::int64_t> nodes,
                   std::span<const real> mass, std::span<const real> volumes, std::span<const real> positions,
                   std::span<const real> velocities) {
  return runs_of(groups, nodes, 8, [&](std::size_t i, real* out) {
    out[0] = mass[i];
    out[1] = volumes[i];
    for (int k = 0; k < 3; ++k) {
      out[2 + k] = mass[i] * positions[3 * i + k];
      out[5 + k] = mass[i] * velocities[3 * i + k];
    }
  });
}

RunSums moment_runs(std::span<const std::int64_t> groups, std::span<const std::int64_t> nodes,
                    std::span<const real> mass, std::span<const real> positions,
                    std::span<const real> velocities, std::span<const real> centres,
                    std::span<const real> centre_velocities) {
  return runs_of(groups, nodes, 10, [&](std::size_t i, real* out) {
    const real m = mass[i];
    const std::size_t g = static_cast<std::size_t>(groups[i]);
    std::array<real, 3> a{}, u{};
    for (int k = 0; k < 3; ++k) {
      a[k] = positions[3 * i + k] - centres[3 * g + k];
      u[k] = velocities[3 * i + k] - centre_velocities[3 * g + k];
    }
    const std::array<real, 3> moment{a[1] * u[2] - a[2] * u[1], a[2] * u[0] - a[0] * u[2],
                                     a[0] * u[1] - a[1] * u[0]};
    const real r2 = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
    for (int k = 0; k < 3; ++k) out[k] = m * moment[k];
    out[3] = m * (r2 - a[0] * a[0]);
    out[4] = m * (r2 - a[1] * a[1]);
    out[5] = m * (r2 - a[2] * a[2]);
    out[6] = m * (0.0 - a[0] * a[1]);
    out[7] = m * (0.0 - a[0] * a[2]);
    out[8] = m * (0.0 - a[1] * a[2]);
    out[9] = m * r2;
  });
}

}  // namespace granulate
