#include "granulate/model.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>

#include "granulate/cell_grid.hpp"

namespace granulate {
namespace {

std::string str(real v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

}  // namespace

Model::Model(int dimension, PlaneMode plane) : dimension_(dimension), plane_(plane) {
  if (dimension != 2 && dimension != 3) {
    throw InputError("dimension must be 2 or 3, got " + std::to_string(dimension));
  }
}

void Model::require_not_finalized(const char* what) const {
  if (finalized_) {
    throw InputError(std::string("cannot ") + what +
                     " after the model is finalized; "
                     "build the whole model before the first run");
  }
}

index_t Model::add_material(const MaterialParams& params) {
  require_not_finalized("add a material");
  materials_.push_back(Material::make(params, dimension_, plane_));
  return static_cast<index_t>(materials_.size() - 1);
}

index_t Model::add_particle(std::span<const real> positions, std::span<const real> volumes, index_t material,
                            real mesh_size) {
  require_not_finalized("add a particle");
  const std::size_t n = volumes.size();
  const index_t id = static_cast<index_t>(particles_.size());
  if (n == 0) throw InputError("particle " + std::to_string(id) + " has no nodes");
  if (positions.size() != 3 * n) {
    throw InputError("particle positions must be an n x 3 array matching n volumes");
  }
  if (material >= materials_.size()) {
    throw InputError("particle " + std::to_string(id) + " refers to material " + std::to_string(material) +
                     ", but only " + std::to_string(materials_.size()) + " materials exist");
  }
  if (!(mesh_size > 0) || !std::isfinite(mesh_size)) {
    throw InputError("particle " + std::to_string(id) + ": mesh size must be positive, got " +
                     str(mesh_size));
  }
  const real horizon = materials_[material].params.horizon;
  if (horizon < mesh_size * (1.0 - 1e-9)) {
    throw InputError("particle " + std::to_string(id) + ": horizon " + str(horizon) +
                     " is smaller than the mesh size " + str(mesh_size) +
                     "; use a horizon of about 3 mesh sizes");
  }
  for (std::size_t a = 0; a < n; ++a) {
    if (!(volumes[a] > 0) || !std::isfinite(volumes[a])) {
      throw InputError("particle " + std::to_string(id) + ": node " + std::to_string(a) + " has volume " +
                       str(volumes[a]) +
                       "; every node needs a positive volume (check the mesh for degenerate elements)");
    }
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(positions[3 * a + k])) {
        throw InputError("particle " + std::to_string(id) + ": node " + std::to_string(a) +
                         " has a non-finite coordinate");
      }
    }
    if (dimension_ == 2 && positions[3 * a + 2] != 0.0) {
      throw InputError("particle " + std::to_string(id) + ": node " + std::to_string(a) +
                       " has z != 0 in a 2D model");
    }
  }
  if (node_count() + n > std::numeric_limits<index_t>::max() / 2) {
    throw InputError("too many nodes for 32-bit indices");
  }
  Particle p;
  p.first_node = node_count();
  p.node_count = static_cast<index_t>(n);
  p.material = material;
  p.mesh_size = mesh_size;
  particles_.push_back(p);
  reference_positions_.insert(reference_positions_.end(), positions.begin(), positions.end());
  volumes_.insert(volumes_.end(), volumes.begin(), volumes.end());
  node_particle_.insert(node_particle_.end(), n, id);
  node_material_.insert(node_material_.end(), n, material);
  node_density_.insert(node_density_.end(), n, materials_[material].params.density);
  return id;
}

void Model::finalize() {
  if (finalized_) return;
  if (particles_.empty()) throw InputError("the model has no particles; add at least one body");
  build_bonds();
  finalized_ = true;
}

