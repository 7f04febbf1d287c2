// granulate._core's walls: surfaces, motion and time functions.
#include "bindings.hpp"

namespace granulate::bindings {

using namespace nb::literals;

void bind_walls(nb::module_& m) {
  nb::enum_<WallSurface::Kind>(m, "WallSurfaceKind")
      .value("plane", WallSurface::Kind::plane)
      .value("box_inside", WallSurface::Kind::box_inside)
      .value("box_outside", WallSurface::Kind::box_outside)
      .value("circle_inside", WallSurface::Kind::circle_inside)
      .value("circle_outside", WallSurface::Kind::circle_outside)
      .value("polygon", WallSurface::Kind::polygon)
      .value("triangles", WallSurface::Kind::triangles);
  nb::class_<WallSurface>(m, "WallSurface")
      .def(nb::init<>())
      .def_rw("kind", &WallSurface::kind)
      .def_rw("point", &WallSurface::point)
      .def_rw("normal", &WallSurface::normal)
      .def_rw("lower", &WallSurface::lower)
      .def_rw("upper", &WallSurface::upper)
      .def_rw("radius", &WallSurface::radius)
      .def_rw("vertices", &WallSurface::vertices)
      .def_rw("inside", &WallSurface::inside)
      .def_rw("mesh_vertices", &WallSurface::mesh_vertices)
      .def_rw("mesh_triangles", &WallSurface::mesh_triangles);
  nb::enum_<Wall::Motion>(m, "WallMotion")
      .value("fixed", Wall::Motion::fixed)
      .value("translation", Wall::Motion::translation)
      .value("rotation", Wall::Motion::rotation);
  nb::class_<Wall>(m, "Wall")
      .def(nb::init<>())
      .def_rw("name", &Wall::name)
      .def_rw("surfaces", &Wall::surfaces)
      .def_rw("motion", &Wall::motion)
      .def_rw("direction", &Wall::direction)
      .def_rw("center", &Wall::center)
      .def_rw("axis", &Wall::axis)
      .def(
          "set_function",
          [](Wall& self, TimeFunction::Kind kind, real a, real b) {
            self.function = make_function(kind, a, b);
          },
          "kind"_a, "a"_a, "b"_a)
      .def("displacement", [](const Wall& self, real t) { return self.function.value(t); }, "time"_a);
}

}  // namespace granulate::bindings
