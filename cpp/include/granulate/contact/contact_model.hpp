// Contact between nodes of different particles (and unbonded fragments of one particle) and
// between nodes and walls: neighbour lists with a Verlet skin, the contact law of
// contact_law.hpp, damping aggregated per pair of bodies, wall reactions.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "granulate/contact/block_sums.hpp"
#include "granulate/contact/body_motion.hpp"
#include "granulate/contact/body_rotation.hpp"
#include "granulate/contact/collisions.hpp"
#include "granulate/contact/contact_law.hpp"
#include "granulate/contact/ghost_bodies.hpp"
#include "granulate/contact/power_law_damping.hpp"
#include "granulate/contact/surface_centres.hpp"
#include "granulate/contact/surface_law.hpp"
#include "granulate/model.hpp"
#include "granulate/state.hpp"
#include "granulate/walls.hpp"

namespace granulate {

struct ContactStatistics {
  std::uint64_t rebuilds = 0;       ///< neighbour-list builds so far (grid searches)
  std::uint64_t list_updates = 0;   ///< updates after bond breaks (no search)
  std::uint64_t list_entries = 0;   ///< node-pair entries in the current lists (both directions)
  std::uint64_t node_contacts = 0;  ///< node pairs in contact at the last evaluation (once each)
  std::uint64_t wall_contacts = 0;  ///< node-wall contacts at the last evaluation
  /// Deepest overlap so far, over the pair's Rc: a node pair's, or a surface probe's depth under
  /// the other body's surface (PeriDEM's node-pair law not counted): near 1,
  /// nodes are about to pass through each other (the contact layer is too soft for the impacts).
  real deepest_overlap = 0;
  /// The steps at which deepest_overlap first reached 0.5 (the contact layer too soft for the
  /// loads) and 1 (the contact gave way: nodes pass into the other body), meaningful once it
  /// has. These three are checkpointed ("contact_overlaps"), so a distributed run's rebuilt
  /// parts keep them.
  std::uint64_t half_overlap_step = 0, full_overlap_step = 0;
  /// Takes an overlap (over Rc) measured at `step` into deepest_overlap and the steps above.
  void add_overlap(real overlap, std::uint64_t step) {
    if (deepest_overlap < 0.5 && overlap >= 0.5) half_overlap_step = step;
    if (deepest_overlap < 1 && overlap >= 1) full_overlap_step = step;
    deepest_overlap = std::max(deepest_overlap, overlap);
  }
};

/// What a checkpoint needs of the contact model to continue bit for bit: the state the lists
/// were built from (they are rebuilt from it on restore) and the collision history of each
/// pair of bodies.
struct ContactCheckpoint {
  bool built = false;
  std::vector<real> positions_at_build;
  real time_at_build = 0;
  std::uint64_t broken_at_build = 0;
  real skin = -1;
  std::vector<std::array<index_t, 2>> slots;
  std::uint64_t particle_slot_count = 0;
  std::vector<real> slot_approach;
  std::vector<real> slot_normal;  ///< 3 per slot: the collision's last contact normal
  std::vector<real> slot_work;    ///< 3 per slot: the springs' work, force-law exponent, phase
  /// 3 per slot: the rolling rotation of each pair of bodies (empty without rolling resistance).
  std::vector<real> slot_rolling;
  /// 3 per slot: the sideways travel since the bodies last touched (empty in checkpoints
  /// written before it: none).
  std::vector<real> slot_slide;
  std::vector<index_t> pair_offsets, pair_partners;  ///< the lists (updated after bond breaks)
  /// Friction springs: the pool (3 per spring) and each list entry's spring (none: 2^32 - 1).
  std::vector<real> springs;
  std::vector<index_t> pair_springs, wall_springs;
  /// Per node: the overlap its probe opened with (ContactModel::opened_rest_; empty before the
  /// first force evaluation).
  std::vector<real> opened_rest;
  real last_time = 0;
  bool has_last_time = false;
  ContactStatistics statistics;
  std::vector<std::array<real, 6>> wall_reactions;
};

/// The contacts between bodies (particles, or their fragments once bonds break) and between
/// bodies and walls at the last force evaluation, one per pair in contact (ContactModel::network).
/// Contact k is between body a and body b (or wall b): `force` is the whole contact force on a
/// from b (springs, friction, dashpot and the turn of slot_redirects, surface-law probes;
/// rolling-resistance couples and friction couples are moments and not in it), `normal` the
/// unit contact normal from b towards a (force . normal > 0 pushes them apart), `point` the
/// spring-weighted contact point. A body is named by its particle and its smallest node.
struct ContactNetwork {
  std::vector<index_t> particle_a, node_a;  ///< a's particle and smallest node
  std::vector<index_t> particle_b, node_b;  ///< b's, or (wall index, 2^32 - 1) for a wall
  std::vector<std::uint8_t> wall;           ///< 1 where b is a wall
  std::vector<real> point, normal, force;   ///< 3 per contact [m, -, N; N/m in 2D]
};

class ContactModel {
 public:
  /// Sizes the law tables for the model's materials (no contact until laws are set).
  void configure(const Model& model);

  /// Law between nodes of materials a and b (symmetric).
  void set_law(index_t a, index_t b, const contact::Law& law);
  const contact::Law& law(index_t a, index_t b) const { return laws_[a * material_count_ + b]; }
  /// Adds a wall; returns its index. Give each wall a law per material with set_wall_law.
  index_t add_wall(Wall wall, int dimension);
  void set_wall_law(index_t wall, index_t material, const contact::Law& law);
  /// Verlet skin [m]: a node is listed again when it moves more than skin/2 from where it was
  /// listed (with the nodes that moved skin/4, in place; a search when a quarter of the nodes
  /// do, or a wall moves skin/2); bond breaks update the lists in place (needs_search).
  void set_skin(real skin);
  /// Whether moved nodes and the nodes breaks open are listed again in place (the default);
  /// without, every such change is a search, as before in-place relisting (for checks: the
  /// forces are the same either way).
  void set_relisting(bool relisting) { relisting_ = relisting; }
  /// Nodes whose every component is prescribed (1) or not (0): a body made of such nodes moves
  /// as told, so its partner's dashpot uses the partner's own mass. Takes effect at the next
  /// list build.
  void set_kinematic_nodes(std::vector<std::uint8_t> kinematic) {
    node_kinematic_ = std::move(kinematic);
    built_ = false;
    bodies_labelled_ = false;
  }
  real skin() const { return skin_; }
  /// The skin the lists are built with: as set, or half the largest contact radius [m].
  real list_skin() const { return skin_ < 0 ? 0.5 * max_contact_radius_ : skin_; }
  /// The largest pair_reach any two nodes can have [m] (the lists' cutoff less the skin).
  real largest_pair_reach(const Model& model) const;
  /// The lists' cutoff [m]: the largest pair reach plus the skin.
  real list_cutoff(const Model& model) const { return largest_pair_reach(model) + list_skin(); }

