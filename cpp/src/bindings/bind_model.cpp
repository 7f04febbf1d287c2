// granulate._core's Model: particles, shared shapes and bond families, zero-copy views.
#include <algorithm>

#include "bindings.hpp"

namespace granulate::bindings {

using namespace nb::literals;

namespace {

/// Building a model: materials, shapes, particles, finalize.
void bind_building(nb::class_<Model>& model) {
  model.def(nb::init<int, PlaneMode>(), "dimension"_a, "plane"_a = PlaneMode::strain)
      .def("add_material", &Model::add_material, "params"_a)
      .def(
          "add_particle",
          [](Model& self, Points positions, Scalars volumes, index_t material, real mesh_size, real horizon) {
            return self.add_particle({positions.data(), positions.shape(0) * 3},
                                     {volumes.data(), volumes.shape(0)}, material, mesh_size, horizon);
          },
          "positions"_a, "volumes"_a, "material"_a, "mesh_size"_a, "horizon"_a = 0.0)
      .def(
          "add_shape",
          [](Model& self, Points positions, Scalars volumes, real mesh_size, Scalars surface_offsets,
             Scalars surface_depths) {
            return self.add_shape({positions.data(), positions.shape(0) * 3},
                                  {volumes.data(), volumes.shape(0)}, mesh_size,
                                  {surface_offsets.data(), surface_offsets.shape(0)},
                                  {surface_depths.data(), surface_depths.shape(0)});
          },
          "positions"_a, "volumes"_a, "mesh_size"_a, "surface_offsets"_a, "surface_depths"_a)
      .def(
          "place_shape",
          [](Model& self, index_t shape, index_t material, Points positions, real scale, real horizon) {
            return self.add_particle(shape, material, {positions.data(), positions.shape(0) * 3}, scale,
                                     horizon);
          },
          "shape"_a, "material"_a, "positions"_a, "scale"_a, "horizon"_a = 0.0)
      .def_prop_ro("shape_count", [](const Model& self) { return self.shapes().size(); })
      .def_prop_ro("family_count", [](const Model& self) { return self.families().size(); })
      .def("shared_bond_bytes",
           [](const Model& self) {
             std::size_t bytes = 0;
             for (const BondFamilies& f : self.families()) {
               bytes += f.neighbors.size() * (sizeof(index_t) + sizeof(float) + sizeof(real)) +
                        f.offsets.size() * sizeof(index_t);
             }
             return bytes;
           })
      .def("set_whole_particle_bonds", &Model::set_whole_particle_bonds, "bonds"_a,
           "The most forward bonds of a particle the bond passes evaluate whole (before finalize).")
      .def("finalize", &Model::finalize, nb::call_guard<nb::gil_scoped_release>());
}

/// What a model holds: counts, per-particle values and zero-copy views of its arrays.
void bind_contents(nb::class_<Model>& model) {
  model.def_prop_ro("finalized", &Model::finalized)
      .def_prop_ro("dimension", &Model::dimension)
      .def_prop_ro("node_count", &Model::node_count)
      .def_prop_ro("bond_count", &Model::bond_count)
      .def_prop_ro("particle_count", [](const Model& self) { return self.particles().size(); })
      .def_prop_ro("material_count", [](const Model& self) { return self.materials().size(); })
      .def(
          "particle_horizon", [](const Model& self, index_t p) { return self.particles().at(p).horizon; },
          "particle"_a)
      .def(
          "particle_critical_stretch",
          [](const Model& self, index_t p) { return self.particles().at(p).critical_stretch; }, "particle"_a)
      .def_prop_ro("materials", &Model::materials)
      .def("stable_time_step", &Model::stable_time_step)
      .def_prop_ro("reference_positions",
                   [](Model& self) {
                     return view(const_cast<real*>(self.reference_positions().data()), self.node_count(), 3,
                                 nb::find(self));
                   })
      .def_prop_ro("volumes",
                   [](Model& self) {
                     return view(const_cast<real*>(self.volumes().data()), self.node_count(), 0,
                                 nb::find(self));
                   })
      .def_prop_ro(
          "node_density",
          [](const Model& self) {  // a copy: densities are kept per material
            std::vector<real> density(self.node_count());
            for (index_t i = 0; i < self.node_count(); ++i) density[i] = self.density(i);
            return copy_out(density);
          },
          nb::rv_policy::move, "each node's mass density [kg/m^3] (a new array)")
      .def_prop_ro("node_particle",
                   [](Model& self) {
                     return view(const_cast<index_t*>(self.node_particle().data()), self.node_count(), 0,
                                 nb::find(self));
                   })
      .def_prop_ro("bond_offsets",
                   [](Model& self) {
                     return view(const_cast<std::size_t*>(self.bond_offsets().data()),
                                 self.bond_offsets().size(), 0, nb::find(self));
                   })
      .def_prop_ro(
          "particle_gathers",
          [](const Model& self) { return copy_out(self.bond_schedule().particle_gathers); },
          nb::rv_policy::move,
          "Per particle, 1 if its nodes evaluate all their bonds and write only their own sums "
          "(BondSchedule::particle_gathers), 0 if each bond is evaluated once (a new array).")
      .def_prop_ro(
          "bond_colour_blocks",
          [](const Model& self) {
            const auto& offsets = self.bond_schedule().colour_offsets;
            std::vector<index_t> counts(offsets.size() - 1);
            for (std::size_t c = 0; c < counts.size(); ++c) counts[c] = offsets[c + 1] - offsets[c];
            return copy_out(counts);
          },
          nb::rv_policy::move,
          "The bond passes' blocks per colour, in the order they are walked (BondSchedule; a new "
          "array).")
      .def(
          "bond_partners",
          [](const Model& self, const std::vector<index_t>& nodes) {
            std::vector<index_t> partners;
            for (const index_t i : nodes) {
              if (i >= self.node_count())
                throw InputError("bond_partners: node " + std::to_string(i) + " does not exist");
              const NodeBonds bonds = self.node_bonds(i);
              for (index_t b = 0; b < bonds.count; ++b) partners.push_back(bonds.neighbor(b));
            }
            std::sort(partners.begin(), partners.end());
            partners.erase(std::unique(partners.begin(), partners.end()), partners.end());
            return copy_out(partners);
          },
          "nodes"_a, "The nodes bonded to any of `nodes` (broken bonds too), sorted, each once.")
      .def(
          "bonded_beyond",
          [](const Model& self, const std::vector<index_t>& nodes, const std::vector<index_t>& held) {
            std::vector<std::uint8_t> in_held(self.node_count(), 0);
            for (const index_t i : held) {
              if (i >= self.node_count())
                throw InputError("bonded_beyond: node " + std::to_string(i) + " does not exist");
              in_held[i] = 1;
            }
            std::vector<index_t> beyond;
            for (const index_t i : nodes) {
              if (i >= self.node_count())
                throw InputError("bonded_beyond: node " + std::to_string(i) + " does not exist");
              const NodeBonds bonds = self.node_bonds(i);
              for (index_t b = 0; b < bonds.count; ++b) {
                if (!in_held[bonds.neighbor(b)]) {
                  beyond.push_back(i);
                  break;
                }
              }
            }
            return copy_out(beyond);
          },
          "nodes"_a, "held"_a,
          "Those of `nodes` (in their order) bonded to a node not in `held` (broken bonds too).")
      .def("bond_neighbors", [](const Model& self) {
        std::vector<index_t> neighbors(self.bond_count());
        for (index_t i = 0; i < self.node_count(); ++i) {
          const NodeBonds bonds = self.node_bonds(i);
          for (index_t b = 0; b < bonds.count; ++b) neighbors[bonds.first + b] = bonds.neighbor(b);
        }
        return copy_out(neighbors);
      });
}

}  // namespace

void bind_model(nb::module_& m) {
  nb::class_<Model> model(m, "Model");
  bind_building(model);
  bind_contents(model);
}

}  // namespace granulate::bindings
