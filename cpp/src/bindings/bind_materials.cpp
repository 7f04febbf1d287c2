// granulate._core's materials: plane modes, force models, influence functions, time functions.
#include "bindings.hpp"

namespace granulate::bindings {

using namespace nb::literals;

void bind_materials(nb::module_& m) {
  nb::enum_<PlaneMode>(m, "PlaneMode")
      .value("strain", PlaneMode::strain)
      .value("stress", PlaneMode::stress)
      .value("peridem", PlaneMode::peridem);
  nb::enum_<ForceModel>(m, "ForceModel").value("lps", ForceModel::lps).value("pmb", ForceModel::pmb);
  nb::enum_<InfluenceKind>(m, "InfluenceKind")
      .value("constant", InfluenceKind::constant)
      .value("linear", InfluenceKind::linear)
      .value("gaussian", InfluenceKind::gaussian)
      .value("inverse", InfluenceKind::inverse);
  nb::enum_<TimeFunction::Kind>(m, "TimeFunctionKind")
      .value("constant", TimeFunction::Kind::constant)
      .value("linear", TimeFunction::Kind::linear)
      .value("quadratic", TimeFunction::Kind::quadratic)
      .value("sine", TimeFunction::Kind::sine)
      .value("smooth_ramp", TimeFunction::Kind::smooth_ramp)
      .value("velocity_ramp", TimeFunction::Kind::velocity_ramp);

  m.def("time_function_value",
        [](TimeFunction::Kind kind, real a, real b, real t) { return make_function(kind, a, b).value(t); });
  m.def("time_function_rate",
        [](TimeFunction::Kind kind, real a, real b, real t) { return make_function(kind, a, b).rate(t); });
  m.def("influence", &influence, "kind"_a, "xi"_a);
  m.def(
      "fracture_coefficients",
      [](ForceModel model, InfluenceKind kind, int dimension) {
        const FractureCoefficients c = fracture_coefficients(model, kind, dimension);
        return nb::make_tuple(c.pair, c.dilatation);
      },
      "model"_a, "influence"_a, "dimension"_a);

  nb::class_<MaterialParams>(m, "MaterialParams")
      .def(nb::init<>())
      .def_rw("model", &MaterialParams::model)
      .def_rw("density", &MaterialParams::density)
      .def_rw("bulk_modulus", &MaterialParams::bulk_modulus)
      .def_rw("shear_modulus", &MaterialParams::shear_modulus)
      .def_rw("horizon", &MaterialParams::horizon)
      .def_rw("fracture_energy", &MaterialParams::fracture_energy)
      .def_rw("influence", &MaterialParams::influence)
      .def_rw("fracture", &MaterialParams::fracture)
      .def_rw("break_in_compression", &MaterialParams::break_in_compression);

  nb::class_<Material>(m, "Material")
      .def_static(
          "make",
          [](const MaterialParams& params, int dimension, PlaneMode plane) {
            return Material::make(params, dimension, plane);
          },
          "params"_a, "dimension"_a, "plane"_a)
      .def_ro("params", &Material::params)
      .def_ro("dilatation_modulus", &Material::dilatation_modulus)
      .def_ro("deviatoric_factor", &Material::deviatoric_factor)
      .def_ro("micromodulus", &Material::micromodulus)
      .def_ro("critical_stretch", &Material::critical_stretch);
}

}  // namespace granulate::bindings