  bool active() const { return any_law_ || !walls_.empty(); }

  /// Stable time step of the contact springs alone [s]: per particle, sqrt(2 rho / S) with the
  /// Gershgorin bound S = 2 n kn V_j of a node touching n partners (n = 4 in 2D, 6 in 3D) of a
  /// particle as fine or finer (a coarse node meets more fine nodes, but each spring is
  /// kn V_j^2, and their sum per unit volume of the node stays below that), and
  /// S = 2 n kn min(V_i, V_j) against a coarser particle; the maximum over every particle and
  /// wall it has a law with. Infinity without contact.
  real stable_time_step(const Model& model) const { return stable_time_step(model, partners(model)); }
  /// What that estimate reads of a particle that is a partner: its material (this model's
  /// index), side (h, delta, kappa_d) and largest node volume [m^3; m^2 in 2D].
  struct Partner {
    index_t material = 0;
    contact::ContactSide side;
    real largest_volume = 0;
  };
  /// Every particle of the model as a partner, in particle order.
  std::vector<Partner> partners(const Model& model) const;
  /// The estimate for the model's particles against `partners` instead of one another (a
  /// distributed run's part: every particle of the run, so that its particles' estimates are
  /// the whole run's while it builds only its own).
  real stable_time_step(const Model& model, const std::vector<Partner>& partners) const;
  /// Energy stored in the normal contact springs [J; J/m in 2D]: sum of k overlap^2 / 2 over
  /// node pairs (each once) and node-wall points in contact at the state's positions, and of
  /// P^2 / (2 k tau) over the surface probes of the last evaluation: node_contact_terms' energy
  /// summed in node order. The friction springs' energy is not included.
  real spring_energy(const Model& model, const State& state) const;
  /// Per node (arrays of node_count, overwritten): the normal springs' energy of its contacts
  /// (pairs listed at it with a larger partner, its wall points, the probes it makes), the node
  /// pairs in contact at the last evaluation counted at their smaller node (a probe at its
  /// probing node), and its wall contacts. The counts sum to statistics().node_contacts and
  /// wall_contacts; a node's terms depend only on its own pairs, so a distributed run sums the
  /// owners' values in node order to the serial totals (granulate.parallel).
  void node_contact_terms(const Model& model, const State& state, real* energy, std::uint32_t* pairs,
                          std::uint32_t* walls) const;
  const std::vector<Wall>& walls() const { return walls_; }

  /// Adds contact force densities to state.forces at time t; updates wall reactions.
  void add_forces(const Model& model, State& state, std::uint64_t broken_bonds);
  /// Lists every node again at its contact position now (a search, as add_forces makes when
  /// the nodes moved too far), carrying the collisions and friction springs of the pairs the
  /// lists held over to the new lists. No-op without laws or walls.
  void search(const Model& model, const State& state, std::uint64_t broken_bonds);
  /// The node-pair lists: per node (CSR offsets, n + 1; empty before the first build) where its
  /// partners start.
  const std::vector<index_t>& pair_offsets() const { return pair_offsets_; }
  /// The wall lists: per node (CSR offsets, n + 1) its (wall, surface) candidates, in the order
  /// of the checkpoint's wall_springs.
  const std::vector<index_t>& wall_offsets() const { return wall_offsets_; }
  const std::vector<std::array<index_t, 2>>& wall_entries() const { return wall_entry_; }
  /// Bonds (i, j) that broke since the last evaluation: the candidates the next list update
  /// inserts (a pair broken earlier and not inserted then cannot reach its Rc before the next
  /// rebuild; see broken_pairs).
  /// Surface nodes whose anchor bond broke take new anchors, or lose their surface point; those
  /// that lose it count their overlaps from a rest measured anew (opened_rest_) and make the next
  /// contact phase list them again, since their reach grows.
  void bonds_broke(const Model& model, const State& state, std::span<const std::array<index_t, 2>> pairs);

  /// Ghost particles (per particle 1 or 0; empty: none), whose nodes another process moves:
  /// their bodies' motion must be given (give_ghost_motions) wherever they touch a body of this
  /// process, their overlaps are left out of statistics() (their owners count them).
  void set_ghost_particles(std::vector<std::uint8_t> ghost) { ghosts_.set_particles(std::move(ghost)); }
  /// The rigid-body motions of ghost bodies, each named by its smallest node, measured by their
  /// owners at the state of the next evaluation, which uses them in place of its own measure
  /// (the owner holds every node of the body) and drops them. That evaluation raises
  /// std::runtime_error if a ghost body touches a body of this process with no motion given.
  void give_ghost_motions(std::vector<std::pair<index_t, BodyMotion>> motions) {
    ghosts_.give(std::move(motions));
  }
  /// The outward surface normals of ghost nodes (surface_normal_at on their owners, at the
  /// state of the next evaluation), which that evaluation uses in place of its own sums over
  /// their bonds (whose far ends this process need not hold) and drops.
  void give_ghost_surface_normals(std::vector<std::pair<index_t, vec3>> normals) {
    ghosts_.give_normals(std::move(normals));
  }
  /// Node i's outward unit surface normal now, as the contact reads it: the opposite of the
  /// influence-weighted sum of its intact bonds, sum_j w_ij (y_j - y_i); zero when that sum is
  /// under 10 % of sum_j w_ij |x_j - x_i| (inside the body, or a node without bonds).
  vec3 surface_normal_at(const Model& model, const State& state, index_t i) const;
  /// Nodes left out of the lists (per node 1 or 0; empty: none): a distributed run's ghost nodes
  /// outside its caps, which stay where they were and can reach none of its own nodes. Takes
  /// effect at the next evaluation: the nodes whose flag changed are listed again (an inert
  /// node has no entries, a node woken finds its partners), and an inert node's displacement
  /// asks for no search.
  void set_inert_nodes(std::vector<std::uint8_t> inert);
  /// Whether the bodies were labelled with `broken_bonds` bonds broken (and are then current).
  bool bodies_labelled_at(std::uint64_t broken_bonds) const {
    return bodies_labelled_ && broken_at_labelling_ == broken_bonds;
  }
  /// The nodes (in node order) of each body whose smallest node is in [first, end): a particle's
  /// bodies when those are its nodes. Meaningful while bodies_labelled_at the current count.
  std::vector<std::span<const index_t>> bodies_in(index_t first, index_t end) const;

