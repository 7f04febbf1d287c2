// The time loop: velocity Verlet over the net force of peridynamics, body force and loading.
#pragma once

#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "granulate/contact/contact_model.hpp"
#include "granulate/contact/peridem_damping.hpp"
#include "granulate/loading.hpp"
#include "granulate/model.hpp"
#include "granulate/state.hpp"

namespace granulate {

/// Wall-clock seconds spent in each phase of the step loop.
struct PhaseTimes {
  double peridynamics = 0;
  double contact = 0;         ///< all contact work, including the search
  double contact_search = 0;  ///< neighbour-list checks and rebuilds (part of contact)
  double integration = 0;
  double loading = 0;
};

class Simulation {
 public:
  /// Finalizes the model if needed; the state starts at rest in the reference configuration.
  explicit Simulation(std::shared_ptr<Model> model);

  const Model& model() const { return *model_; }
  State& state() { return state_; }
  const State& state() const { return state_; }

  /// Time step [s]; by default safety 0.8 times the stable estimate.
  real time_step() const { return time_step_; }
  void set_time_step(real dt);
  /// Stable estimate combining peridynamics and contact: 1/dt^2 = 1/dt_pd^2 + 1/dt_contact^2.
  real stable_time_step() const {
    return combined_time_step(stable_time_step_, contact_.stable_time_step(*model_));
  }
  /// The peridynamic part of it alone (Model::stable_time_step) [s].
  real peridynamic_stable_time_step() const { return stable_time_step_; }
  /// 1 / sqrt(1/dt_pd^2 + 1/dt_contact^2) [s]; dt_pd when there is no contact (infinite).
  static real combined_time_step(real peridynamic, real contact) {
    if (!std::isfinite(contact)) return peridynamic;
    return 1.0 / std::sqrt(1.0 / (peridynamic * peridynamic) + 1.0 / (contact * contact));
  }

  /// Uniform body acceleration g (gravity) [m/s^2]: adds rho g to every node's force density.
  void set_body_acceleration(const std::array<real, 3>& g);
  /// Background viscous damping gamma [1/s]: adds -gamma rho v to every node's force density.
  /// Off (0) by default; for quasi-static settling, not for dynamics (it damps rigid motion too).
  void set_viscous_damping(real gamma);
  real viscous_damping() const { return viscous_damping_; }
  void add_prescribed_motion(PrescribedMotion motion);
  void add_nodal_force(NodalForce force);
  /// Contact laws, walls and neighbour lists (configured for the model's materials).
  ContactModel& contact() { return contact_; }
  /// PeriDEM's centre damping (comparisons only; see contact/peridem_damping.hpp).
  void set_peridem_damping(std::vector<contact::PeridemParticle> particles,
                           std::vector<contact::PeridemPair> pairs) {
    peridem_damping_.configure(*model_, std::move(particles), std::move(pairs));
    forces_current_ = false;
  }
  const ContactModel& contact() const { return contact_; }

