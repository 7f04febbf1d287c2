// Models shared by the C++ tests.
#pragma once

#include <vector>

#include "granulate/model.hpp"

namespace granulate_test {

/// An elastic solid of density 1000 kg/m^3, K = 1 GPa, G = 0.6 GPa, horizon 3 mm (3 h on the
/// 1 mm lattices below); brittle with fracture energy G0 [J/m^2] if G0 > 0.
inline granulate::MaterialParams test_material(double fracture_energy = 0) {
  granulate::MaterialParams p;
  p.density = 1000;
  p.bulk_modulus = 1e9;
  p.shear_modulus = 6e8;
  p.horizon = 3e-3;
  p.fracture = fracture_energy > 0;
  if (p.fracture) p.fracture_energy = fracture_energy;
  return p;
}

/// Adds a 2D particle of n x n nodes, spacing 1 mm, its first node at (x0 + 0.5, y0 + 0.5) mm.
inline granulate::index_t add_square(granulate::Model& model, granulate::index_t material, int n, double x0,
                                     double y0) {
  std::vector<double> x, v;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      x.insert(x.end(), {x0 + (i + 0.5) * 1e-3, y0 + (j + 0.5) * 1e-3, 0.0});
      v.push_back(1e-6);
    }
  return model.add_particle(x, v, material, 1e-3);
}

}  // namespace granulate_test