  /// Per wall: force (x, y, z) and torque about its centre (x, y, z) exerted by the particles
  /// [N, N m; per unit thickness in 2D], from the last evaluation.
  const std::vector<std::array<real, 6>>& wall_reactions() const { return wall_reactions_; }
  /// The terms wall_reactions sums, from the last evaluation, for a distributed run to sum
  /// them in the serial order: per wall slot (slots() past particle_slot_count()) the dashpot's
  /// force and torque on the wall and the rolling couple taken from it (9); per wall entry
  /// (wall_entries()) its reaction (6). A wall's reaction is the slots' dashpot terms in slot
  /// order, less their rolling couples in slot order, plus the entries' in entry order.
  const std::vector<std::array<real, 9>>& wall_slot_terms() const { return wall_slot_terms_; }
  const std::vector<std::array<real, 6>>& wall_entry_reactions() const { return wall_entry_reaction_; }
  const std::vector<std::array<index_t, 2>>& slots() const { return slots_; }
  std::size_t particle_slot_count() const { return particle_slot_count_; }
  const ContactStatistics& statistics() const { return statistics_; }
  /// The contacts of the last force evaluation (see ContactNetwork), in slot order: particle
  /// pairs, then particle-wall pairs. `state` must be the state that evaluation saw.
  ContactNetwork network(const Model& model, const State& state) const;
  /// Wall-clock seconds spent checking and rebuilding the neighbour lists.
  double search_seconds() const { return search_seconds_; }
  /// Bytes of the lists and per-entry scratch.
  std::size_t memory_bytes() const;

  /// Set-up checks. The first node (and wall) with a node on the wrong side of a wall surface
  /// (a particle placed outside its container, or inside an obstacle); {node count, 0} if none.
  std::array<index_t, 2> first_wall_penetration(const Model& model, const State& state) const;
  /// The first pair of nodes of different particles (with a contact law between them) closer
  /// than `fraction` times the finer mesh size: overlapping particles; {n, n} if none. Under
  /// the surface law, where touching grains' nodes may meet, a node carrying a surface point
  /// overlaps only where its point lies deeper than that inside the other's surface
  /// (first_surface_overlap).
  std::array<index_t, 2> first_overlap(const Model& model, const State& state, real fraction);

  /// Where the lists see node i now (SurfaceCentres::at_list: its surface point under the
  /// surface law, else its contact centre; the node itself for a node seen at itself, and
  /// before the first evaluation finds the points) [m].
  vec3 list_position(const Model& model, const State& state, index_t i) const {
    return centres_.at_list(model, state, i);
  }
  /// Every node's list position, into x (n x 3) [m].
  void fill_list_positions(const Model& model, const State& state, std::vector<real>& x) const {
    centres_.fill_positions(model, state, x);
  }
  /// How near two nodes of different bodies must come [m], as the lists see them (list
  /// positions, the skin included), before their contact reads their surface normals (each
  /// a sum over the node's intact bonds, pair_surface_normal): the sphere pairs of every law
  /// but PeriDEM's node pairs; under the surface law only those of two nodes seen at
  /// themselves, within Rc. 0 where no law reads them. The bonded neighbours a distributed
  /// run's caps must hold for a node that near.
  real surface_normal_reach(const Model& model) const;
  /// The nodes node i's anchored vector reads now (SurfaceCentres::anchors_of), appended to
  /// `out`.
  void anchors_of(const Model& model, index_t i, std::vector<index_t>& out) const {
    centres_.anchors_of(model, i, out);
  }

  ContactCheckpoint checkpoint() const;
  /// Restores a checkpoint taken with the same model, laws and walls; `state` is the restored
  /// state (its bond states are those the lists were built with).
  void restore(const Model& model, const State& state, const ContactCheckpoint& saved);
  /// InputError unless every array of a checkpoint has the size and range this model and its
  /// walls allow (a file edited or damaged by hand must not crash the core); changes nothing.
  void check_checkpoint(const Model& model, const ContactCheckpoint& saved) const;

