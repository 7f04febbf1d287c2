// granulate._core's contact laws, damping ratios and contact statistics.
#include "bindings.hpp"
#include "granulate/cell_grid.hpp"

namespace granulate::bindings {

using namespace nb::literals;

void bind_contact(nb::module_& m) {
  nb::class_<contact::Law>(m, "ContactLaw")
      .def(nb::init<>())
      .def_rw("contact_radius", &contact::Law::contact_radius)
      .def_rw("contact_radius_factor", &contact::Law::contact_radius_factor)
      .def_rw("normal_stiffness", &contact::Law::normal_stiffness)
      .def_rw("stiffness_factor", &contact::Law::stiffness_factor)
      .def_rw("damping_ratio", &contact::Law::damping_ratio)
      .def_rw("friction", &contact::Law::friction)
      .def_rw("tangential_stiffness_ratio", &contact::Law::tangential_stiffness_ratio)
      .def_rw("rolling_friction", &contact::Law::rolling_friction)
      .def_rw("rolling_damping", &contact::Law::rolling_damping)
      .def_rw("peridem_friction", &contact::Law::peridem_friction)
      .def_rw("node_pair", &contact::Law::node_pair)
      .def_rw("surface", &contact::Law::surface);
  m.def("combined_time_step", &Simulation::combined_time_step, "peridynamic"_a, "contact"_a,
        "1 / sqrt(1/dt_pd^2 + 1/dt_contact^2) [s] (dt_pd for an infinite dt_contact).");
  m.def("damping_ratio_from_restitution", &contact::damping_ratio_from_restitution, "restitution"_a);
  m.def("power_law_restitution", &contact::power_law_restitution, "damping_ratio"_a, "exponent"_a);
  m.def("power_law_damping_ratio", &contact::power_law_damping_ratio, "restitution"_a, "exponent"_a,
        "low"_a = 0.0, "high"_a = 50.0);

  m.def(
      "points_within",
      [](Points points, Points targets, real distance) {
        if (!(distance >= 0) || !std::isfinite(distance))
          throw InputError("points_within: the distance must be a non-negative length in m");
        const index_t n = static_cast<index_t>(points.shape(0)), m = static_cast<index_t>(targets.shape(0));
        std::vector<real> x(3 * static_cast<std::size_t>(m + n));  // the targets, then the points
        std::copy(targets.data(), targets.data() + 3 * static_cast<std::size_t>(m), x.begin());
        std::copy(points.data(), points.data() + 3 * static_cast<std::size_t>(n), x.begin() + 3 * m);
        std::vector<std::uint8_t> near(n, 0);
        {
          nb::gil_scoped_release released;
          const CellGrid grid = CellGrid::build(x, 0, m, std::max(distance, 1e-300));
          for (index_t k = 0; k < n; ++k)
            grid.for_each_within(x, m + k, distance, 3, [&](index_t, real) { near[k] = 1; });
        }
        return copy_out(near);
      },
      "points"_a, "targets"_a, "distance"_a,
      "Per point (n, 3), 1 where one of `targets` (m, 3) lies within `distance` [m] of it (a cell grid).");

  nb::class_<ContactStatistics>(m, "ContactStatistics")
      .def_ro("rebuilds", &ContactStatistics::rebuilds)
      .def_ro("list_updates", &ContactStatistics::list_updates)
      .def_ro("list_entries", &ContactStatistics::list_entries)
      .def_ro("node_contacts", &ContactStatistics::node_contacts)
      .def_ro("wall_contacts", &ContactStatistics::wall_contacts)
      .def_ro("deepest_overlap", &ContactStatistics::deepest_overlap)
      .def_ro("half_overlap_step", &ContactStatistics::half_overlap_step)
      .def_ro("full_overlap_step", &ContactStatistics::full_overlap_step);
}

}  // namespace granulate::bindings