void Model::build_bonds() {
  const index_t nodes = node_count();
  const auto& x = reference_positions_;
  std::vector<CellGrid> grids;
  grids.reserve(particles_.size());
  // Cells slightly larger than the horizon: two nodes exactly one horizon apart (common on
  // lattices) are then never two cells apart after rounding.
  for (const Particle& p : particles_) {
    grids.push_back(
        CellGrid::build(x, p.first_node, p.node_count, materials_[p.material].params.horizon * (1.0 + 1e-6)));
  }

  bonds_.offsets.assign(nodes + 1, 0);
#pragma omp parallel for schedule(static)
  for (std::int64_t ii = 0; ii < static_cast<std::int64_t>(nodes); ++ii) {
    const index_t i = static_cast<index_t>(ii);
    const index_t p = node_particle_[i];
    index_t count = 0;
    grids[p].for_each_within(x, i, materials_[particles_[p].material].params.horizon, dimension_,
                             [&](index_t, real) { ++count; });
    bonds_.offsets[i + 1] = count;
  }
  for (index_t i = 0; i < nodes; ++i) bonds_.offsets[i + 1] += bonds_.offsets[i];
  const std::size_t bond_count = bonds_.offsets[nodes];
  bonds_.neighbors.resize(bond_count);
  bonds_.weights.resize(bond_count);
  bonds_.lengths.resize(bond_count);
  weighted_volume_.assign(nodes, 0);
  lps_coefficients_.assign(nodes, {});
  pmb_stiffness_.assign(nodes, 0);

  std::vector<index_t> isolated;
  std::vector<std::pair<index_t, index_t>> coincident;
#pragma omp parallel for schedule(static)
  for (std::int64_t ii = 0; ii < static_cast<std::int64_t>(nodes); ++ii) {
    const index_t i = static_cast<index_t>(ii);
    const Particle& particle = particles_[node_particle_[i]];
    const Material& material = materials_[particle.material];
    const real horizon = material.params.horizon;
    const real h = particle.mesh_size;
    index_t* family = bonds_.neighbors.data() + bonds_.offsets[i];
    index_t filled = 0;
    grids[node_particle_[i]].for_each_within(x, i, horizon, dimension_,
                                             [&](index_t j, real) { family[filled++] = j; });
    std::sort(family, family + filled);
    real m = 0, first_moment = 0;
    for (index_t b = bonds_.offsets[i]; b < bonds_.offsets[i + 1]; ++b) {
      const index_t j = bonds_.neighbors[b];
      const real r = std::sqrt((x[3 * j] - x[3 * i]) * (x[3 * j] - x[3 * i]) +
                               (x[3 * j + 1] - x[3 * i + 1]) * (x[3 * j + 1] - x[3 * i + 1]) +
                               (x[3 * j + 2] - x[3 * i + 2]) * (x[3 * j + 2] - x[3 * i + 2]));
      if (r == 0) {
#pragma omp critical(granulate_coincident)
        coincident.emplace_back(i, j);
      }
      const real partial = r > horizon - 0.5 * h ? std::min(1.0, (horizon + 0.5 * h - r) / h) : 1.0;
      const real weight =
          influence(material.params.influence, std::min(r / horizon, 1.0)) * volumes_[j] * partial;
      bonds_.lengths[b] = r;
      bonds_.weights[b] = weight;
      m += weight * r * r;
      first_moment += weight * r;
    }
    if (filled == 0) {
#pragma omp critical(granulate_isolated)
      isolated.push_back(i);
    }
    weighted_volume_[i] = m;
    if (material.params.model == ForceModel::pmb && first_moment > 0) {
      pmb_stiffness_[i] = dimension_ * dimension_ * material.dilatation_modulus / first_moment;
    }
    if (m > 0) {
      const real d = dimension_;
      const real a = material.deviatoric_factor;
      const real G = material.params.shear_modulus;
      lps_coefficients_[i].dilatation_scale = d / m;
      lps_coefficients_[i].dilatation_coupling = (d * material.dilatation_modulus - a * G / d) / m;
      lps_coefficients_[i].deviatoric_stiffness = a * G / m;
    }
  }
  if (!coincident.empty()) {
    std::sort(coincident.begin(), coincident.end());
    throw InputError("nodes " + std::to_string(coincident[0].first) + " and " +
                     std::to_string(coincident[0].second) +
                     " are at the same position; remove duplicate nodes from the mesh");
  }
  if (!isolated.empty()) {
    std::sort(isolated.begin(), isolated.end());
    const index_t i = isolated[0];
    throw InputError("node " + std::to_string(i) + " of particle " + std::to_string(node_particle_[i]) +
                     " has no neighbour within the horizon (" + std::to_string(isolated.size()) +
                     " such nodes); increase the horizon or refine the mesh");
  }
}

real Model::stable_time_step() const {
  const auto& b = bonds_;
  real dt = std::numeric_limits<real>::infinity();
  for (index_t i = 0; i < node_count(); ++i) {
    const Material& material = materials_[node_material_[i]];
    real stiffness = 0;
    if (material.params.model == ForceModel::lps) {
      const auto& ci = lps_coefficients_[i];
      real moment = 0;
      for (index_t k = b.offsets[i]; k < b.offsets[i + 1]; ++k) {
        const index_t j = b.neighbors[k];
        stiffness += b.weights[k] * (ci.deviatoric_stiffness + lps_coefficients_[j].deviatoric_stiffness);
        moment += b.weights[k] * b.lengths[k];
      }
      stiffness += 2.0 * std::abs(ci.dilatation_coupling) * ci.dilatation_scale * moment * moment;
    } else {
      for (index_t k = b.offsets[i]; k < b.offsets[i + 1]; ++k) {
        stiffness += (pmb_stiffness_[i] + pmb_stiffness_[b.neighbors[k]]) * b.weights[k] / b.lengths[k];
      }
    }
    if (stiffness > 0) dt = std::min(dt, std::sqrt(2.0 * node_density_[i] / stiffness));
  }
  return dt;
}

}  // namespace granulate