  /// Advances n steps of velocity Verlet:
  ///   v += dt/2 f/rho; x += dt v; prescribed motion; f = F(x); v += dt/2 f/rho; prescribed v.
  /// Throws InstabilityError if positions become non-finite or a node moves more than its
  /// mesh size in one step.
  void run(std::uint64_t steps);
  /// One step of run in two halves, for a distributed run whose ghosts' bonds other processes
  /// evaluate. begin_step: the first half kick, the drift, prescribed motion and pass 1 of the
  /// bonds (stretch and breaking; ghost particles skipped); returns the bonds it broke, (i, j)
  /// node pairs, which the owners send to the processes holding their particles as ghosts.
  /// finish_step(ghost_breaks): breaks the ghosts' bonds their owners broke in this step, then
  /// the rest of the step as run takes it (InputError, with nothing changed, for a pair that is
  /// not an intact bond of a ghost particle; each bond once). The forces must be evaluated
  /// before ghosts are marked; run and begin_step refuse to start while a step is begun.
  std::vector<std::array<index_t, 2>> begin_step();
  void finish_step(std::span<const std::array<index_t, 2>> ghost_breaks);
  /// Between begin_step and finish_step: the LPS pressures and each own node's body force, then
  /// pass 2 of the inner bond blocks up to `share` (0 to 1) of them in schedule order,
  /// continuing from where the last call stopped; finish_step takes what is left (the halo's
  /// pressures, the outer blocks). None of it reads a ghost, the halo or anything other
  /// processes send in the step (the ghosts' bonds are skipped), so a distributed run
  /// evaluates it while that step's exchange is under way, in parts with the MPI progressed in
  /// between; the forces are the same bits however the blocks are split.
  void evaluate_bonds(real share = 1);
  /// The first half kick, the drift and prescribed motion of a step, which begin_step then
  /// continues from (pass 1) instead of taking them itself: a run with foreign nodes gives
  /// them their owners' positions in between (set_foreign_nodes).
  void move();
  /// Between move and begin_step: pass 1 of the inner bond blocks (those that read nothing of
  /// the halo; with no foreign node, every block) up to `share` (0 to 1) of them in schedule
  /// order, continuing from where the last call stopped; begin_step takes the rest. A run with
  /// foreign nodes evaluates them while the halo's positions travel, in parts with the MPI
  /// progressed in between; each node's sums are the same bits however the blocks are split.
  void evaluate_dilatation(real share = 1);

  /// Recomputes forces (and breaks bonds) at the current positions.
  void compute_forces();

  // Diagnostics (computed on demand; sums in a fixed order, so identical for any thread count).
  real strain_energy() const;  ///< sum W_i V_i in node order [J; J/m in 2D]
  real contact_energy() const { return contact_.spring_energy(*model_, state_); }  ///< [J; J/m]
  /// W_i per node [J/m^3, also in 2D]: LPS and PMB energy densities (see the evaluators); 0
  /// on ghost particles (set_ghost_particles: their owners measure them).
  void strain_energy_density(real* out) const;
  /// phi_i = 1 - (intact weighted volume)/(initial weighted volume); z_i = max_j |s_ij| / s0;
  /// 0 on ghost particles. z may be null: phi alone reads only the bond states (no stretch).
  void damage(real* phi, real* z) const;
  std::uint64_t broken_bonds() const;  ///< broken bonds, each counted once
  /// A count that changes whenever a bond state does (bonds broken in a step, also a ghost's,
  /// or by hand; states restored or assigned): what reads only the bond states (phi, the
  /// fragments) is the same while it is.
  std::uint64_t bond_changes() const { return bond_changes_; }
  /// Replaces every bond copy's state (one byte each, in the model's bond order, as checkpoints
  /// hold them); false when the count does not match. Rank 0 of a distributed run takes the
  /// ranks' bonds this way (granulate.parallel.whole_state).
  bool assign_bonds(const std::vector<std::uint8_t>& states);
  /// The bonds' force densities alone at the current state [N/m^3, nodes x 3]: pass 2 of the
  /// last force evaluation again, without body forces, damping, contact and loads (zero before
  /// any evaluation; zero on ghost particles, see set_ghost_particles). For particle stresses
  /// from internal forces.
  std::vector<real> bond_force_densities() const;
  /// Breaks the bonds between the given node pairs (both copies; pre-cracks, notches). Pairs
  /// that are not bonded are an InputError; already broken ones are left as they are.
  void break_bonds(const std::vector<std::array<index_t, 2>>& pairs);
  /// Fragments: connected components of the graph of intact bonds. Writes each node's label
  /// (the smallest node index of its fragment) and returns the number of fragments.
  index_t fragments(index_t* labels) const;
  /// Model::fragments_among of these nodes in the current bond states.
  void fragments_among(const std::vector<index_t>& nodes, index_t* labels,
                       std::vector<std::array<index_t, 2>>& leaving) const {
    model_->fragments_among(state_.bonds, nodes, labels, leaving);
  }
  /// Bit k set: component k of the node is prescribed.
  std::vector<std::uint8_t> fixity() const;
  const PhaseTimes& phase_times() const { return phase_times_; }
  /// Bytes held by the core: {bond data (shared families + per-bond state), everything else
  /// (per-node model and state arrays, contact lists)}, from the arrays' capacities.
  std::array<std::size_t, 2> memory_bytes() const;

