// granulate._core's Simulation: loading, contact set-up, the state as zero-copy views, results.
#include "bindings.hpp"

namespace granulate::bindings {

using namespace nb::literals;

namespace {

/// A BodyMotion's numbers (body_motion_size: centre, velocity, angular velocity, inverse
/// inertia) appended to `out`, and read back.
void append_motion(std::vector<real>& out, const BodyMotion& motion) {
  for (const auto* part : {&motion.centre, &motion.velocity, &motion.angular_velocity})
    out.insert(out.end(), part->begin(), part->end());
  out.insert(out.end(), motion.inverse_inertia.begin(), motion.inverse_inertia.end());
}

BodyMotion motion_from(const double* numbers) {
  BodyMotion motion;
  for (auto* part : {&motion.centre, &motion.velocity, &motion.angular_velocity}) {
    std::copy(numbers, numbers + 3, part->begin());
    numbers += 3;
  }
  std::copy(numbers, numbers + 6, motion.inverse_inertia.begin());
  return motion;
}

/// count_of(i) for each node i of `nodes` (InputError naming `what` for one out of range).
template <typename CountOf>
std::vector<index_t> per_node(const Simulation& self, const std::int64_t* nodes, std::size_t size,
                              const char* what, CountOf count_of) {
  const auto count = static_cast<std::int64_t>(self.model().node_count());
  std::vector<index_t> counts(size);
  for (std::size_t k = 0; k < size; ++k) {
    if (nodes[k] < 0 || nodes[k] >= count) throw InputError(std::string(what) + ": nodes out of range");
    counts[k] = count_of(static_cast<index_t>(nodes[k]));
  }
  return counts;
}

// The time step, PeriDEM's damping, time and step, checkpoints, body forces.
void bind_run_setup(nb::class_<Simulation>& cls) {
  cls.def(nb::init<std::shared_ptr<Model>>(), "model"_a, nb::call_guard<nb::gil_scoped_release>())
      .def_prop_rw("time_step", &Simulation::time_step, &Simulation::set_time_step)
      .def_prop_ro("stable_time_step", &Simulation::stable_time_step)
      .def_prop_ro("contact_stable_time_step",
                   [](const Simulation& self) { return self.contact().stable_time_step(self.model()); })
      .def_prop_ro("peridynamic_stable_time_step", &Simulation::peridynamic_stable_time_step)
      .def(
          "contact_partners",
          [](const Simulation& self) {
            std::vector<real> rows;
            for (const ContactModel::Partner& q : self.contact().partners(self.model())) {
              rows.insert(rows.end(), {static_cast<real>(q.material), q.side.mesh_size, q.side.horizon,
                                       q.side.modulus, q.largest_volume});
            }
            return copy_out(rows);
          },
          "Each particle as the contact's stable time step reads a partner, flat (k x 5): its "
          "material, mesh size, horizon, dilatation modulus and largest node volume.")
      .def(
          "contact_stable_time_step_against",
          [](const Simulation& self, Scalars rows) {
            if (rows.shape(0) % 5 != 0) throw InputError("contact partners: give 5 numbers per particle");
            std::vector<ContactModel::Partner> partners(rows.shape(0) / 5);
            for (std::size_t q = 0; q < partners.size(); ++q) {
              const double* row = rows.data() + 5 * q;
              partners[q] = {static_cast<index_t>(row[0]), {row[1], row[2], row[3]}, row[4]};
            }
            return self.contact().stable_time_step(self.model(), partners);
          },
          "rows"_a,
          "The contact's stable time step of this model's particles against these partners "
          "(contact_partners' rows, materials in this model's numbering) [s].")
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
          [](Simulation& self, real fraction) {
            return self.contact().first_overlap(self.model(), self.state(), fraction);
          },
          "fraction"_a)
      .def("checkpoint", &checkpoint_dict,
           "Everything a run needs to continue bit for bit: a dict of arrays (copies) and numbers.")
      .def("restore", &restore_dict, "data"_a, "Continue from a dict made by checkpoint().")
      .def("set_body_acceleration", &Simulation::set_body_acceleration, "acceleration"_a)
      .def_prop_rw("viscous_damping", &Simulation::viscous_damping, &Simulation::set_viscous_damping);
}

// Prescribed motion, nodal forces, contact laws, walls, the neighbour skin.
void bind_loading(nb::class_<Simulation>& cls) {
  cls.def(
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
      .def_prop_ro(
          "contact_reach", [](const Simulation& self) { return self.contact().list_cutoff(self.model()); },
          "The neighbour lists' cutoff [m]: the largest reach of a pair of nodes plus the skin.")
      .def_prop_ro(
          "contact_skin", [](const Simulation& self) { return self.contact().list_skin(); },
          "The neighbour lists' skin [m]: as set, or half the largest contact radius.")
      .def(
          "set_contact_skin", [](Simulation& self, real skin) { self.contact().set_skin(skin); }, "skin"_a)
      .def("set_ghost_particles", &Simulation::set_ghost_particles, "particles"_a,
           "Mark the particles whose forces another process evaluates (Simulation::set_ghost_particles).")
      .def("set_foreign_nodes", &Simulation::set_foreign_nodes, "nodes"_a,
           "Mark the nodes of this process's particles that other processes own, a particle split at "
           "node level (Simulation::set_foreign_nodes); [] for none.")
      .def(
          "set_inert_contact_nodes",
          [](Simulation& self, const std::vector<index_t>& nodes) {
            std::vector<std::uint8_t> inert(nodes.empty() ? 0 : self.model().node_count(), 0);
            for (const index_t i : nodes) {
              if (i >= inert.size())
                throw InputError("inert contact node " + std::to_string(i) + " does not exist");
              inert[i] = 1;
            }
            self.contact().set_inert_nodes(std::move(inert));
          },
          "nodes"_a,
          "Leave these nodes out of the contact lists (ContactModel::set_inert_nodes); [] for none.")
      .def("set_reported_numbers", &Simulation::set_reported_numbers, "nodes"_a, "particles"_a,
           "The node and particle numbers error messages give (Simulation::set_reported_numbers).")
      .def("set_reported_stable_time_step", &Simulation::set_reported_stable_time_step, "estimate"_a,
           "The stable time-step estimate [s] error messages quote; 0: the simulation's own.")
      .def("set_travel_origin", &Simulation::set_travel_origin, "watched"_a,
           "Measure each step how far the farthest node, or where the contact lists see one of the "
           "nodes watched, is from where it is now (largest_travel).")
      .def_prop_ro(
          "largest_travel", &Simulation::largest_travel,
          "The largest distance of a node (but the ghosts), or of a watched node's list position, from the "
          "travel origin where the last step, begun or finished, put them [m].")
      .def_prop_ro(
          "list_positions", [](const Simulation& s) { return rows_out(s.list_positions(), 3); },
          nb::rv_policy::move,
          "Where the contact lists see each node now (its surface point or contact centre, or the node), "
          "n x 3 [m].")
      .def_prop_ro("contact_surface_normal_reach", &Simulation::contact_surface_normal_reach,
                   "How near two nodes of different bodies must come, as the lists see them, before "
                   "their contact reads their surface normals (sums over their bonds) [m]; 0: never.")
      .def(
          "contact_anchors",
          [](const Simulation& s, const std::vector<index_t>& nodes) {
            return copy_out(s.contact_anchors(nodes));
          },
          "nodes"_a,
          "The nodes whose positions these nodes' anchored vectors read now: their anchors (sorted, each "
          "once).")
      .def("search_contacts", &Simulation::search_contacts,
           "List every node's contact partners again now, carrying collisions and friction springs over.")
      .def(
          "contact_wall_entries",
          [](const Simulation& self) {
            std::vector<index_t> entries;
            for (const auto& entry : self.contact().wall_entries())
              entries.insert(entries.end(), entry.begin(), entry.end());
            return nb::make_tuple(copy_out(self.contact().wall_offsets()), copy_out(entries));
          },
          "The wall lists: (offsets per node, n + 1; (wall, surface) pairs, flat).")
      .def(
          "set_contact_relisting",
          [](Simulation& self, bool relisting) { self.contact().set_relisting(relisting); }, "relisting"_a);
}

// Wall reactions, the contact network, energies, damage, fragments, timings.
void bind_results(nb::class_<Simulation>& cls) {
  cls.def("wall_reactions", [](const Simulation& self) { return self.contact().wall_reactions(); })
      .def(
          "wall_reaction_terms",
          [](const Simulation& self) {
            const ContactModel& c = self.contact();
            std::vector<index_t> slots;
            for (std::size_t k = c.particle_slot_count(); k < c.slots().size(); ++k)
              slots.insert(slots.end(), c.slots()[k].begin(), c.slots()[k].end());
            std::vector<real> terms, entries;
            for (const auto& t : c.wall_slot_terms()) terms.insert(terms.end(), t.begin(), t.end());
            for (const auto& r : c.wall_entry_reactions()) entries.insert(entries.end(), r.begin(), r.end());
            return nb::make_tuple(copy_out(slots), copy_out(terms), copy_out(entries));
          },
          "The terms of wall_reactions (ContactModel::wall_slot_terms): the wall slots' (body, wall) "
          "pairs, their 9 terms, and each wall entry's reaction (6), all flat.")
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
      .def("move", &Simulation::move, nb::call_guard<nb::gil_scoped_release>(),
           "The first half kick, drift and prescribed motion of a step, which begin_step continues "
           "from (Simulation::move).")
      .def("evaluate_dilatation", &Simulation::evaluate_dilatation, "share"_a = 1.0,
           nb::call_guard<nb::gil_scoped_release>(),
           "Between move and begin_step: pass 1 of the inner bond blocks, which read nothing of the "
           "halo, up to this share of them (Simulation::evaluate_dilatation); begin_step takes the "
           "rest.")
      .def(
          "begin_step",
          [](Simulation& self) {
            std::vector<std::array<index_t, 2>> broken;
            {
              nb::gil_scoped_release released;
              broken = self.begin_step();
            }
            std::vector<index_t> flat;
            flat.reserve(2 * broken.size());
            for (const auto& [i, j] : broken) flat.insert(flat.end(), {i, j});
            return copy_out(flat);
          },
          "The first half of a step (Simulation::begin_step); the bonds it broke, (i, j) flat.")
      .def(
          "finish_step",
          [](Simulation& self,
             nb::ndarray<const std::uint32_t, nb::shape<-1, 2>, nb::c_contig> ghost_breaks) {
            std::vector<std::array<index_t, 2>> list(ghost_breaks.shape(0));
            for (std::size_t k = 0; k < list.size(); ++k) list[k] = {ghost_breaks(k, 0), ghost_breaks(k, 1)};
            nb::gil_scoped_release released;
            self.finish_step(list);
          },
          "ghost_breaks"_a,
          "The rest of the step, after breaking the ghosts' bonds their owners broke, (k, 2) node pairs.")
      .def("evaluate_bonds", &Simulation::evaluate_bonds, "share"_a = 1.0,
           nb::call_guard<nb::gil_scoped_release>(),
           "Between begin_step and finish_step: the own nodes' body forces, then pass 2 of the inner "
           "bond blocks, which read no ghost and nothing of the halo, up to this share of them "
           "(Simulation::evaluate_bonds); finish_step takes what is left.")
      .def(
          "fragment_motions",
          [](const Simulation& self, const std::vector<index_t>& particles) {
            std::vector<index_t> nodes;
            std::vector<real> numbers;
            for (const auto& [node, motion] : self.fragment_motions(particles)) {
              nodes.push_back(node);
              append_motion(numbers, motion);
            }
            return nb::make_tuple(copy_out(nodes), copy_out(numbers));
          },
          "particles"_a,
          "Between begin_step and finish_step: every fragment of these own particles, its smallest "
          "node and its rigid-body motion (Simulation::fragment_motions), as (nodes, flat motions: "
          "centre, velocity, angular velocity, inverse inertia; 15 a fragment).")
      .def(
          "give_ghost_motions",
          [](Simulation& self, nb::ndarray<const std::uint32_t, nb::ndim<1>, nb::c_contig> nodes,
             nb::ndarray<const double, nb::shape<-1, body_motion_size>, nb::c_contig> motions) {
            if (nodes.shape(0) != motions.shape(0))
              throw InputError("give_ghost_motions: one node per motion, got " +
                               std::to_string(nodes.shape(0)) + " nodes and " +
                               std::to_string(motions.shape(0)) + " motions");
            std::vector<std::pair<index_t, BodyMotion>> given(nodes.shape(0));
            for (std::size_t k = 0; k < given.size(); ++k) given[k] = {nodes(k), motion_from(&motions(k, 0))};
            self.give_ghost_motions(std::move(given));
          },
          "nodes"_a, "motions"_a,
          "Before finish_step: the ghost bodies' motions from their owners' fragment_motions "
          "(Simulation::give_ghost_motions), each named by its smallest node here; (k, 15).")
      .def(
          "surface_normals",
          [](const Simulation& self, const std::vector<index_t>& nodes) {
            return rows_out(self.surface_normals(nodes), 3);
          },
          nb::rv_policy::move, "nodes"_a,
          "Between begin_step and finish_step, on the owner: the outward surface normals of these "
          "nodes as this step's contact reads them (Simulation::surface_normals), (k, 3).")
      .def(
          "give_ghost_surface_normals",
          [](Simulation& self, nb::ndarray<const std::uint32_t, nb::ndim<1>, nb::c_contig> nodes,
             nb::ndarray<const double, nb::shape<-1, 3>, nb::c_contig> normals) {
            if (nodes.shape(0) != normals.shape(0))
              throw InputError("give_ghost_surface_normals: one node per normal, got " +
                               std::to_string(nodes.shape(0)) + " nodes and " +
                               std::to_string(normals.shape(0)) + " normals");
            std::vector<std::pair<index_t, vec3>> given(nodes.shape(0));
            for (std::size_t k = 0; k < given.size(); ++k)
              given[k] = {nodes(k), {normals(k, 0), normals(k, 1), normals(k, 2)}};
            self.give_ghost_surface_normals(std::move(given));
          },
          "nodes"_a, "normals"_a,
          "Before finish_step: the ghost nodes' surface normals from their owners' surface_normals "
          "(Simulation::give_ghost_surface_normals); (k,) nodes here and (k, 3) normals.")
      .def("compute_forces", &Simulation::compute_forces, nb::call_guard<nb::gil_scoped_release>())
      .def("strain_energy", &Simulation::strain_energy)
      .def("contact_energy", &Simulation::contact_energy)
      .def(
          "node_contact_terms",
          [](const Simulation& self) {
            const index_t n = self.model().node_count();
            std::vector<real> energy(n);
            std::vector<std::uint32_t> pairs(n), walls(n);
            self.contact().node_contact_terms(self.model(), self.state(), energy.data(), pairs.data(),
                                              walls.data());
            return nb::make_tuple(copy_out(energy), copy_out(pairs), copy_out(walls));
          },
          "Per node: its contacts' spring energy, node pairs in contact (at the smaller node) and "
          "wall contacts (ContactModel::node_contact_terms).")
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
      .def(
          "damage_phi",
          [](const Simulation& self) {
            std::vector<real> phi(self.model().node_count());
            self.damage(phi.data(), nullptr);
            return copy_out(phi);
          },
          "Per node the damage phi alone (damage()[0], from the bond states only).")
      .def_prop_ro("bond_changes", &Simulation::bond_changes,
                   "A count that changes whenever a bond state does (Simulation::bond_changes).")
      .def("fixity", [](const Simulation& self) { return copy_out(self.fixity()); })
      .def("fragments",
           [](const Simulation& self) {
             std::vector<index_t> labels(self.model().node_count());
             self.fragments(labels.data());
             return copy_out(labels);
           })
      .def(
          "fragments_among",
          [](const Simulation& self, Indices nodes) {
            const std::vector<index_t> among = to_vector(nodes);
            std::vector<index_t> labels(among.size());
            std::vector<std::array<index_t, 2>> leaving;
            self.fragments_among(among, labels.data(), leaving);
            std::vector<index_t> flat;
            flat.reserve(2 * leaving.size());
            for (const auto& [i, j] : leaving) flat.insert(flat.end(), {i, j});
            return nb::make_tuple(copy_out(labels), rows_out(std::move(flat), 2));
          },
          "nodes"_a,
          "The fragments among these nodes (increasing): each one's label, the smallest of them "
          "it is connected to through intact bonds among them, and the intact bonds (node, "
          "partner) leaving them (Model::fragments_among).")
      .def_prop_ro("phase_times", &Simulation::phase_times)
      .def("memory_bytes", &Simulation::memory_bytes);
}

// The state as zero-copy views, and bonds broken by hand.
void bind_state(nb::class_<Simulation>& cls) {
  cls.def_prop_ro("positions",
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
      .def(
          "assign_bonds",
          [](Simulation& self, nb::ndarray<const std::uint8_t, nb::ndim<1>, nb::c_contig> states) {
            if (!self.assign_bonds(std::vector<std::uint8_t>(states.data(), states.data() + states.size())))
              throw InputError("assign_bonds: one byte per bond copy of the model is needed");
          },
          "states"_a, "Every bond copy's state, one byte each in the model's bond order.")
      .def(
          "broken_bond_copies",
          [](const Simulation& self, index_t first, index_t last) {
            if (first > last || last > self.model().node_count())
              throw InputError("broken_bond_copies: nodes out of range");
            return self.state().bonds.broken(self.model().bond_offsets(), first, last);
          },
          "first"_a, "last"_a, "The broken bond copies (two per bond) of nodes first .. last-1.")
      .def(
          "intact_bond_copies",
          [](const Simulation& self, nb::ndarray<const std::int64_t, nb::ndim<1>, nb::c_contig> nodes) {
            const auto& offsets = self.model().bond_offsets();
            return copy_out(per_node(self, nodes.data(), nodes.shape(0), "intact_bond_copies",
                                     [&](index_t i) { return self.state().bonds.intact_count(offsets, i); }));
          },
          "nodes"_a, "Each of these nodes' intact bond copies.")
      .def(
          "contact_list_entries",
          [](const Simulation& self, nb::ndarray<const std::int64_t, nb::ndim<1>, nb::c_contig> nodes) {
            const auto& pairs = self.contact().pair_offsets();
            const auto& walls = self.contact().wall_offsets();
            const auto span = [](const std::vector<index_t>& offsets, index_t i) {
              return offsets.empty() ? index_t{0} : offsets[i + 1] - offsets[i];
            };
            return copy_out(per_node(self, nodes.data(), nodes.shape(0), "contact_list_entries",
                                     [&](index_t i) { return span(pairs, i) + span(walls, i); }));
          },
          "nodes"_a,
          "Each of these nodes' entries in the contact lists of their last build: node pairs and "
          "wall surfaces (0 before the first).")
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

}  // namespace

void bind_simulation(nb::module_& m) {
  nb::class_<PhaseTimes>(m, "PhaseTimes")
      .def_ro("peridynamics", &PhaseTimes::peridynamics)
      .def_ro("contact", &PhaseTimes::contact)
      .def_ro("contact_search", &PhaseTimes::contact_search)
      .def_ro("integration", &PhaseTimes::integration)
      .def_ro("loading", &PhaseTimes::loading);

  nb::class_<Simulation> simulation(m, "Simulation");
  bind_run_setup(simulation);
  bind_loading(simulation);
  bind_results(simulation);
  bind_state(simulation);
}

}  // namespace granulate::bindings