 private:
  real largest_displacement(const Model& model, const State& state) const;  ///< since listed [m]
  /// The nodes whose list position lies more than `limit` from where they were listed (sorted).
  std::vector<index_t> nodes_moved_past(const Model& model, const State& state, real limit) const;
  /// Whether the lists must be searched again (true) or can be updated in place (false, with
  /// the nodes to list again in `relist`: those that moved more than half the skin, with those
  /// that moved a quarter, and those the breaks opened or took a surface point from). A search
  /// is needed before the first lists, when a wall moved half the skin, when a relisted node may
  /// reach a particle the search left out, and when so many nodes moved that a search costs
  /// less. `moved`: the largest node displacement since listed (0 when not computed).
  bool needs_search(const Model& model, const State& state, bool broke, real& moved,
                    std::vector<index_t>& relist) const;
  /// Lists are updated in place while at most 1/relist_share of the nodes need listing again.
  static constexpr std::size_t relist_share = 4;
  /// A grid search at positions_at_build_, which the caller fills with every node's contact
  /// position (contact_position); bonds and time from `state`; `finish`: then finish_lists.
  void rebuild(const Model& model, const State& state, std::uint64_t broken_bonds, bool finish = true);
  /// The particles a rebuild searches: per particle, whether another particle's bounding sphere
  /// (or its own broken bonds) and whether a wall is within reach.
  struct NearParticles {
    std::vector<std::uint8_t> particle, wall;
  };
  /// The broad phase of a rebuild: bounding spheres of the particles at positions_at_build_.
  NearParticles near_particles(const Model& model, const State& state, std::uint64_t broken_bonds,
                               real reach) const;
  /// The node-pair lists (pair_offsets_, pair_partner_): a grid search over the nodes that take
  /// part of the particles near another or broken, within each pair's reach plus the skin.
  void search_node_pairs(const Model& model, const State& state, const std::vector<std::uint8_t>& near,
                         real reach);
  /// The node-wall lists (wall_offsets_, wall_entry_): the surfaces within a node's contact
  /// radius, its list offset and the skin, for the nodes of particles near a wall.
  void search_node_walls(const Model& model, const State& state, const std::vector<std::uint8_t>& near);
  /// The wall entries (wall, surface) of node i at its list position and the walls at `time`.
  void list_node_walls(const Model& model, real time, index_t i,
                       std::vector<std::array<index_t, 2>>& out) const;
  /// Whether the search lists node pair (i, j) at squared distance r2 of their list positions:
  /// a law between their materials, not bonded, within the pair's reach plus the skin (the
  /// larger of its reaches within one body and between two, with `either_reach`).
  bool lists_pair(const Model& model, const State& state, index_t i, index_t j, real r2,
                  bool either_reach) const;
  /// The lists changed in place, without a search: the pairs of newly_broken_ inserted
  /// (broken_pairs), and each node of `relist` listed again as a search would list it now, at
  /// its current list position (relisted_pairs; its wall entries too).
  void update_lists(const Model& model, const State& state, std::uint64_t broken_bonds, real moved,
                    const std::vector<index_t>& relist);
  /// The pairs of newly_broken_ that could come within reach before the next search (both
  /// ways); newly_broken_ is emptied.
  std::vector<std::array<index_t, 2>> broken_pairs(const Model& model, const State& state, real moved);
  /// The nodes of newly_broken_ that took no part until now (sorted).
  std::vector<index_t> opened_nodes(const Model& model) const;
  /// The relisted nodes' pairs (both ways) from a grid over the list positions of the nodes
  /// that take part; marks the relisted nodes that take part.
  std::vector<std::array<index_t, 2>> relisted_pairs(const Model& model, const State& state,
                                                     const std::vector<index_t>& relist);
  /// Slots, reduced masses, slot laws and scratch, from the lists and the bodies.
  void finish_lists(const Model& model);
  /// slots_ (pairs of bodies in the lists, sorted, then pairs of a body and a wall, sorted) and
  /// each entry's slot (pair_slot_, wall_slot_).
  void find_slots(const Model& model);
  /// The pairs of bodies (in the new numbering) whose collision is still open in a gap
  /// (approach > 0): their slots stay though no entry names them, so that a collision ends
  /// when the bodies are back where they touched and not when a search drops their entries
  /// (which depends on the Verlet skin: a fragment would collide afresh, with another dashpot).
  struct HeldSlots {
    std::vector<std::array<index_t, 2>> particles, walls;
  };
  HeldSlots held_slots() const;
  /// Each slot's law (slot_law_index_ into resolved_laws_): one per pair of particles, or of a
  /// particle and a wall, however many fragments the particles broke into.
  void resolve_slot_laws();
  /// The collisions in progress carried from `old_slots` (their first `old_particle_slots`
  /// between particles) to the same pairs' new slots; the slots' stiffness reset. A body is
  /// known by its smallest node across a relabelling (fragments are numbered in that order, so
  /// a new fragment renumbers the bodies after it); a fragment that splits off starts afresh.
  void carry_over_collisions(const std::vector<std::array<index_t, 2>>& old_slots,
                             std::size_t old_particle_slots);
  /// The lists and their friction springs as they were before a rebuild.
  struct KeptLists {
    std::vector<index_t> pair_offsets, pair_partner, pair_spring, wall_offsets;
    std::vector<std::array<index_t, 2>> wall_entry;
    std::vector<index_t> wall_spring;
  };
  /// Friction springs of the rebuilt lists from the kept ones (entries in both keep theirs; the
  /// springs of entries that left the lists go back to the pool).
  void carry_over_springs(const KeptLists& kept, index_t node_count);
  /// Gives each entry in contact a spring and takes back those of entries apart (entry order).
  void assign_springs();
  /// The pool holds only the springs entries hold, renumbered in entry order (pair entries,
  /// then wall entries); the free list is empty. The numbering never enters a force.
  void compact_springs();
  // Surface nodes (mesh and grid vertices on the boundary) have their spheres centred one
  // contact radius inside (surface_centres.hpp); contact sees every node at its centre.
  /// Whether particle p's surface nodes are centred (its shape has anchors and no law of its
  /// material is PeriDEM's node-pair law).
  bool centres_particle(const Model& model, index_t p) const;
  /// How deep particle p's surface nodes are centred: its node's contact radius over h/2, from
  /// its material's law with itself, or else its first other law.
  real centring_depth(index_t p) const;
  /// centring_depth of every particle that centres its surface nodes, 0 for the others.
  std::vector<real> centring_depths(const Model& model) const;
  /// Whether particle p meets others under the surface law (a law of its material says so):
  /// then its outer layer's nodes (lattices, conforming discretisations) carry surface points
  /// too; otherwise only a mesh's or grid's boundary vertices are centred.
  bool surface_particle(index_t p) const { return surface_particles_[p] != 0; }
  /// surface_particle of every particle, from the laws (at every law change).
  void find_surface_particles();
  std::vector<std::uint8_t> surface_particles_;
  bool any_surface_ = false;
  /// Where node i's contact sphere is centred (its contact centre), and how fast that point moves.
  vec3 contact_position(const Model& model, const State& state, index_t i) const;
  vec3 contact_velocity(const Model& model, const State& state, index_t i) const;
  /// Whether node i takes part in node-pair contact: every node of a particle that does not use
  /// the surface law, else the surface points and the nodes on crack faces (with a broken
  /// bond): the nodes inside an intact surface never touch another body.
  bool takes_part(const Model& model, const State& state, index_t i) const;
  std::vector<index_t> detached_nodes_;  // surface nodes that lost their point since the last list change
  std::vector<std::uint8_t> inert_;      // per node: left out of the lists (set_inert_nodes); or empty
  std::vector<index_t> changed_inert_;   // nodes whose inert flag changed since the last list change
  bool inert(index_t i) const { return !inert_.empty() && inert_[i]; }
  std::vector<std::uint8_t> taking_part_;    // per node, since the last search or list update
  std::vector<std::uint8_t> near_particle_;  // per particle, searched at the last search
  bool relisting_ = true;                    // set_relisting
  bool all_near_ = false;                    // every particle was searched at the last search
  /// Whether node i carries a point of its body's surface (surface_centres.hpp).
  bool on_surface(const Model& model, index_t i) const { return centres_.anchor(model, i) != nullptr; }
  /// Whether the surface law decides node i's list entry e (i probes j's body's surface, or j
  /// probes i's): two bodies under the surface law, and one of the nodes carries a surface point.
  bool surface_entry(const Model& model, index_t i, std::size_t e) const;
  /// The list cutoff of nodes i and j (without the skin), between their surface points (their
  /// positions where they have none): the surface law's support radius where either carries a
  /// surface point of another body, else the pair's Rc (plus the centres' depths in one body).
  real pair_reach(const Model& model, index_t i, index_t j, bool same_body) const;
  /// How far node i's list position lies out from its contact centre, for a contact radius
  /// `radius` of the node: radius |o_i| for a surface point of a particle under the surface
  /// law (at_list is then the surface point), 0 otherwise.
  real list_offset(const Model& model, index_t i, real radius) const;
  SurfaceCentres centres_;
  std::vector<vec3> anchor_forces_;  // per contact node: the force on its anchored vector A_i

