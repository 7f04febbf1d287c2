// The model: everything that does not change in time. Built with add_material/add_particle,
// frozen by finalize(), which builds the bond families and the per-node constants.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "granulate/material.hpp"
#include "granulate/peridynamics/lps.hpp"
#include "granulate/types.hpp"

namespace granulate {

/// A particle is a contiguous range of nodes with one material and one mesh size.
struct Particle {
  index_t first_node = 0;
  index_t node_count = 0;
  index_t material = 0;
  real mesh_size = 0;  ///< h [m], lattice spacing or typical edge length
};

/// Bond families in CSR form: the bonds of node i are offsets[i] .. offsets[i+1]-1, each bond
/// stored once per end (i's copy and j's copy), so force loops gather without atomics.
struct BondFamilies {
  std::vector<index_t> offsets;    ///< size nodes + 1
  std::vector<index_t> neighbors;  ///< j, sorted ascending within a family
  std::vector<real> weights;       ///< w_ij = J(r/delta) V_j beta_ij [m^d]
  std::vector<real> lengths;       ///< r = |X_j - X_i| [m]

  std::size_t size() const { return neighbors.size(); }
};

class Model {
 public:
  explicit Model(int dimension, PlaneMode plane = PlaneMode::strain);

  /// Registers a material; returns its index. Validates the parameters (InputError).
  index_t add_material(const MaterialParams& params);

  /// Adds a particle of n nodes: positions is n x 3 row-major [m] (z = 0 in 2D), volumes n
  /// [m^3, or m^2 per unit thickness in 2D]. Returns the particle index.
  index_t add_particle(std::span<const real> positions, std::span<const real> volumes, index_t material,
                       real mesh_size);

  /// Builds bond families (cell list, O(nodes)), partial volumes and LPS constants.
  void finalize();

  bool finalized() const { return finalized_; }
  int dimension() const { return dimension_; }
  PlaneMode plane() const { return plane_; }
  index_t node_count() const { return static_cast<index_t>(volumes_.size()); }

  const std::vector<Material>& materials() const { return materials_; }
  const std::vector<Particle>& particles() const { return particles_; }
  const std::vector<real>& reference_positions() const { return reference_positions_; }
  const std::vector<real>& volumes() const { return volumes_; }
  const std::vector<index_t>& node_particle() const { return node_particle_; }
  const std::vector<index_t>& node_material() const { return node_material_; }
  const std::vector<real>& node_density() const { return node_density_; }
  const BondFamilies& bonds() const { return bonds_; }
  const std::vector<real>& weighted_volume() const { return weighted_volume_; }
  const std::vector<lps::NodeCoefficients>& lps_coefficients() const { return lps_coefficients_; }
  /// k_i = d^2 kappa_d / sum_j w_ij r_ij of PMB nodes (0 for LPS nodes), see pmb.hpp.
  const std::vector<real>& pmb_stiffness() const { return pmb_stiffness_; }

  /// Per-node stable time step sqrt(2 rho / sum_j C_ij w_ij), minimised (Silling & Askari
  /// 2005, with the LPS dilatation coupling bounded by Gershgorin) [s].
  real stable_time_step() const;

 private:
  void require_not_finalized(const char* what) const;
  void build_bonds();

  int dimension_;
  PlaneMode plane_;
  bool finalized_ = false;
  std::vector<Material> materials_;
  std::vector<Particle> particles_;
  std::vector<real> reference_positions_;
  std::vector<real> volumes_;
  std::vector<index_t> node_particle_;
  std::vector<index_t> node_material_;
  std::vector<real> node_density_;
  BondFamilies bonds_;
  std::vector<real> weighted_volume_;
  std::vector<lps::NodeCoefficients> lps_coefficients_;
  std::vector<real> pmb_stiffness_;
};

}  // namespace granulate
