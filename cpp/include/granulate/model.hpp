// The model: everything that does not change in time. Built with add_material/add_particle,
// frozen by finalize(), which builds the bond families and the per-node constants.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "granulate/material.hpp"
#include "granulate/peridynamics/lps.hpp"
#include "granulate/state.hpp"
#include "granulate/surface_anchors.hpp"
#include "granulate/types.hpp"

namespace granulate {

/// A reference shape: nodes (local coordinates) and volumes, discretised once and placed as
/// many particles as wanted (translated, rotated, scaled); its bond families are shared.
struct Shape {
  std::vector<real> positions;  ///< n x 3 [m], local frame (released by Model::finalize)
  std::vector<real> volumes;    ///< n [m^d] (released by Model::finalize)
  real mesh_size = 0;           ///< h [m] of the reference discretisation
  /// Nodes on or just below the shape's surface, n x 3 in the shape's frame: o_a with
  /// n_k . o_a = 1 for the outward normal n_k of every boundary face at a mesh's or grid's
  /// boundary vertex, the unit outward normal for a node of a lattice's or conforming
  /// discretisation's outer layer, zero inside; empty when the shape has none (a mesh without
  /// elements). `surface_depths` (n [m], or empty: all 0) give each such node's depth below the
  /// surface. Turned into `anchors` (see surface_anchors.hpp) and released by Model::finalize.
  std::vector<real> surface_offsets;
  std::vector<real> surface_depths;
  SurfaceAnchors anchors;  ///< where contact centres the surface nodes' spheres
  index_t node_count() const { return static_cast<index_t>(volumes.size()); }  ///< before finalize
};

/// A particle is a contiguous range of nodes: a shape placed with a scale, one material.
struct Particle {
  index_t first_node = 0;
  index_t node_count = 0;
  index_t material = 0;
  real mesh_size = 0;  ///< h [m] = scale x the shape's mesh size
  index_t shape = 0;
  real scale = 1;
  real horizon = 0;           ///< delta [m] of this particle's bonds
  real critical_stretch = 0;  ///< s0 at this horizon (Material::critical_stretch_at)
  index_t family = 0;         ///< shared bond family (see Model::node_bonds)
};

/// Bond families of one shape for one horizon (in shape units) and influence function, in CSR
/// form over the shape's nodes: the bonds of local node a are offsets[a] .. offsets[a+1]-1, each
/// bond stored once per end (a node's whole family, for diagnostics, damage and fragments).
/// The force loops evaluate a bond once, at its lower-numbered end: bonds forward[a] ..
/// offsets[a+1]-1 of node a join it to higher-numbered nodes (neighbors are sorted). Shared by
/// every particle placed from the shape with the same horizon/scale: lengths scale with the
/// particle; the volumes in w_ij = J beta_ij V_j are the particle's own.
struct BondFamilies {
  std::vector<index_t> offsets;    ///< size shape nodes + 1
  std::vector<index_t> forward;    ///< size shape nodes: first bond of a with neighbour > a
  std::vector<index_t> neighbors;  ///< local j, sorted ascending within a family
  /// J(r/delta) beta_ij (influence times partial volume, dimensionless, the same at both ends of
  /// a bond), in single precision (4 bytes of the 16 a bond takes; a relative error of 6e-8 in
  /// a bond's force, none at rest since e = 0).
  std::vector<float> weights;
  std::vector<real> lengths;  ///< r = |X_j - X_i| at scale 1 [m]
  index_t shape = 0;
  real horizon = 0;  ///< in shape units (the material horizon / scale)
  InfluenceKind influence = InfluenceKind::linear;
};

/// The bonds of one node, as seen by the force loops: bond b (0 <= b < count) joins the node to
/// neighbor(b), has reference length length(b) and weight weight(b); its state (intact or not)
/// is State::bonds.intact(node, b), its global number first + b.
struct NodeBonds {
  const index_t* neighbors = nullptr;
  const real* lengths = nullptr;
  const float* weights = nullptr;
  const real* particle_volumes = nullptr;  ///< volumes of the particle's nodes (local index)
  index_t count = 0;
  index_t forward = 0;  ///< bonds forward .. count-1 join this node to higher-numbered nodes
  index_t first_node = 0;
  real length_scale = 1;
  std::size_t first = 0;