  // Surface contact (contact/surface_law.hpp). A node's list entries whose partners carry
  // surface points of one other body make one probe of that body's surface (a group); the
  // partners see the same entries from their side as targets. Groups are numbered in node
  // order at every list change; their sums and forces are per step.
  static constexpr index_t no_group = ~index_t{0};
  struct ProbeGroup {
    index_t probe = 0;  ///< the probing node
    index_t body = 0;   ///< the body whose surface it probes
    index_t slot = 0;   ///< the slot of the two bodies
  };
  /// Per step: the sums over a touching group's surface points, and what its contact is.
  struct ProbeState {
    index_t group = 0;  ///< the group it measures
    contact::SurfaceGap sums;
    vec3 point{0, 0, 0};         ///< the probe point p (a surface point, or the node)
    real radius = 0;             ///< its contact radius r (0 for a surface point)
    real support = 0;            ///< the target's support radius a
    real stiffness = 0;          ///< k of the probe
    real contact_radius = 0;     ///< Rc of the pair's law (the scale of the deepest overlap)
    real push = 0;               ///< P = k delta tau (> 0: only touching groups are kept)
    real taper = 0;              ///< Q = k delta^2 tau'(S) / 2 (0 on a surface)
    real fade_force = 0;         ///< dE/d|A| of the probe's own point through its fade (0 unless it fades)
    vec3 gradient{0, 0, 0};      ///< G, the surface's normal direction at p (out of the target)
    vec3 friction{0, 0, 0};      ///< the friction force on the probe
    vec3 foot{0, 0, 0};          ///< sum_k (w_k / S) y_k: where the target's nodes take the friction force
    vec3 facing{0, 0, 0};        ///< the points counted face along it (surface_law.hpp: facing_start)
    bool smooth_facing = false;  ///< facing is -n_p, the probe's own normal (shares psi smooth)
    vec3 facing_force{0, 0, 0};  ///< the force on the probe's own A through the shares psi
  };
  std::vector<index_t> entry_group_;  // per pair entry: the group it belongs to as a probe entry
  /// Whether list entry e belongs to a surface probe (none without the surface law).
  bool probe_entry(std::size_t e) const { return !entry_group_.empty() && entry_group_[e] != no_group; }
  std::vector<index_t> entry_target_;  // per pair entry: the group that probes the node's body
  std::vector<ProbeGroup> groups_;
  std::vector<index_t> group_offsets_;  // per node: its groups (CSR)
  /// Node i's groups, [first, last) (none without the surface law).
  std::array<index_t, 2> groups_of(index_t i) const {
    if (group_offsets_.empty()) return {0, 0};
    return {group_offsets_[i], group_offsets_[i + 1]};
  }
  // This step's touching groups, in group order, and each group's index among them (or
  // no_probe): the groups apart, most of them, keep no state.
  static constexpr index_t no_probe = ~index_t{0};
  std::vector<ProbeState> probes_;
  std::vector<index_t> group_probe_;
  /// Group g's state this step, or null where it does not touch.
  const ProbeState* touching_probe(index_t g) const {
    return group_probe_[g] == no_probe ? nullptr : &probes_[group_probe_[g]];
  }
  ProbeState* touching_probe(index_t g) {
    return group_probe_[g] == no_probe ? nullptr : &probes_[group_probe_[g]];
  }
  /// probes_ and group_probe_ from the touching groups each thread measured (any order).
  void keep_touching_probes(std::vector<ProbeState>& measured);
  /// The probe k of a group of node i against body b: beta kn min(V_i, h_b^d)^2 (h_i/h_min)^(d-1),
  /// V_i the stiffness_volume of i, h_b^d the nominal volume of b's nodes (the same for all of
  /// b's points, so k does not jump when the point `target` leaves reach), beta = h_b^2 / (h_i^2
  /// + h_b^2) (the finer surface probes the coarser; equal meshes share the contact equally).
  real probe_stiffness(const Model& model, index_t i, index_t target, const contact::PairLaw& law) const;
  /// Node j's surface point as the surface law sees it (this step's, from measure_surface_points).
  const contact::SurfacePoint& surface_point(index_t j) const;
  void measure_surface_points(const Model& model, const State& state);
  std::vector<index_t> surface_nodes_, surface_slot_;  // nodes with entries and surface points; per node
  std::vector<contact::SurfacePoint> surface_points_;  // per step, per surface node
  std::vector<real> surface_sizes_;                    // |A| of each, per step
  std::vector<float> surface_stretches_;               // |A| / |A_0| of each, per step
  /// The fade phi of node j's surface point this step (contact/surface_law.hpp).
  real surface_fade_of(index_t j) const {
    return contact::surface_fade(surface_stretches_[surface_slot_[j]]);
  }
  /// Groups from the lists and the bodies (after every list change).
  void find_groups(const Model& model);
  /// The group of the probe j whose target body holds node i (the entry (j, i)), or no_group.
  index_t target_group(index_t i, index_t j) const;
  /// Pass A for node i's groups: the sums, the gap, the push, and its probe entries' springs;
  /// the touching groups' states go to scratch.touching.
  struct ProbeScratch {  // per thread: per entry of the node, and per group
    std::vector<const contact::SurfacePoint*> points;
    std::vector<real> weights, nearest;
    std::vector<ProbeState> states;    // the node's groups
    std::vector<ProbeState> touching;  // every node's touching groups, kept for the step
  };
  /// `pair_overlap` (>= 0): the deepest overlap of node i's sphere pairs under the surface law,
  /// which its rest covers too.
  real measure_probes(const Model& model, const State& state, index_t i, ProbeScratch& scratch,
                      real pair_overlap);
  /// The rest overlap of node i's contact-sphere probe and sphere pairs this step (below), from
  /// the deepest overlap `deepest` (>= 0) of its groups and pairs: set to it on the first
  /// measure, then never above it.
  real settle_opened_rest(index_t i, real deepest);
  /// Per node, the overlap its contact-sphere probe and its sphere pairs under the surface law
  /// (a node without a surface point: on a crack face, detached, or of a particle without
  /// surface points) count from, or -1 before its first measure (a particle set down inside
  /// another's contact layer gets no push out of it either; one that comes into reach gets 0).
  /// A crack can open a node already inside the contact layer of a body pressed against its
  /// grain, or inside the sphere of a node of that body which has no surface point either (a
  /// crack face of its own), or of the node across the bond that broke; counting its overlaps
  /// from there, a rest that only falls with them (so it changes only where it pushes nothing),
  /// gives it no push out of nothing: opening a node adds no energy. A sphere pair counts from
  /// the larger rest of its two nodes (pair_rest).
  std::vector<real> opened_rest_;
  /// The rest a sphere pair of nodes i and j under `law` counts its overlap from: the larger of
  /// their rests under the surface law (0 for a node without one), else 0.
  real pair_rest(index_t i, index_t j, const contact::PairLaw& law) const {
    if (!law.surface || opened_rest_.empty()) return 0;
    return std::max({real{0}, opened_rest_[i], opened_rest_[j]});
  }
  /// Clears the in-contact flags of the sphere pairs under the surface law of `nodes` (those
  /// with such a pair within its contact radius) that do not reach past their rest; the others
  /// count in the deepest overlap.
  void release_rested_pairs(const Model& model, const State& state, const std::vector<index_t>& nodes);
  /// The force on the own A of node i's touching probe of group g through its smooth facing.
  vec3 facing_force(index_t i, index_t g, const ProbeState& probe, index_t first, index_t last) const;
  /// phi_k w_k / S of node j's surface point in a group's sums (0 if it does not face the probe).
  real surface_share(const ProbeState& probe, index_t j) const;
  /// Friction of every touching group (updates its entries' springs), per probing node in
  /// parallel, after pass B.
  void probe_frictions(const Model& model, const State& state, real dt);
  /// Friction of node i's touching groups: each probe entry's spring (Cundall-Strack, on the
  /// slip of the probe point against the target's surface velocity there, sum_k (w_k / S)
  /// v(s_k)), weighted by w_k / S; and the foot f = sum_k (w_k / S) y_k (`shares`: scratch,
  /// per entry of the node).
  void probe_friction(const Model& model, const State& state, index_t i, real dt, std::vector<real>& shares);
  /// The force on a target's surface point (`point`, with |A| = `size` and |A| / |A_0| =
  /// `stretch`) from a touching probe, and the force on its anchored vector A.
  void target_forces(const contact::SurfacePoint& point, real size, real stretch, const ProbeState& probe,
                     vec3& on_point, vec3& on_normal, vec3& on_friction) const;