  /// Continues a run bit for bit from a checkpoint: the state (with the forces of its last
  /// step) and the contact model's history. The model, loading and walls must be the ones the
  /// checkpoint was taken with (the caller checks; sizes are checked here).
  void restore(const State& state, const ContactCheckpoint& contact);
  /// Lists every node's contact partners again now (ContactModel::search); the forces of the
  /// last step stay. For a distributed run, whose ranks re-list the grains they receive.
  void search_contacts() { contact_.search(*model_, state_, broken_bond_copies_); }
  /// Marks the particles whose bonds and forces another process evaluates (a distributed run's
  /// ghosts; the rest are not): both bond passes skip them, and their bonds break only through
  /// finish_step's ghost_breaks (their fragments enter their partners' contact), and the
  /// steps neither move them nor check their stability. Their forces, velocities and
  /// dilatation are then not their own: between begin_step and finish_step the caller gives
  /// the ghost nodes within the contact's reach their owners' positions and velocities and the
  /// ghost bodies their owners' motion (give_ghost_motions), which is all the contact reads of
  /// them; the other ghost nodes stay where they were. InputError for an index out of range.
  void set_ghost_particles(const std::vector<index_t>& particles);
  /// Marks the nodes of this process's particles that other processes own (a particle split at
  /// node level, whose bonds cross processes; empty: none). The steps neither move nor check
  /// them, and the bond passes evaluate of them only their bonds to this process's nodes, so
  /// that each own node takes the serial run's terms in the serial run's order. The caller
  /// gives them their owners' state each step: between move and begin_step the positions of
  /// those bonded to own nodes (the halo, one horizon deep), and between begin_step and
  /// finish_step their dilatation sums (pass 1's sum_j w r e, before finish_step scales it;
  /// LPS only). Their dilatation, forces, breaks and measures here are not their own:
  /// broken_bonds counts the bonds broken whose lower-numbered end is own. InputError for a
  /// node that does not exist or is a ghost particle's, and while contact or PeriDEM's damping
  /// is on (a body's motion, which they read, is not measured across processes yet).
  void set_foreign_nodes(const std::vector<index_t>& nodes);
  /// Between begin_step and finish_step, on the owner: the rigid-body motion (measure_body) of
  /// every fragment of each of `particles` (this process's own) at the state the contact will
  /// see, named by the fragment's smallest node: what a process holding them as ghosts needs of
  /// their bodies (give_ghost_motions). The fragments are those after this step's breaks.
  std::vector<std::pair<index_t, BodyMotion>> fragment_motions(const std::vector<index_t>& particles) const;
  /// Before finish_step, where ghosts are held: their bodies' motions, from fragment_motions
  /// on their owners (node numbers this process's), for the contact of this step, which would
  /// otherwise measure them from the ghost nodes held (ContactModel::give_ghost_motions).
  /// InputError for a node that is not a ghost's.
  void give_ghost_motions(std::vector<std::pair<index_t, BodyMotion>> motions);
  /// On the owner, between begin_step and finish_step: the outward surface normals of `nodes`
  /// as this step's contact reads them (ContactModel::surface_normal_at: sums over their
  /// bonds, after this step's breaks), 3 per node. InputError for a node that does not exist.
  std::vector<real> surface_normals(const std::vector<index_t>& nodes) const;
  /// Before finish_step, where ghosts are held: the surface normals of ghost nodes from their
  /// owners' surface_normals, which this step's contact takes in place of its sums over their
  /// bonds (ContactModel::give_ghost_surface_normals). InputError for a node that is not a
  /// ghost's.
  void give_ghost_surface_normals(std::vector<std::pair<index_t, vec3>> normals);
  /// The numbers error messages give this process's nodes and particles (a distributed run's
  /// part names them as the whole run does): one per node and one per particle; empty, their
  /// own indices. InputError for the wrong sizes.
  void set_reported_numbers(std::vector<index_t> nodes, std::vector<index_t> particles);
  /// The stable time-step estimate [s] error messages quote (a distributed run's part quotes
  /// the whole run's, which its own grains and ghosts do not give); 0: its own.
  void set_reported_stable_time_step(real estimate) { reported_stable_time_step_ = estimate; }
  /// From now on each step measures how far the farthest node (but the ghosts), or where the
  /// contact lists see one of the nodes `watched` (ContactModel::list_position), is from where
  /// it is now [m] (largest_travel), once the step has moved the nodes and taken its bonds'
  /// breaks (its drift, prescribed motion, pass 1 and the anchors its breaks change, in
  /// begin_step): a distributed run's check, before the step's contact, that its ghosts and
  /// caps still hold (it watches the nodes of the grains other ranks hold as ghosts). Off until
  /// called (a serial run measures nothing). InputError for a ghost's node or one that does not
  /// exist.
  void set_travel_origin(std::vector<index_t> watched);
  /// The largest distance of a node, or of a watched node's list position, from the travel origin where
  /// the last step (begun or finished) put them [m] (0 before a step, or with no origin set).
  real largest_travel() const { return largest_travel_; }
  /// Every node's list position now (ContactModel::list_position), n x 3 [m].
  std::vector<real> list_positions() const;
  /// How near two nodes of different bodies must come, as the lists see them, before their
  /// contact reads their surface normals, sums over their bonds [m]
  /// (ContactModel::surface_normal_reach; 0: never).
  real contact_surface_normal_reach() const { return contact_.surface_normal_reach(*model_); }
  /// The nodes whose positions the anchored vectors of `nodes` read now (their anchors:
  /// ContactModel::anchors_of), sorted, each once.
  std::vector<index_t> contact_anchors(const std::vector<index_t>& nodes) const;

