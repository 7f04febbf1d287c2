// granulate._core's measures of arrays Python holds: exact sums' bins and run sums.
#include <algorithm>

#include "bindings.hpp"
#include "granulate/exact_sum.hpp"
#include "granulate/run_sums.hpp"

namespace granulate::bindings {

using namespace nb::literals;
using Counts = nb::ndarray<const std::int64_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using Table = nb::ndarray<const double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;

namespace {

/// The node count, after checking that `groups` and `nodes` have `rows` entries and the nodes
/// increase.
std::size_t check_runs(const char* name, const Counts& groups, const Counts& nodes, std::size_t rows) {
  const std::size_t n = nodes.shape(0);
  if (groups.shape(0) != n || rows != n)
    throw InputError(std::string(name) + ": the arrays differ in length");
  for (std::size_t i = 1; i < n; ++i) {
    if (nodes.data()[i] <= nodes.data()[i - 1])
      throw InputError(std::string(name) + ": the nodes must increase");
  }
  return n;
}

/// Runs as (first, length, group, sums) for NumPy.
nb::object runs_out(RunSums runs, std::size_t width) {
  return nb::make_tuple(copy_out(runs.first), copy_out(runs.length), copy_out(runs.group),
                        rows_out(std::move(runs.sums), std::max<std::size_t>(width, 1)));
}

}  // namespace

void bind_measures(nb::module_& m) {
  m.def(
      "exact_sum_bins",
      [](const std::vector<Scalars>& arrays) -> nb::object {
        std::vector<std::span<const double>> terms;
        for (const Scalars& a : arrays) terms.emplace_back(a.data(), a.shape(0));
        const auto bins = exact_sum_bins(terms);
        if (!bins) return nb::none();
        return nb::make_tuple(copy_out(bins->array), copy_out(bins->exponent), copy_out(bins->high),
                              copy_out(bins->low));
      },
      "arrays"_a,
      "Each array's terms binned for an exact sum (exact_sum.hpp): (array, exponent, high, low) "
      "per bin, or None when a term is not finite.");
  m.def(
      "run_sums",
      [](Counts groups, Counts nodes, Table values) {
        const std::size_t n = check_runs("run_sums", groups, nodes, values.shape(0));
        return runs_out(run_sums({groups.data(), n}, {nodes.data(), n}, {values.data(), n * values.shape(1)},
                                 values.shape(1)),
                        values.shape(1));
      },
      "groups"_a, "nodes"_a, "values"_a,
      "Per run of consecutive nodes of one group within a block of 64 nodes: its first node, "
      "length, group and the sums of its rows of values, in node order (run_sums.hpp).");
  m.def(
      "first_runs",
      [](Counts groups, Counts nodes, Scalars mass, Scalars volumes, Points positions, Points velocities) {
        const std::size_t n = check_runs("first_runs", groups, nodes, mass.shape(0));
        if (volumes.shape(0) != n || positions.shape(0) != n || velocities.shape(0) != n) {
          throw InputError("first_runs: the arrays differ in length");
        }
        return runs_out(
            first_runs({groups.data(), n}, {nodes.data(), n}, {mass.data(), n}, {volumes.data(), n},
                       {positions.data(), 3 * n}, {velocities.data(), 3 * n}),
            8);
      },
      "groups"_a, "nodes"_a, "mass"_a, "volumes"_a, "positions"_a, "velocities"_a,
      "The runs (as run_sums) of m, V, m x and m v: 8 sums a run (run_sums.hpp).");
  m.def(
      "moment_runs",
      [](Counts groups, Counts nodes, Scalars mass, Points positions, Points velocities, Points centres,
         Points centre_velocities) {
        const std::size_t n = check_runs("moment_runs", groups, nodes, mass.shape(0));
        if (positions.shape(0) != n || velocities.shape(0) != n) {
          throw InputError("moment_runs: the arrays differ in length");
        }
        const std::size_t count = centres.shape(0);
        if (centre_velocities.shape(0) != count)
          throw InputError("moment_runs: centres and velocities differ");
        for (std::size_t i = 0; i < n; ++i) {
          if (groups.data()[i] < 0 || static_cast<std::size_t>(groups.data()[i]) >= count) {
            throw InputError("moment_runs: a node's group is past count");
          }
        }
        return runs_out(moment_runs({groups.data(), n}, {nodes.data(), n}, {mass.data(), n},
                                    {positions.data(), 3 * n}, {velocities.data(), 3 * n},
                                    {centres.data(), 3 * count}, {centre_velocities.data(), 3 * count}),
                        10);
      },
      "groups"_a, "nodes"_a, "mass"_a, "positions"_a, "velocities"_a, "centres"_a, "centre_velocities"_a,
      "The runs (as run_sums) of the angular momentum, inertia tensor (xx, yy, zz, xy, xz, yz) "
      "and spread about each group's centre and velocity: 10 sums a run (run_sums.hpp).");
}

}  // namespace granulate::bindings