  /// Nodes with list entries, grouped by body (each group in node order), and the per-step
  /// scratch of bodies and slots.
  void group_contact_nodes(const Model& model);
  /// Bodies for the dashpots: particles while whole, fragments (connected components of intact
  /// bonds) once bonds break; labelled again at a list build or update when bonds broke since
  /// (bonds never heal, so the count tells) or the held nodes changed.
  void label_bodies(const Model& model, const State& state, std::uint64_t broken_bonds);

  // The passes of add_forces, in order (see there).
  void measure_contacts(const Model& model, const State& state);
  void sum_slot_stiffness();
  /// The touching bodies and the slots in contact this step (after sum_slot_stiffness).
  void find_touching();
  void measure_bodies(const Model& model, const State& state);
  /// std::runtime_error if a ghost body whose motion was not given touches one of this
  /// process's bodies (`measured`: per touching body, 1 where its motion was measured here).
  void check_ghost_motions(const std::vector<std::uint8_t>& measured) const;
  void sum_slot_springs(const Model& model, const State& state);
  void sum_probe_springs();
  /// Adds node i's spring (force, normal, contact point, surface normal) to a slot in contact
  /// (the sums of its index among them).
  void add_slot_spring(std::size_t slot, index_t i, real spring, const vec3& normal, const vec3& point,
                       const vec3& surface);
  void slot_dashpots(const State& state, real dt);
  void slot_rolling_resistance(const State& state, real dt);
  /// Whether a slot's bodies resist rolling this step: a law with mu_r > 0, two bodies (or a
  /// body and a wall) in contact, each able to turn (rotational inertia).
  bool resists_rolling(std::size_t slot) const;
  /// Whether a slot's bodies are in contact this step: springs loaded, surface normals summed.
  bool slot_in_contact(std::size_t slot) const;
  /// The rolling torque on a resisting slot's first body (advances its rolling rotation).
  vec3 slot_rolling_torque(const State& state, std::size_t slot, real dt);
  /// A touching body's moment of inertia for rolling about `axis` (unit) through the contact
  /// point, at `lever` from its centre [kg m^2; per unit thickness in 2D].
  real rolling_inertia(index_t body, const BodyMotion& motion, const vec3& axis, real lever) const;
  void slot_redirects();
  /// The spring-weighted contact point of a slot in contact (its index among them).
  vec3 slot_contact_point(index_t touch) const;
  /// Velocity of a point moving with a touching body's rigid-body motion.
  vec3 rigid_velocity(index_t body, const vec3& point) const;
  /// A force at a point of a touching body, as a rigid-body load.
  void add_body_load(index_t body, const vec3& point, const vec3& force);
  /// The contact normal of node pair (i, j) from the two surfaces' normals (from i to j), or
  /// `line`, the direction of the nodes, where either node has no surface normal.
  vec3 pair_surface_normal(index_t i, index_t j, const vec3& line) const;
  void measure_surface_normals(const Model& model, const State& state);
  void node_forces(const Model& model, State& state, real dt);
  /// A contact node's forces (N): on its contact centre, on its surface point, on the node
  /// itself (friction) and on its anchored vector A.
  struct NodeContactForces {
    vec3 at_centre{0, 0, 0}, at_surface{0, 0, 0}, at_node{0, 0, 0}, on_vector{0, 0, 0};
  };
  /// Node i's contact forces from its pair, wall and probe entries and, when it is `anchored`
  /// (carries a surface point), as other bodies' probe target; advances its friction springs
  /// and sets its wall entries' reactions.
  NodeContactForces gather_node_forces(const Model& model, State& state, index_t i, bool anchored, real dt);
  /// The force on an anchored node's vector A: `forces.on_vector` and the levers of the forces
  /// on its centre and surface point (both lie on its normal).
  vec3 anchored_vector_force(const Model& model, const State& state, index_t i,
                             const NodeContactForces& forces) const;
  /// Each anchored contact node's vector force to its anchors, w_k each (node order).
  void spread_anchor_forces(const Model& model, State& state) const;
  /// The friction couples of the surface probes, as loads on their bodies (in group order).
  void probe_couples(const State& state);
  void body_loads(const Model& model, State& state);
  void sum_wall_reactions();
  /// A node pair in contact: i's contact centre x_i, the normal from i to j, the overlap, and the
  /// levers of the contact point p = x_i + lever_i n = x_j - lever_j n (the middle of the overlap).
  struct PairGeometry {
    vec3 centre_i{0, 0, 0};
    vec3 normal{0, 0, 0};
    real overlap = 0, lever_i = 0, lever_j = 0;
  };
  PairGeometry pair_geometry(const Model& model, const State& state, index_t i, index_t e) const;
  /// Spring stiffness k of node i's list entry e in double precision (pair_stiffness_ keeps it
  /// in single precision, as the in-contact flag and for the sums of pass B).
  real entry_stiffness(const Model& model, index_t i, index_t e) const;
  /// Spring stiffness of each contact point of node i's wall entry e: kn V_i^2 (V_i its
  /// stiffness_volume).
  real wall_spring_stiffness(const Model& model, index_t i, index_t e) const;
  /// The volume node i stands for in a contact spring [m^d]: sqrt(V_i h^d) under the surface
  /// law, so that a spring kn min(V_i, V_j)^2 is kn V_i h^d between equal particles, in
  /// proportion to the node's mass (every node rings on its contact at a lattice's frequency,
  /// so the time step that suits a lattice suits any mesh), where kn V_i^2 made a mesh's
  /// boundary vertices, which hold 0.3-0.5 h^d, 4-5 times softer per area than a lattice's
  /// surface; its own V_i under the node spheres and PeriDEM's law.
  real stiffness_volume(const Model& model, index_t i) const;
  /// The collisions of a checkpoint's slots (slots_ restored).
  void restore_collisions(const ContactCheckpoint& saved);
  /// Damping ratio of a slot in contact that gives the requested restitution for the force law
  /// of its collision, after adding the springs' work over `advance` (the approach this step).
  real damping_ratio(std::size_t slot, contact::Collision& collision, real advance);
  /// Adds a gap step's sideways travel (`relative`: the bodies' relative velocity at the
  /// contact) to the collision's; whether it now exceeds the contact radius, which ends it.
  bool slid_apart(std::size_t slot, contact::Collision& collision, const vec3& relative, real dt) const;
  /// Force on node i of its list entry e (updates the entry's friction spring).
  vec3 pair_force(const Model& model, const State& state, index_t i, index_t e, real dt);
  /// PeriDEM's friction on node i of entry e: mu |push| against the tangential relative velocity.
  vec3 peridem_pair_friction(const contact::Law& law, real push, const vec3& relative,
                             const vec3& normal) const;
  /// The force pair_force gave node i of entry e in the last evaluation, from the springs as it
  /// left them (F_t = -kt xi), without the fragment dashpot (entries between two bodies only).
  vec3 evaluated_pair_force(const Model& model, const State& state, index_t i, index_t e) const;
  /// A node-wall entry in contact: the deepest point's normal (towards the node), its contact
  /// point p and the spring stiffness (kn V_i^2; times the weights' sum on a round particle).
  struct WallGeometry {
    vec3 normal{0, 0, 0}, point{0, 0, 0};
    real stiffness = 0;
  };
  /// The two spheres through which node i's wall entry e sees the wall: [0] its contact sphere
  /// (centre c_i, radius rho), [1] its osculating sphere (centre o_i, radius 1 / kappa, as
  /// measure_wall_points found them; unset off a round particle).
  struct WallSpheres {
    std::array<vec3, 2> centre{};
    std::array<real, 2> radius{0, 0};
  };
  WallSpheres wall_spheres(const Model& model, const State& state, index_t i, index_t e) const;
  WallGeometry wall_geometry(const Model& model, index_t i, index_t e, const WallSpheres& spheres) const;
  /// Node i's wall entry e's points, measured (wall_points_[e]) from its contact sphere or, on a
  /// round particle and a wall of planes, boxes or circles, from its osculating sphere.
  void measure_wall_points(const Model& model, const State& state, index_t i, index_t e, const vec3& centre,
                           std::vector<WallContact>& found);
  /// The bodies of round particles with wall entries (rotated_bodies_), at every list change.
  void find_rotated_bodies(const Model& model);
  /// The rotation R of each of those bodies (body_rotation.hpp), per step.
  void measure_body_rotations(const Model& model, const State& state);
  /// The unit normal n of a round particle's node i that places its osculating sphere: R n_0,
  /// its reference normal turned with its body, or A_i / |A_i| if the body has no rotation.
  /// Through R the spheres have a potential whose derivative is a couple on the body.
  vec3 osculating_normal(const Model& model, const State& state, const SurfaceCentres::Seen& seen,
                         index_t i) const;
  /// Forces of node i's wall entry e: the springs on its sphere's centre, friction on the node
  /// (updates the spring; sets the entry's reaction), added to `forces`.
  void wall_force(const Model& model, const State& state, index_t i, index_t e, real dt,
                  NodeContactForces& forces);
  /// Sum of (p - c_i) x F_t over node i's friction forces, from the springs, and its
  /// osculating wall entries' couples (osculating_couple): loads on its body.
  vec3 contact_couple(const Model& model, const State& state, index_t i) const;
  /// Minus the derivative of node i's wall entry e's energy for a rotation of its body, which
  /// turns its osculating sphere about y_i: (o - y_i) x F of the springs F, plus the turn of
  /// their weights and of the contact sphere's rest.
  vec3 osculating_couple(const Model& model, const State& state, index_t i, index_t e) const;
  /// Whether nodes i and j have a contact law between them.
  bool interact(const Model& model, index_t i, index_t j) const;
  /// Whether first_overlap leaves nodes i and j to first_surface_overlap: both particles are
  /// under the surface law and one of the nodes carries a surface point.
  bool between_surfaces(const Model& model, index_t i, index_t j) const;
  /// The first surface point lying deeper than `fraction` h inside another particle's surface,
  /// and that particle's nearest surface point lying as deep inside the first's.
  std::array<index_t, 2> first_surface_overlap(const Model& model, const State& state, real fraction) const;
  /// Node j's surface point at the state's positions (normal A / |A|, position y + d phi n,
  /// curvature), and |A| into `size`; `seen` is j's (SurfaceCentres::seen).
  static contact::SurfacePoint surface_point_now(const SurfaceCentres::Seen& seen, const State& state,
                                                 index_t j, real& size);
  /// How deep surface node probe's surface point lies inside surface node node's osculating
  /// sphere [m] (negative outside).
  real depth_inside(const Model& model, const State& state, index_t probe, index_t node) const;
  /// Contact radius of node i in a contact of law `law` with node j (its share of the pair's Rc).
  real node_radius(const contact::Law& law, const Model& model, index_t i, index_t j,
                   real contact_radius) const;

