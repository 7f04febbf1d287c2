// granulate._core's measures of arrays Python holds: exact sums' bins and particle sums.
#include "bindings.hpp"
#include "granulate/exact_sum.hpp"
#include "granulate/particle_sums.hpp"

namespace granulate::bindings {

using namespace nb::literals;

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
      "particle_sums",
      [](Indices owner, Scalars mass, Points positions, Points velocities, std::size_t count) {
        const std::size_t n = owner.shape(0);
        if (mass.shape(0) != n || positions.shape(0) != n || velocities.shape(0) != n) {
          throw InputError("particle_sums: owner, mass, positions and velocities differ in length");
        }
        for (std::size_t i = 0; i < n; ++i) {
          if (owner.data()[i] >= count) throw InputError("particle_sums: a node's particle is past count");
        }
        ParticleSums s = particle_sums({owner.data(), n}, {mass.data(), n}, {positions.data(), 3 * n},
                                       {velocities.data(), 3 * n}, count);
        return nb::make_tuple(copy_out(s.mass), rows_out(std::move(s.centre), 3),
                              rows_out(std::move(s.velocity), 3), rows_out(std::move(s.momentum), 3),
                              rows_out(std::move(s.inertia), 6), copy_out(s.spread));
      },
      "owner"_a, "mass"_a, "positions"_a, "velocities"_a, "count"_a,
      "Per particle its mass, centre, velocity, angular momentum, inertia tensor (xx, yy, zz, "
      "xy, xz, yz) and sum m |x - c|^2 (particle_sums.hpp).");
}

}  // namespace granulate::bindings
