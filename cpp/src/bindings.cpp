// nanobind module granulate._core: the C++ core seen from Python.
// Arrays returned by Model and Simulation are zero-copy NumPy views whose owner is the bound
// object: they stay valid while any view or the object itself is alive.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/shared_ptr.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>
#include <omp.h>

#include "granulate/simulation.hpp"

namespace nb = nanobind;
using namespace nb::literals;
using namespace granulate;

namespace {

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

std::vector<index_t> to_vector(const Indices& nodes) {
  return std::vector<index_t>(nodes.data(), nodes.data() + nodes.shape(0));
}

/// A flat array of T from a dict entry (a checkpoint), copied; a missing or mistyped entry is an
/// InputError naming it.
template <class T>
std::vector<T> entry(const nb::dict& data, const char* key) {
  if (!data.contains(key)) throw InputError(std::string("the checkpoint has no '") + key + "' entry");
  try {
    auto array = nb::cast<nb::ndarray<const T, nb::ndim<1>, nb::c_contig, nb::device::cpu>>(data[key]);
    return std::vector<T>(array.data(), array.data() + array.shape(0));
  } catch (const nb::cast_error&) {
    throw InputError(std::string("the checkpoint's '") + key + "' entry has the wrong type or shape");
  }
}

template <class T>
T scalar(const nb::dict& data, const char* key) {
  if (!data.contains(key)) throw InputError(std::string("the checkpoint has no '") + key + "' entry");
  try {
    return nb::cast<T>(data[key]);
  } catch (const nb::cast_error&) {
    throw InputError(std::string("the checkpoint's '") + key + "' entry has the wrong type");
  }
}

nb::dict checkpoint_dict(const Simulation& self) {
  const State& s = self.state();
  const ContactCheckpoint c = self.contact().checkpoint();
  nb::dict d;
  d["positions"] = copy_out(s.positions);
  d["velocities"] = copy_out(s.velocities);
  d["forces"] = copy_out(s.forces);
  d["bond_intact"] = copy_out(s.bonds.unpacked(self.model().bond_offsets()));
  d["dilatation"] = copy_out(s.dilatation);
  d["time"] = s.time;
  d["step"] = s.step;
  d["contact_built"] = c.built;
  d["contact_positions_at_build"] = copy_out(c.positions_at_build);
  d["contact_time_at_build"] = c.time_at_build;
  d["contact_broken_at_build"] = c.broken_at_build;
  d["contact_skin"] = c.skin;
  std::vector<index_t> slots;
  for (const auto& slot : c.slots) slots.insert(slots.end(), slot.begin(), slot.end());
  d["contact_slots"] = copy_out(slots);
  d["contact_particle_slot_count"] = c.particle_slot_count;
  d["contact_slot_approach"] = copy_out(c.slot_approach);
  d["contact_slot_normal"] = copy_out(c.slot_normal);
  d["contact_slot_work"] = copy_out(c.slot_work);
  d["contact_slot_rolling"] = copy_out(c.slot_rolling);
  d["contact_last_time"] = c.last_time;
  d["contact_has_last_time"] = c.has_last_time;
  d["contact_statistics"] = copy_out(
      std::vector<std::uint64_t>{c.statistics.rebuilds, c.statistics.list_entries, c.statistics.node_contacts,
                                 c.statistics.wall_contacts, c.statistics.list_updates});
  d["contact_pair_offsets"] = copy_out(c.pair_offsets);
  d["contact_pair_partners"] = copy_out(c.pair_partners);
  d["contact_springs"] = copy_out(c.springs);
  d["contact_pair_springs"] = copy_out(c.pair_springs);
  d["contact_wall_springs"] = copy_out(c.wall_springs);
  std::vector<real> reactions;
  for (const auto& r : c.wall_reactions) reactions.insert(reactions.end(), r.begin(), r.end());
  d["contact_wall_reactions"] = copy_out(reactions);
  return d;
}

void restore_dict(Simulation& self, const nb::dict& d) {
  State s;
  s.positions = entry<real>(d, "positions");
  s.velocities = entry<real>(d, "velocities");
  s.forces = entry<real>(d, "forces");
  if (!s.bonds.assign_unpacked(self.model().bond_offsets(), entry<std::uint8_t>(d, "bond_intact"))) {
    throw InputError("the checkpoint's state does not match this model (nodes or bonds differ)");
  }
  s.dilatation = entry<real>(d, "dilatation");
  s.time = scalar<real>(d, "time");
  s.step = scalar<std::uint64_t>(d, "step");
  ContactCheckpoint c;
  c.built = scalar<bool>(d, "contact_built");
  c.positions_at_build = entry<real>(d, "contact_positions_at_build");
  c.time_at_build = scalar<real>(d, "contact_time_at_build");
  c.broken_at_build = scalar<std::uint64_t>(d, "contact_broken_at_build");
  c.skin = scalar<real>(d, "contact_skin");
  const auto slots = entry<index_t>(d, "contact_slots");
  if (slots.size() % 2) throw InputError("the checkpoint's contact slots are malformed");
  for (std::size_t k = 0; k < slots.size(); k += 2) c.slots.push_back({slots[k], slots[k + 1]});
  c.particle_slot_count = scalar<std::uint64_t>(d, "contact_particle_slot_count");
  c.slot_approach = entry<real>(d, "contact_slot_approach");
  c.slot_normal = entry<real>(d, "contact_slot_normal");
  c.slot_work = entry<real>(d, "contact_slot_work");
  // Written since rolling resistance exists; a checkpoint without it had none.
  if (d.contains("contact_slot_rolling")) c.slot_rolling = entry<real>(d, "contact_slot_rolling");
  c.last_time = scalar<real>(d, "contact_last_time");
  c.has_last_time = scalar<bool>(d, "contact_has_last_time");
  const auto statistics = entry<std::uint64_t>(d, "contact_statistics");
  if (statistics.size() != 5) throw InputError("the checkpoint's contact statistics are malformed");
  c.statistics = {statistics[0], statistics[4], statistics[1], statistics[2], statistics[3]};
  c.pair_offsets = entry<index_t>(d, "contact_pair_offsets");
  c.pair_partners = entry<index_t>(d, "contact_pair_partners");
  c.springs = entry<real>(d, "contact_springs");
  c.pair_springs = entry<index_t>(d, "contact_pair_springs");
  c.wall_springs = entry<index_t>(d, "contact_wall_springs");
  const auto reactions = entry<real>(d, "contact_wall_reactions");
  if (reactions.size() % 6) throw InputError("the checkpoint's wall reactions are malformed");
  for (std::size_t k = 0; k < reactions.size(); k += 6) {
    c.wall_reactions.push_back({reactions[k], reactions[k + 1], reactions[k + 2], reactions[k + 3],
                                reactions[k + 4], reactions[k + 5]});
  }
  self.restore(s, c);
}

TimeFunction make_function(TimeFunction::Kind kind, real a, real b) {
  TimeFunction f;
  f.kind = kind;
  f.a = a;
  f.b = b;
  return f;
}

}  // namespace

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

  nb::class_<Model>(m, "Model")
      .def(nb::init<int, PlaneMode>(), "dimension"_a, "plane"_a = PlaneMode::strain)
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
      .def("finalize", &Model::finalize, nb::call_guard<nb::gil_scoped_release>())
      .def_prop_ro("finalized", &Model::finalized)
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
      .def_prop_ro("node_density",
                   [](Model& self) {
                     return view(const_cast<real*>(self.node_density().data()), self.node_count(), 0,
                                 nb::find(self));
                   })
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
      .def("bond_neighbors", [](const Model& self) {
        std::vector<index_t> neighbors(self.bond_count());
        for (index_t i = 0; i < self.node_count(); ++i) {
          const NodeBonds bonds = self.node_bonds(i);
          for (index_t b = 0; b < bonds.count; ++b) neighbors[bonds.first + b] = bonds.neighbor(b);
        }
        return copy_out(neighbors);
      });

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
        "low"_a = 0.0, "high"_a = 4.0);

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

  nb::class_<ContactStatistics>(m, "ContactStatistics")
      .def_ro("rebuilds", &ContactStatistics::rebuilds)
      .def_ro("list_updates", &ContactStatistics::list_updates)
      .def_ro("list_entries", &ContactStatistics::list_entries)
      .def_ro("node_contacts", &ContactStatistics::node_contacts)
      .def_ro("wall_contacts", &ContactStatistics::wall_contacts)
      .def_ro("deepest_overlap", &ContactStatistics::deepest_overlap);

  nb::class_<PhaseTimes>(m, "PhaseTimes")
      .def_ro("peridynamics", &PhaseTimes::peridynamics)
      .def_ro("contact", &PhaseTimes::contact)
      .def_ro("contact_search", &PhaseTimes::contact_search)
      .def_ro("integration", &PhaseTimes::integration)
      .def_ro("loading", &PhaseTimes::loading);

  nb::class_<Simulation>(m, "Simulation")
      .def(nb::init<std::shared_ptr<Model>>(), "model"_a, nb::call_guard<nb::gil_scoped_release>())
      .def_prop_rw("time_step", &Simulation::time_step, &Simulation::set_time_step)
      .def_prop_ro("stable_time_step", &Simulation::stable_time_step)
      .def_prop_ro("contact_stable_time_step",
                   [](const Simulation& self) { return self.contact().stable_time_step(self.model()); })
      .def(
          "set_peridem_damping",
          [](Simulation& self, Indices centers, Scalars radii, Indices walls, Scalars betan, Scalars kappa,
             Scalars contact_radius) {
            const std::size_t particles = centers.shape(0);
            const std::size_t pairs = betan.shape(0);
            if (radii.shape(0) != particles || walls.shape(0) != particles || kappa.shape(0) != pairs ||
                contact_radius.shape(0) != pairs) {
              throw InputError("set_peridem_damping: arrays of mismatched lengths");
            }
            std::vector<contact::PeridemParticle> p(particles);
            for (std::size_t k = 0; k < particles; ++k) p[k] = {centers(k), radii(k), walls(k) != 0};
            std::vector<contact::PeridemPair> q(pairs);
            for (std::size_t k = 0; k < pairs; ++k) q[k] = {betan(k), kappa(k), contact_radius(k)};
            self.set_peridem_damping(std::move(p), std::move(q));
          },
          "centers"_a, "radii"_a, "walls"_a, "betan"_a, "kappa"_a, "contact_radius"_a,
          "PeriDEM's centre damping (comparisons only): per particle its centre node, radius and wall "
          "flag; per material pair (row-major) betan, kappa and Rc")
      .def_prop_rw(
          "time", [](const Simulation& self) { return self.state().time; },
          [](Simulation& self, real t) { self.state().time = t; })
      .def_prop_rw(
          "step", [](const Simulation& self) { return self.state().step; },
          [](Simulation& self, std::uint64_t s) { self.state().step = s; })
      .def("first_wall_penetration",
           [](const Simulation& self) {
             return self.contact().first_wall_penetration(self.model(), self.state());
           })
      .def(
          "first_overlap",
          [](const Simulation& self, real fraction) {
            return self.contact().first_overlap(self.model(), self.state(), fraction);
          },
          "fraction"_a)
      .def("checkpoint", &checkpoint_dict,
           "Everything a run needs to continue bit for bit: a dict of arrays (copies) and numbers.")
      .def("restore", &restore_dict, "data"_a, "Continue from a dict made by checkpoint().")
      .def("set_body_acceleration", &Simulation::set_body_acceleration, "acceleration"_a)
      .def_prop_rw("viscous_damping", &Simulation::viscous_damping, &Simulation::set_viscous_damping)
      .def(
          "add_displacement",
          [](Simulation& self, Indices nodes, unsigned components, std::array<real, 3> direction,
             TimeFunction::Kind kind, real a, real b) {
            PrescribedMotion motion;
            motion.nodes = to_vector(nodes);
            motion.components = static_cast<std::uint8_t>(components & 0b111u);
            motion.direction = direction;
            motion.function = make_function(kind, a, b);
            self.add_prescribed_motion(std::move(motion));
          },
          "nodes"_a, "components"_a, "direction"_a, "kind"_a, "a"_a, "b"_a)
      .def(
          "add_rotation",
          [](Simulation& self, Indices nodes, std::array<real, 3> center, std::array<real, 3> axis,
             TimeFunction::Kind kind, real a, real b) {
            PrescribedMotion motion;
            motion.kind = PrescribedMotion::Kind::rotation;
            motion.nodes = to_vector(nodes);
            motion.center = center;
            motion.axis = axis;
            motion.function = make_function(kind, a, b);
            self.add_prescribed_motion(std::move(motion));
          },
          "nodes"_a, "center"_a, "axis"_a, "kind"_a, "a"_a, "b"_a)
      .def(
          "add_nodal_force",
          [](Simulation& self, Indices nodes, std::array<real, 3> vector, TimeFunction::Kind kind, real a,
             real b) {
            NodalForce force;
            force.nodes = to_vector(nodes);
            force.vector = vector;
            force.function = make_function(kind, a, b);
            self.add_nodal_force(std::move(force));
          },
          "nodes"_a, "vector"_a, "kind"_a, "a"_a, "b"_a)
      .def(
          "set_contact_law",
          [](Simulation& self, index_t a, index_t b, const contact::Law& law) {
            self.contact().set_law(a, b, law);
          },
          "material_a"_a, "material_b"_a, "law"_a)
      .def(
          "add_wall",
          [](Simulation& self, Wall wall) {
            return self.contact().add_wall(std::move(wall), self.model().dimension());
          },
          "wall"_a)
      .def(
          "set_wall_law",
          [](Simulation& self, index_t wall, index_t material, const contact::Law& law) {
            self.contact().set_wall_law(wall, material, law);
          },
          "wall"_a, "material"_a, "law"_a)
      .def(
          "set_contact_skin", [](Simulation& self, real skin) { self.contact().set_skin(skin); }, "skin"_a)
      .def("wall_reactions", [](const Simulation& self) { return self.contact().wall_reactions(); })
      .def(
          "contact_network",
          [](const Simulation& self) {
            const ContactNetwork net = self.contact().network(self.model(), self.state());
            nb::dict d;
            d["particle_a"] = copy_out(net.particle_a);
            d["node_a"] = copy_out(net.node_a);
            d["particle_b"] = copy_out(net.particle_b);
            d["node_b"] = copy_out(net.node_b);
            d["wall"] = copy_out(net.wall);
            d["point"] = copy_out(net.point);
            d["normal"] = copy_out(net.normal);
            d["force"] = copy_out(net.force);
            return d;
          },
          "The contacts of the last force evaluation (ContactNetwork): a dict of flat arrays (copies).")
      .def(
          "bond_force_densities",
          [](const Simulation& self) { return copy_out(self.bond_force_densities()); },
          "The bonds' force densities alone at the current state [N/m^3], flat (nodes x 3).")
      .def_prop_ro("walls", [](const Simulation& self) { return self.contact().walls(); })
      .def_prop_ro("contact_statistics", [](const Simulation& self) { return self.contact().statistics(); })
      .def("run", &Simulation::run, "steps"_a, nb::call_guard<nb::gil_scoped_release>())
      .def("compute_forces", &Simulation::compute_forces, nb::call_guard<nb::gil_scoped_release>())
      .def("kinetic_energy", &Simulation::kinetic_energy)
      .def("strain_energy", &Simulation::strain_energy)
      .def("contact_energy", &Simulation::contact_energy)
      .def("broken_bonds", &Simulation::broken_bonds)
      .def("strain_energy_density",
           [](const Simulation& self) {
             std::vector<real> density(self.model().node_count());
             self.strain_energy_density(density.data());
             return copy_out(density);
           })
      .def("damage",
           [](const Simulation& self) {
             std::vector<real> phi(self.model().node_count()), z(self.model().node_count());
             self.damage(phi.data(), z.data());
             return nb::make_tuple(copy_out(phi), copy_out(z));
           })
      .def("fixity", [](const Simulation& self) { return copy_out(self.fixity()); })
      .def("fragments",
           [](const Simulation& self) {
             std::vector<index_t> labels(self.model().node_count());
             self.fragments(labels.data());
             return copy_out(labels);
           })
      .def_prop_ro("phase_times", &Simulation::phase_times)
      .def("memory_bytes", &Simulation::memory_bytes)
      .def_prop_ro("positions",
                   [](Simulation& self) {
                     return view(self.state().positions.data(), self.model().node_count(), 3, nb::find(self));
                   })
      .def_prop_ro("velocities",
                   [](Simulation& self) {
                     return view(self.state().velocities.data(), self.model().node_count(), 3,
                                 nb::find(self));
                   })
      .def_prop_ro("forces",
                   [](Simulation& self) {
                     return view(self.state().forces.data(), self.model().node_count(), 3, nb::find(self));
                   })
      .def_prop_ro("dilatation",
                   [](Simulation& self) {
                     return view(self.state().dilatation.data(), self.model().node_count(), 0,
                                 nb::find(self));
                   })
      .def_prop_ro("bond_intact",
                   [](Simulation& self) {  // a read-only copy, 1 byte per bond (stored as bits)
                     nb::object array =
                         nb::cast(copy_out(self.state().bonds.unpacked(self.model().bond_offsets())),
                                  nb::rv_policy::move);
                     array.attr("setflags")("write"_a = false);
                     return array;
                   })
      .def(
          "break_bonds",
          [](Simulation& self, nb::ndarray<const std::uint32_t, nb::shape<-1, 2>, nb::c_contig> pairs) {
            std::vector<std::array<index_t, 2>> list(pairs.shape(0));
            for (std::size_t k = 0; k < list.size(); ++k) list[k] = {pairs(k, 0), pairs(k, 1)};
            self.break_bonds(list);
          },
          "pairs"_a);
}