  /// Rc and kn of the pair of particles p, q (resolve() of their materials' law).
  contact::PairLaw pair_law(index_t p, index_t q) const;
  contact::PairLaw wall_law(index_t wall, index_t p) const;

  index_t material_count_ = 0;
  std::vector<contact::ContactSide> particle_side_;  // h, delta, kappa_d of each particle
  std::vector<index_t> particle_material_;
  std::vector<real> material_max_mesh_size_;
  std::vector<contact::Law> laws_;  // material x material
  std::vector<std::uint8_t> law_set_;
  bool any_law_ = false;
  real max_contact_radius_ = 0;
  std::vector<Wall> walls_;
  std::vector<contact::Law> wall_laws_;  // wall x material
  std::vector<std::uint8_t> wall_law_set_;
  real skin_ = -1;                             // < 0: 0.5 x the largest contact radius
  std::vector<index_t> node_body_;             // body of each node
  std::vector<real> body_mass_;                // a splittable particle's bodies' order-free (body_sums.hpp)
  std::vector<std::uint8_t> body_splittable_;  // per body: of a splittable particle
  std::vector<std::uint8_t> node_kinematic_;   // empty: none
  std::vector<std::uint8_t> body_kinematic_;   // every node of the body kinematic
  std::vector<index_t> body_material_;
  std::vector<index_t> body_particle_;
  std::vector<index_t> body_node_offsets_, body_nodes_;  // CSR: nodes of each body
  bool bodies_labelled_ = false;
  std::uint64_t broken_at_labelling_ = 0;
  // Each body's smallest node under the labelling the slots were found with, kept from a
  // relabelling to the next carry_over_collisions (empty: the body numbers did not change).
  std::vector<index_t> relabelled_first_node_;
  /// Each body's smallest node (bodies list their nodes in node order).
  std::vector<index_t> body_first_nodes() const;
  int dimension_ = 3;