 private:
  // The phases of compute_forces, in order.
  /// Pass 1 of the bonds (what evaluate_dilatation left of it): each node's dilatation sum;
  /// bonds past their critical stretch break (both copies), left in breaks_, and contact is
  /// told of them (the anchors they change).
  void sum_dilatation_and_break_bonds();
  /// Within a step: the dilatation sums and breaks_ cleared unless pass 1 has begun, then its
  /// blocks from where the last call stopped up to place `to` (inner_schedule's blocks, then
  /// outer_schedule_'s), the bonds they break appended to breaks_.
  void sum_dilatation_terms(std::int64_t to);
  /// InputError unless every pair is an intact bond of a ghost particle.
  void check_ghost_breaks(std::span<const std::array<index_t, 2>> pairs) const;
  /// The ghosts' bonds their owners broke (both copies), appended to breaks_.
  void break_ghost_bonds(std::span<const std::array<index_t, 2>> pairs);
  /// After pass 1: what evaluate_bonds left of the LPS pressures, body forces and pass 2, the
  /// ghosts' breaks (contact told of them), contact forces and nodal loads.
  void finish_forces(std::span<const std::array<index_t, 2>> ghost_breaks);
  /// The forces at the current state unless they are current (prescribed motion first).
  void evaluate_if_stale();
  /// The halves of a step (begin_step and finish_step without their checks); the first is
  /// move_nodes (the kick, drift and prescribed motion) and then pass 1.
  void move_and_break_bonds();
  void move_nodes();
  void break_bonds_and_measure_travel();
  void finish_step_after_breaks(std::span<const std::array<index_t, 2>> ghost_breaks);
  /// LPS dilatation theta_i and pressure A_i theta_i; each node's force density started with
  /// rho (g - gamma v): of the own nodes (with no foreign node, every node), of the foreign
  /// nodes bonded to own ones (the halo), or of both.
  enum class NodeGroup { own, halo, both };
  void start_node_forces(NodeGroup group);
  /// Adds the bond forces (pass 2) to `forces` (nodes x 3): of the blocks at places [from, to)
  /// of inner_schedule's followed by outer_schedule_'s, or all.
  void add_bond_forces(real* forces, std::int64_t from = 0,
                       std::int64_t to = std::numeric_limits<std::int64_t>::max()) const;
  /// Contact (node pairs, walls, dashpots, friction) and PeriDEM's damping, timed.
  void add_contact_forces();
  /// The nodal force densities f(t) b.
  void add_nodal_forces();
  void apply_prescribed_motion(bool positions_too);
  /// Whether node i belongs to a ghost particle (set_ghost_particles).
  bool ghost_node(index_t i) const { return !ghost_.empty() && ghost_[model_->node_particle()[i]]; }
  /// Whether node i is another process's: a ghost particle's or a foreign node.
  bool others_node(index_t i) const { return !others_.empty() && others_[i]; }
  /// others_ from ghost_ and foreign_.
  void mark_others();
  /// inner_schedule_ and outer_schedule_ from the model's schedule and foreign_.
  void cut_schedule();
  /// broken_bond_copies_ from the bond states: every broken copy, or with foreign nodes twice
  /// the bonds broken whose lower-numbered end is own (each bond once over the processes); and
  /// a change of bond_changes_.
  void count_broken_bond_copies();
  void check_stability() const;
  std::shared_ptr<Model> model_;
  State state_;
  real time_step_ = 0;
  real stable_time_step_ = 0;
  std::array<real, 3> body_acceleration_{0, 0, 0};
  real viscous_damping_ = 0;
  std::vector<PrescribedMotion> motions_;
  std::vector<NodalForce> nodal_forces_;
  std::vector<real> pressure_;         // A_i theta_i of LPS nodes
  std::vector<std::uint8_t> ghost_;    // per particle: 1 if another process evaluates it;
                                       // empty when none is
  std::vector<std::uint8_t> foreign_;  // per node: 0 own, else another process owns it
                                       // (set_foreign_nodes): 1 bonded to an own node,
                                       // far_foreign not
  static constexpr std::uint8_t far_foreign = 2;
  std::vector<std::uint8_t> others_;  // per node: a ghost particle's or foreign; empty if none
  /// With foreign nodes, the blocks of the model's bond schedule that hold a node that is own or
  /// bonded to one, in two schedules, each in the model's colours and order: the inner blocks,
  /// which read no halo node's position or pressure and touch no node that an outer block of an
  /// earlier colour touches, and the outer blocks, the rest. The bond passes walk the inner
  /// blocks, then the outer ones, so each node still takes its terms in the model's order (the
  /// serial run's sums). Without foreign nodes, the inner schedule is the model's and the outer
  /// one is empty.
  BondSchedule inner_schedule_, outer_schedule_;
  const BondSchedule& inner_schedule() const {
    return foreign_.empty() ? model_->bond_schedule() : inner_schedule_;
  }
  std::int64_t inner_block_count() const { return static_cast<std::int64_t>(inner_schedule().blocks.size()); }
  std::int64_t block_count() const {
    return inner_block_count() + static_cast<std::int64_t>(outer_schedule_.blocks.size());
  }
  std::vector<index_t> reported_node_, reported_particle_;  // set_reported_numbers; or empty
  real reported_stable_time_step_ = 0;                      // set_reported_stable_time_step
  std::vector<real> travel_origin_;    // positions largest_travel is measured from; or empty
  std::vector<index_t> list_watched_;  // the nodes whose list positions it is measured for
  std::vector<real> list_origin_;      // and where they were (3 per watched node)
  real largest_travel_ = 0;
  std::vector<std::array<index_t, 2>> breaks_;  // the bonds pass 1 (and the owners) broke
  bool step_begun_ = false;                     // begin_step called, finish_step not yet
  bool moved_ = false;                          // move called, begin_step not yet
  static constexpr std::int64_t pass_not_begun = -1;
  std::int64_t dilatation_blocks_ = pass_not_begun;  // pass 1's blocks done within the step
  std::int64_t blocks_evaluated_ = pass_not_begun;   // pass 2's blocks done within the step
  std::uint64_t broken_bond_copies_ = 0;             // both copies of a broken bond count
  std::uint64_t bond_changes_ = 0;                   // see bond_changes()
  ContactModel contact_;
  contact::PeridemDamping peridem_damping_;
  bool forces_current_ = false;
  bool kinematic_stale_ = false;  // prescribed motions changed: the contact's held bodies
  void update_kinematic_nodes();
  PhaseTimes phase_times_;
};

}  // namespace granulate