  index_t neighbor(index_t b) const { return first_node + neighbors[b]; }
  real length(index_t b) const { return length_scale * lengths[b]; }
  /// J(r/delta) beta_ij: the weight without the neighbour's volume (symmetric in i and j).
  real influence_weight(index_t b) const { return static_cast<real>(weights[b]); }
  /// w_ij = J(r/delta) beta_ij V_j [m^d].
  real weight(index_t b) const { return influence_weight(b) * particle_volumes[neighbors[b]]; }
  /// The bond to node j (global index), or count if there is none.
  index_t find(index_t j) const;
};

/// A particle of more forward bonds than this is cut into ranges of BondSchedule blocks; one of
/// up to this many is evaluated whole, in one block (Model::set_whole_particle_bonds).
inline constexpr std::size_t default_whole_particle_bonds = 16384;

/// The order of the force loops, which evaluate each bond once, at its lower-numbered end, and
/// add the result to both ends. Nodes are cut into blocks of consecutive nodes (small particles
/// whole); a block touches its nodes and their forward neighbours. Blocks that touch a common
/// node get different colours, so the blocks of one colour run in parallel without atomics,
/// and every node receives its terms in the same order for any number of threads. Nodes of a
/// large particle whose numbering is not banded gather instead (particle_gathers): each
/// evaluates all its bonds and writes only its own sums (see Model::build_bond_schedule).
struct BondSchedule {
  std::vector<index_t> block_starts;           ///< blocks + 1 (node numbers)
  std::vector<index_t> colour_offsets;         ///< colours + 1, into `blocks`
  std::vector<index_t> blocks;                 ///< block numbers grouped by colour, ascending in each
  std::vector<std::uint8_t> particle_gathers;  ///< per particle: 1 if its nodes gather
  std::size_t memory_bytes() const {
    return (block_starts.capacity() + colour_offsets.capacity() + blocks.capacity()) * sizeof(index_t) +
           particle_gathers.capacity();
  }
};

class Model {
 public:
  explicit Model(int dimension, PlaneMode plane = PlaneMode::strain);

  /// Registers a material; returns its index. Validates the parameters (InputError).
  index_t add_material(const MaterialParams& params);

  /// Adds a reference shape: positions n x 3 row-major [m] (z = 0 in 2D), volumes n [m^3, or
  /// m^2 per unit thickness in 2D], its mesh size h [m], and optionally the offsets and depths
  /// of the nodes on or below its surface (n x 3 and n, see Shape::surface_offsets). Returns
  /// the shape index.
  index_t add_shape(std::span<const real> positions, std::span<const real> volumes, real mesh_size,
                    std::span<const real> surface_offsets = {}, std::span<const real> surface_depths = {});

  /// Places a shape as a particle: `positions` (n x 3) are the shape's nodes after scaling by
  /// `scale`, rotating and translating (the caller places them; they are checked to be a rigid
  /// placement). Volumes are scale^d times the shape's. `horizon` [m] is the particle's own
  /// (0: the material's), so particles of one material may differ in size and resolution; the
  /// critical stretch follows it as s0 = s0_material sqrt(delta_material / delta), since the
  /// fracture energy per stretch^2 of both force models is proportional to delta.
  /// Returns the particle index.
  index_t add_particle(index_t shape, index_t material, std::span<const real> positions, real scale,
                       real horizon = 0);

  /// Adds a particle of its own (a shape used once): add_shape then add_particle at scale 1.
  index_t add_particle(std::span<const real> positions, std::span<const real> volumes, index_t material,
                       real mesh_size, real horizon = 0);

  /// Builds bond families (cell list, O(nodes)), partial volumes and LPS constants.
  void finalize();

  /// The most forward bonds of a particle evaluated whole (default_whole_particle_bonds); a
  /// larger one is cut into ranges (BondSchedule). A tuning of the bond passes' parallelism,
  /// before finalize(): the bits of the forces depend on it, never on the other particles.
  void set_whole_particle_bonds(std::size_t bonds);
  std::size_t whole_particle_bonds() const { return whole_particle_bonds_; }

  bool finalized() const { return finalized_; }
  int dimension() const { return dimension_; }
  PlaneMode plane() const { return plane_; }
  /// d in the LPS formulas (theta = d/m sum J r e V, e - theta r / d): the dimension, or 3 in
  /// PeriDEM's 2D (PlaneMode::peridem).
  int lps_dimension() const { return plane_ == PlaneMode::peridem ? 3 : dimension_; }
  index_t node_count() const { return static_cast<index_t>(volumes_.size()); }