  // Lists (rebuilt): node pairs and node-wall-surface candidates, CSR by node.
  bool built_ = false;
  // Every node's list position when it was last listed (n x 3; at the search, or at an update
  // that listed it again), in single precision: the lists and the rebuild test
  // (largest_displacement) both measure from these stored values, so nodes that have moved less
  // than half the skin from them still find every partner within reach.
  std::vector<float> positions_at_build_;
  real time_at_build_ = 0;
  std::uint64_t broken_at_build_ = 0;
  std::vector<std::array<index_t, 2>> newly_broken_;  // bonds broken since the last list change
  std::vector<index_t> pair_offsets_, pair_partner_, pair_slot_;
  std::vector<index_t> wall_offsets_;
  std::vector<std::array<index_t, 2>> wall_entry_;  // (wall, surface)
  std::vector<index_t> wall_slot_;
  // Bodies in contact: one slot per (particle, particle) or (particle, wall) pair in the lists.
  std::vector<std::array<index_t, 2>> slots_;  // particle pairs (p <= q), then (p, wall)
  std::size_t particle_slot_count_ = 0;
  /// Reduced mass of a slot's bodies (particles, or fragments once bonds break): two bodies
  /// m_p m_q / (m_p + m_q); unbonded nodes of one body (a crack that has not separated it),
  /// about m_p / 4; a body and a rigid wall, or a body whose every node is prescribed (a held
  /// particle, a meshed wall), the moving body's mass; two such bodies, 0 (no dashpot) [kg].
  real slot_reduced_mass(std::size_t slot) const;
  std::vector<index_t> slot_law_index_;          // Rc and kn of each slot's pair of bodies:
  std::vector<contact::PairLaw> resolved_laws_;  // an index into the laws of particle pairs
  const contact::PairLaw& slot_law(std::size_t slot) const { return resolved_laws_[slot_law_index_[slot]]; }
  std::vector<real> slot_stiffness_;  // K: sum of the contact springs, last evaluation
  // The collisions in progress (collisions.hpp), by slot, kept across list rebuilds: the
  // approach x of the two bodies since they touched (for the secant stiffness F / x of the
  // dashpot), the normal of the last step in contact, the springs' work W since the touch and
  // the force-law exponent p = F x / W - 1 (exact for F = k x^p), measured while the bodies
  // approach, which picks the damping ratio that gives the requested restitution
  // (power_law_damping.hpp), and the rolling rotation theta (contact_law.hpp), used only when
  // some law has mu_r > 0.
  contact::CollisionStore collisions_;
  bool any_rolling_ = false;
  // Damping ratio against the exponent p, per law (as laws_ and wall_laws_).
  std::vector<contact::DampingTable> damping_tables_, wall_damping_tables_;
  // Friction springs (tangential displacement xi) of the entries in contact, in a pool: each
  // entry holds the index of its spring (no_spring when apart), given and taken back in pass B
  // in entry order, carried over by list updates (in their merge) and rebuilds
  // (carry_over_springs).
  static constexpr index_t no_spring = ~index_t{0};
  std::vector<vec3> springs_;
  std::vector<index_t> free_springs_;
  std::vector<index_t> pair_spring_, wall_spring_;
  // Nodes with entries, grouped by body: contact_nodes_[body_contact_offsets_[b] ...].
  std::vector<index_t> contact_nodes_, body_contact_offsets_;
  // Per step: the touching bodies (in a collision, or in a gap of one) and the slots in contact,
  // numbered compactly (fragments can outnumber nodes' neighbours when grains shatter).
  static constexpr index_t not_touching = ~index_t{0};
  std::vector<index_t> body_touch_;  // per body: its index among the touching bodies, or none
  std::vector<index_t> touching_bodies_;
  std::vector<BodyMotion> body_motion_;         // per touching body
  GhostBodies ghosts_;                          // ghost particles and their bodies' motions
  std::vector<std::array<real, 6>> body_load_;  // per touching body: force, torque about the centre
  std::vector<index_t> slot_touch_;             // per slot: its index among the slots in contact
  // The order-free sums (block_sums.hpp) of the slots of a splittable particle's bodies: per slot
  // its stiffness; per slot in contact its spring force, normal, contact point and surface
  // normal sums (as slot_force_ ... below); per touching body of a splittable particle, the
  // couples its contact nodes and the probes put on it.
  BlockSums<1> slot_stiffness_sums_;
  BlockSums<10> slot_spring_sums_;
  BlockSums<3> body_couple_sums_;
  /// Whether a slot's sums are block sums: one of its bodies is a splittable particle's.
  bool slot_splittable(std::size_t slot) const {
    return body_splittable_[slots_[slot][0]] ||
           (slot < particle_slot_count_ && body_splittable_[slots_[slot][1]]);
  }
  std::vector<real> slot_force_;                // per slot in contact: spring force, and the
  std::vector<vec3> slot_normal_, slot_point_;  // spring-weighted normal and contact point sums
  std::vector<vec3> slot_surface_normal_;       // spring-weighted sum of the surfaces' normals
  std::vector<index_t> touching_nodes_;         // nodes in a pair in contact between two bodies, in
  std::vector<vec3> touching_normals_;          // order, and their surface normals (per step)
  // Per slot in contact: the dashpot's and the turn's force on q (on p for a wall slot), for network().
  std::vector<vec3> slot_load_;
  /// Angular velocity of a body (zero if it touches nothing).
  const vec3& body_spin(index_t body) const {
    static constexpr vec3 none{0, 0, 0};
    return body_touch_[body] == not_touching ? none : body_motion_[body_touch_[body]].angular_velocity;
  }
  std::vector<std::array<real, 6>> wall_damping_;     // per wall: the dashpots' and rolling torques' share
  std::vector<std::array<real, 9>> wall_slot_terms_;  // per wall slot: its share (wall_slot_terms)
  real last_time_ = 0;
  bool has_last_time_ = false;
  // Scratch, per entry: the spring stiffness k of the pair in contact, 0 if apart (single
  // precision, 4 bytes: list entries outnumber nodes when grains shatter).
  std::vector<float> pair_stiffness_;
  /// Contact points of a wall entry (at most one per box face), normals in the world frame, of
  /// the node's spheres (WallSpheres), each point's spring weighted by `weights`
  /// (measure_wall_points).
  struct WallPoints {
    std::uint8_t count = 0;
    std::uint8_t osculating = 0;      ///< the first `osculating` points are the osculating sphere's
    real osculating_radius = 0;       ///< r = 1 / kappa [m]
    vec3 osculating_centre{0, 0, 0};  ///< o = s - r n at this step's positions
    std::array<WallContact, 6> points{};
    std::array<real, 6> weights{};
  };
  /// Which sphere of WallSpheres point k of an entry belongs to.
  static int sphere_of(const WallPoints& points, std::size_t k) { return k < points.osculating ? 1 : 0; }
  std::vector<WallPoints> wall_points_;
  // The bodies of round particles with wall entries (listed with the lists), and per listed
  // body its rotation from its reference shape this step and whether it has one
  // (measure_body_rotations); per body its place in that list, or no_rotation (surface law only).
  static constexpr index_t no_rotation = ~index_t{0};
  std::vector<index_t> rotated_bodies_, body_rotation_slot_;
  std::vector<contact::matrix3> body_rotation_;
  std::vector<std::uint8_t> body_rotated_;
  std::vector<real> wall_entry_stiffness_;
  std::vector<std::array<real, 6>> wall_entry_reaction_;
  std::vector<std::array<real, 6>> wall_reactions_;
  ContactStatistics statistics_;
  double search_seconds_ = 0;
};

}  // namespace granulate
