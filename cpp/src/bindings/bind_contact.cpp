// granulate._core's contact laws, damping ratios and contact statistics.
#include "bindings.hpp"

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
  m.def("damping_ratio_from_restitution", &contact::damping_ratio_from_restitution, "restitution"_a);
  m.def("power_law_restitution", &contact::power_law_restitution, "damping_ratio"_a, "exponent"_a);
  m.def("power_law_damping_ratio", &contact::power_law_damping_ratio, "restitution"_a, "exponent"_a,
        "low"_a = 0.0, "high"_a = 50.0);

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
