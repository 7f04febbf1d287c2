// nanobind module granulate._core: the C++ core seen from Python, bound room by room.
// Arrays returned by Model and Simulation are zero-copy NumPy views whose owner is the bound
// object: they stay valid while any view or the object itself is alive.
#include <omp.h>

#include "bindings.hpp"

using namespace granulate;
using namespace granulate::bindings;

NB_MODULE(_core, m) {
  m.doc() = "granulate C++ core: peridynamic particles, bonds, time integration";
  nb::exception<InputError>(m, "InputError", PyExc_ValueError);
  nb::exception<InstabilityError>(m, "InstabilityError", PyExc_RuntimeError);

  m.def("set_num_threads", [](int n) {
    if (n < 1) throw InputError("number of threads must be at least 1");
    omp_set_num_threads(n);
  });
  m.def("get_max_threads", [] { return omp_get_max_threads(); });
  m.def("build_info", [] {
    nb::dict d;
    d["build_type"] = GRANULATE_BUILD_TYPE;
    d["compiler"] = GRANULATE_COMPILER;
    d["cpu_tuning"] = GRANULATE_CPU_TUNING;
    d["openmp"] = _OPENMP;  // the specification date the compiler implements (yyyymm)
    d["warnings_as_errors"] = static_cast<bool>(GRANULATE_WARNINGS_AS_ERRORS);
    d["precision"] = sizeof(real) == 8 ? "double" : "single";
    d["index_bits"] = 8 * static_cast<int>(sizeof(index_t));
    return d;
  });

  bind_materials(m);
  bind_model(m);
  bind_contact(m);
  bind_walls(m);
  bind_simulation(m);
  bind_measures(m);
}