  const std::vector<Material>& materials() const { return materials_; }
  const std::vector<Particle>& particles() const { return particles_; }
  const std::vector<real>& reference_positions() const { return reference_positions_; }
  const std::vector<real>& volumes() const { return volumes_; }
  const std::vector<index_t>& node_particle() const { return node_particle_; }
  const std::vector<index_t>& node_material() const { return node_material_; }
  /// Node i's mass density rho [kg/m^3], its material's (kept per material, not per node).
  real density(index_t i) const { return materials_[node_material_[i]].params.density; }
  const std::vector<Shape>& shapes() const { return shapes_; }
  /// The anchors of node i if it lies on its shape's surface (see surface_anchors.hpp), else
  /// null; their nodes are local to the particle (add its first node). Valid after finalize().
  const SurfaceAnchor* surface_anchor(index_t i) const {
    const Particle& p = particles_[node_particle_[i]];
    return shapes_[p.shape].anchors.of(i - p.first_node);
  }
  const std::vector<BondFamilies>& families() const { return families_; }
  /// Global bond numbering: the bonds of node i are bond_offsets()[i] .. bond_offsets()[i+1]-1.
  const std::vector<std::size_t>& bond_offsets() const { return bond_offsets_; }
  std::size_t bond_count() const { return bond_offsets_.empty() ? 0 : bond_offsets_.back(); }
  /// The bonds of node i (valid after finalize()).
  NodeBonds node_bonds(index_t i) const {
    const Particle& p = particles_[node_particle_[i]];
    const BondFamilies& f = families_[p.family];
    const index_t a = i - p.first_node;
    NodeBonds b;
    b.neighbors = f.neighbors.data() + f.offsets[a];
    b.lengths = f.lengths.data() + f.offsets[a];
    b.weights = f.weights.data() + f.offsets[a];
    b.particle_volumes = volumes_.data() + p.first_node;
    b.count = f.offsets[a + 1] - f.offsets[a];
    b.forward = f.forward[a] - f.offsets[a];
    b.first_node = p.first_node;
    b.length_scale = p.scale;
    b.first = bond_offsets_[i];
    return b;
  }
  const BondSchedule& bond_schedule() const { return bond_schedule_; }
  /// Per node, for LPS nodes (zero for others; empty when no particle uses LPS).
  const std::vector<lps::NodeCoefficients>& lps_coefficients() const { return lps_coefficients_; }
  /// k_i = d^2 kappa_d / sum_j w_ij r_ij of PMB nodes (0 for LPS nodes; empty when no particle
  /// uses PMB), see pmb.hpp.
  const std::vector<real>& pmb_stiffness() const { return pmb_stiffness_; }

  /// Fragments: connected components of the graph of intact bonds. Writes each node's label,
  /// the smallest node index of its fragment, and returns the number of fragments.
  /// Deterministic (sequential union-find).
  index_t fragments(const BondStates& intact, index_t* labels) const;
  /// The same over the `count` nodes from `first`, whole particles (bonds never leave a
  /// particle): labels[k] for node first + k.
  index_t fragments_in(const BondStates& intact, index_t first, index_t count, index_t* labels) const;
  /// The fragments of the graph of intact bonds among `nodes` (increasing): labels[k], the
  /// smallest of them connected to nodes[k] within them, and, into `leaving`, each intact bond
  /// (nodes[k], j) to a node j not among them, in node and bond order. The pieces of a body
  /// cut across processes: joined through the leaving bonds, they are the whole fragments.
  void fragments_among(const BondStates& intact, const std::vector<index_t>& nodes, index_t* labels,
                       std::vector<std::array<index_t, 2>>& leaving) const;
  /// Node i's bond to node j (its index among i's bonds), or nothing when they are not bonded
  /// (out of range, of different particles, or beyond the horizon).
  std::optional<index_t> bond_between(index_t i, index_t j) const;

  /// Per-node stable time step sqrt(2 rho / sum_j C_ij w_ij), minimised (Silling & Askari
  /// 2005, with the LPS dilatation coupling bounded by Gershgorin) [s].
  real stable_time_step() const;

 private:
  void require_not_finalized(const char* what) const;
  void build_bonds();
  void build_bond_schedule();
  void cut_bond_blocks();     // BondSchedule's blocks and which particles gather
  void colour_bond_blocks();  // their colours (blocks of a colour share no node)
  BondFamilies build_family(index_t shape, real horizon, InfluenceKind influence) const;

  int dimension_;
  PlaneMode plane_;
  bool finalized_ = false;
  std::size_t whole_particle_bonds_ = default_whole_particle_bonds;
  std::vector<Material> materials_;
  std::vector<Shape> shapes_;
  std::vector<Particle> particles_;
  std::vector<real> reference_positions_;
  std::vector<real> volumes_;
  std::vector<index_t> node_particle_;
  std::vector<index_t> node_material_;
  std::vector<BondFamilies> families_;
  std::vector<std::size_t> bond_offsets_;
  BondSchedule bond_schedule_;
  std::vector<lps::NodeCoefficients> lps_coefficients_;
  std::vector<real> pmb_stiffness_;
};

}  // namespace granulate
