// What the binding files of granulate._core share: array types and views, and the one
// function per room that binds it (bind_module.cpp calls them in order).
#pragma once

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/shared_ptr.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include "granulate/simulation.hpp"

namespace granulate::bindings {

namespace nb = nanobind;

using Points = nb::ndarray<const double, nb::shape<-1, 3>, nb::c_contig, nb::device::cpu>;
using Scalars = nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using Indices = nb::ndarray<const std::uint32_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;

template <class T>
nb::ndarray<nb::numpy, T> view(T* data, std::size_t rows, std::size_t columns, nb::handle owner) {
  if (columns == 0) return nb::ndarray<nb::numpy, T>(data, {rows}, owner);
  return nb::ndarray<nb::numpy, T>(data, {rows, columns}, owner);
}

template <class T>
nb::ndarray<nb::numpy, T> copy_out(const std::vector<T>& values) {
  auto* data = new std::vector<T>(values);
  nb::capsule owner(data, [](void* p) noexcept { delete static_cast<std::vector<T>*>(p); });
  return nb::ndarray<nb::numpy, T>(data->data(), {data->size()}, owner);
}

/// `values` handed to NumPy as rows of `columns`, without a copy.
template <class T>
nb::ndarray<nb::numpy, T> rows_out(std::vector<T>&& values, std::size_t columns) {
  auto* data = new std::vector<T>(std::move(values));
  nb::capsule owner(data, [](void* p) noexcept { delete static_cast<std::vector<T>*>(p); });
  return nb::ndarray<nb::numpy, T>(data->data(), {data->size() / columns, columns}, owner);
}

inline std::vector<index_t> to_vector(const Indices& nodes) {
  return std::vector<index_t>(nodes.data(), nodes.data() + nodes.shape(0));
}

inline TimeFunction make_function(TimeFunction::Kind kind, real a, real b) {
  TimeFunction f;
  f.kind = kind;
  f.a = a;
  f.b = b;
  return f;
}

void bind_materials(nb::module_& m);   // plane modes, force models, influence, time functions, materials
void bind_model(nb::module_& m);       // Model: particles, shapes, bonds
void bind_contact(nb::module_& m);     // contact laws, damping ratios, statistics
void bind_walls(nb::module_& m);       // wall surfaces and walls
void bind_simulation(nb::module_& m);  // Simulation: loading, contact set-up, state, results
void bind_measures(nb::module_& m);    // exact sums' bins and run sums of NumPy arrays

/// Everything a run needs to continue bit for bit, as a dict of arrays (copies) and numbers.
nb::dict checkpoint_dict(const Simulation& self);
/// Continue from a dict made by checkpoint_dict (InputError naming a missing or bad entry).
void restore_dict(Simulation& self, const nb::dict& d);

}  // namespace granulate::bindings
