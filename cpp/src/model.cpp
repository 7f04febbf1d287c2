#include "granulate/model.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <sstream>

#include "granulate/cell_grid.hpp"
#include "granulate/in_parallel.hpp"

namespace granulate {
namespace {

std::string str(real v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

/// The bonds a block of BondSchedule evaluates, about, when cut from `bonds`: 1/64 of them,
/// from 1,024 to 16,384. Of a particle's own bonds for its ranges, so that a particle's cut, and
/// the order in which its nodes take their terms, depends on the particle alone (a distributed
/// run's part of the particles sums them as the whole model does).
std::size_t block_bonds(std::size_t bonds) {
  return std::clamp<std::size_t>(bonds / 64, 1024, 16384);
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

void Model::set_whole_particle_bonds(std::size_t bonds) {
  require_not_finalized("set the bonds of a particle evaluated whole");
  if (bonds < 1) throw InputError("whole_particle_bonds must be at least 1");
  whole_particle_bonds_ = bonds;
}

index_t Model::add_material(const MaterialParams& params) {
  require_not_finalized("add a material");
  materials_.push_back(Material::make(params, dimension_, plane_));
  return static_cast<index_t>(materials_.size() - 1);
}

index_t Model::add_shape(std::span<const real> positions, std::span<const real> volumes, real mesh_size,
                         std::span<const real> surface_offsets, std::span<const real> surface_depths) {
  require_not_finalized("add a shape");
  const std::size_t n = volumes.size();
  const std::string name = "shape " + std::to_string(shapes_.size());
  if (n == 0) throw InputError(name + " has no nodes");
  if (positions.size() != 3 * n)
    throw InputError(name + ": positions must be an n x 3 array matching n volumes");
  if (!(mesh_size > 0) || !std::isfinite(mesh_size)) {
    throw InputError(name + ": mesh size must be positive, got " + str(mesh_size));
  }
  for (std::size_t a = 0; a < n; ++a) {
    if (!(volumes[a] > 0) || !std::isfinite(volumes[a])) {
      throw InputError(name + ": node " + std::to_string(a) + " has volume " + str(volumes[a]) +
                       "; every node needs a positive volume (check the mesh for degenerate elements)");
    }
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(positions[3 * a + k])) {
        throw InputError(name + ": node " + std::to_string(a) + " has a non-finite coordinate");
      }
    }
    if (dimension_ == 2 && positions[3 * a + 2] != 0.0) {
      throw InputError(name + ": node " + std::to_string(a) + " has z != 0 in a 2D model");
    }
  }
  if (!surface_offsets.empty() && surface_offsets.size() != 3 * n) {
    throw InputError(name + ": " + std::to_string(surface_offsets.size() / 3) + " surface offsets for " +
                     std::to_string(n) + " nodes");
  }
  if (!std::all_of(surface_offsets.begin(), surface_offsets.end(), [](real o) { return std::isfinite(o); }))
    throw InputError(name + ": a surface offset is not finite");
  if (!surface_depths.empty() && surface_depths.size() != n) {
    throw InputError(name + ": " + std::to_string(surface_depths.size()) + " surface depths for " +
                     std::to_string(n) + " nodes");
  }
  if (!std::all_of(surface_depths.begin(), surface_depths.end(),
                   [mesh_size](real d) { return d >= 0 && d <= 2 * mesh_size; }))
    throw InputError(name + ": a surface depth is negative, not finite or deeper than 2 mesh sizes");
  Shape shape;
  if (std::any_of(surface_offsets.begin(), surface_offsets.end(), [](real o) { return o != 0; })) {
    shape.surface_offsets.assign(surface_offsets.begin(), surface_offsets.end());
    shape.surface_depths.assign(surface_depths.begin(), surface_depths.end());
  }
  shape.positions.assign(positions.begin(), positions.end());
  shape.volumes.assign(volumes.begin(), volumes.end());
  shape.mesh_size = mesh_size;
  shapes_.push_back(std::move(shape));
  return static_cast<index_t>(shapes_.size() - 1);
}

index_t Model::add_particle(index_t shape_index, index_t material, std::span<const real> positions,
                            real scale, real horizon) {
  require_not_finalized("add a particle");
  const index_t id = static_cast<index_t>(particles_.size());
  const std::string name = "particle " + std::to_string(id);
  if (shape_index >= shapes_.size()) throw InputError(name + " refers to an unknown shape");
  const Shape& shape = shapes_[shape_index];
  const std::size_t n = shape.node_count();
  if (positions.size() != 3 * n) {
    throw InputError(name + ": " + std::to_string(positions.size() / 3) +
                     " placed positions for a shape of " + std::to_string(n) + " nodes");
  }
  if (material >= materials_.size()) {
    throw InputError(name + " refers to material " + std::to_string(material) + ", but only " +
                     std::to_string(materials_.size()) + " materials exist");
  }
  if (!(scale > 0) || !std::isfinite(scale))
    throw InputError(name + ": scale must be positive, got " + str(scale));
  const real mesh_size = scale * shape.mesh_size;
  if (horizon == 0) horizon = materials_[material].params.horizon;
  if (!(horizon > 0) || !std::isfinite(horizon))
    throw InputError(name + ": horizon must be positive, got " + str(horizon));
  if (horizon < mesh_size * (1.0 - 1e-9)) {
    throw InputError(name + ": horizon " + str(horizon) + " is smaller than the mesh size " + str(mesh_size) +
                     "; use a horizon of about 3 mesh sizes");
  }
  // A rigid placement keeps every distance times the scale; check consecutive nodes.
  for (std::size_t a = 0; a < n; ++a) {
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(positions[3 * a + k])) throw InputError(name + ": a placed position is not finite");
    }
    if (dimension_ == 2 && positions[3 * a + 2] != 0.0) throw InputError(name + ": placed with z != 0 in 2D");
    if (a + 1 == n) continue;
    real placed = 0, reference = 0;
    for (int k = 0; k < 3; ++k) {
      placed += (positions[3 * a + 3 + k] - positions[3 * a + k]) *
                (positions[3 * a + 3 + k] - positions[3 * a + k]);
      reference += (shape.positions[3 * a + 3 + k] - shape.positions[3 * a + k]) *
                   (shape.positions[3 * a + 3 + k] - shape.positions[3 * a + k]);
    }
    if (std::abs(std::sqrt(placed) - scale * std::sqrt(reference)) >
        1e-9 * scale * (std::sqrt(reference) + shape.mesh_size)) {
      throw InputError(name + ": the positions are not the shape scaled by " + str(scale) +
                       ", rotated and translated");
    }
  }
  if (node_count() + n > std::numeric_limits<index_t>::max() / 2)
    throw InputError("too many nodes for 32-bit indices");
  Particle p;
  p.first_node = node_count();
  p.node_count = static_cast<index_t>(n);
  p.material = material;
  p.mesh_size = mesh_size;
  p.shape = shape_index;
  p.scale = scale;
  p.horizon = horizon;
  const Material& m = materials_[material];
  p.critical_stretch = m.critical_stretch_at(horizon);
  particles_.push_back(p);
  const real volume_scale = std::pow(scale, dimension_);
  reference_positions_.insert(reference_positions_.end(), positions.begin(), positions.end());
  for (real v : shape.volumes) volumes_.push_back(volume_scale * v);
  node_particle_.insert(node_particle_.end(), n, id);
  node_material_.insert(node_material_.end(), n, material);
  return id;
}

index_t Model::add_particle(std::span<const real> positions, std::span<const real> volumes, index_t material,
                            real mesh_size, real horizon) {
  if (material >= materials_.size()) {
    throw InputError("particle " + std::to_string(particles_.size()) + " refers to material " +
                     std::to_string(material) + ", but only " + std::to_string(materials_.size()) +
                     " materials exist");
  }
  return add_particle(add_shape(positions, volumes, mesh_size), material, positions, 1.0, horizon);
}

void Model::finalize() {
  if (finalized_) return;
  if (particles_.empty()) throw InputError("the model has no particles; add at least one body");
  build_bonds();
  build_bond_schedule();
  // The shapes' node positions, volumes and surface offsets were only needed to place the
  // particles and build the bond families and the surface anchors (a body used once would
  // otherwise hold its nodes twice).
  for (Shape& shape : shapes_) {
    if (!shape.surface_offsets.empty()) {
      shape.anchors = build_surface_anchors(shape.positions, shape.surface_offsets, shape.surface_depths,
                                            shape.mesh_size, dimension_);
    }
    std::vector<real>().swap(shape.positions);
    std::vector<real>().swap(shape.volumes);
    std::vector<real>().swap(shape.surface_offsets);
    std::vector<real>().swap(shape.surface_depths);
  }
  // The per-node arrays grew body by body (capacity up to twice their size); the model is
  // complete now.
  reference_positions_.shrink_to_fit();
  volumes_.shrink_to_fit();
  node_particle_.shrink_to_fit();
  node_material_.shrink_to_fit();
  finalized_ = true;
}

BondFamilies Model::build_family(index_t shape_index, real horizon, InfluenceKind influence_kind) const {
  const Shape& shape = shapes_[shape_index];
  const auto& x = shape.positions;
  const index_t nodes = shape.node_count();
  const real h = shape.mesh_size;
  BondFamilies family;
  family.shape = shape_index;
  family.horizon = horizon;
  family.influence = influence_kind;
  // Cells slightly larger than the horizon: two nodes exactly one horizon apart (common on
  // lattices) are then never two cells apart after rounding.
  const CellGrid grid = CellGrid::build(x, 0, nodes, horizon * (1.0 + 1e-6));
  family.offsets.assign(nodes + 1, 0);
  family.forward.assign(nodes, 0);
  in_parallel([&] {
#pragma omp for schedule(static)
    for (std::int64_t aa = 0; aa < static_cast<std::int64_t>(nodes); ++aa) {
      const index_t a = static_cast<index_t>(aa);
      index_t count = 0;
      grid.for_each_within(x, a, horizon, dimension_, [&](index_t, real) { ++count; });
      family.offsets[a + 1] = count;
    }
  });
  for (index_t a = 0; a < nodes; ++a) family.offsets[a + 1] += family.offsets[a];
  const std::size_t bonds = family.offsets[nodes];
  family.neighbors.resize(bonds);
  family.weights.resize(bonds);
  family.lengths.resize(bonds);
  std::vector<std::pair<index_t, index_t>> coincident;
  in_parallel([&] {
#pragma omp for schedule(static)
    for (std::int64_t aa = 0; aa < static_cast<std::int64_t>(nodes); ++aa) {
      const index_t a = static_cast<index_t>(aa);
      index_t* out = family.neighbors.data() + family.offsets[a];
      index_t filled = 0;
      grid.for_each_within(x, a, horizon, dimension_, [&](index_t j, real) { out[filled++] = j; });
      std::sort(out, out + filled);
      family.forward[a] =
          static_cast<index_t>(std::upper_bound(out, out + filled, a) - family.neighbors.data());
      for (index_t b = family.offsets[a]; b < family.offsets[a + 1]; ++b) {
        const index_t j = family.neighbors[b];
        const real r = std::sqrt((x[3 * j] - x[3 * a]) * (x[3 * j] - x[3 * a]) +
                                 (x[3 * j + 1] - x[3 * a + 1]) * (x[3 * j + 1] - x[3 * a + 1]) +
                                 (x[3 * j + 2] - x[3 * a + 2]) * (x[3 * j + 2] - x[3 * a + 2]));
        if (r == 0) {
#pragma omp critical(granulate_coincident)
          coincident.emplace_back(a, j);
        }
        // Partial volume: a neighbour cell cut by the horizon counts for its share inside.
        const real partial = r > horizon - 0.5 * h ? std::min(1.0, (horizon + 0.5 * h - r) / h) : 1.0;
        family.lengths[b] = r;
        family.weights[b] =
            static_cast<float>(influence(influence_kind, std::min(r / horizon, 1.0)) * partial);
      }
    }
  });
  if (!coincident.empty()) {
    std::sort(coincident.begin(), coincident.end());
    throw InputError("nodes " + std::to_string(coincident[0].first) + " and " +
                     std::to_string(coincident[0].second) + " of shape " + std::to_string(shape_index) +
                     " are at the same position; remove duplicate nodes from the mesh");
  }
  return family;
}

void Model::build_bonds() {
  // One family per (shape, horizon in shape units, influence), shared by its particles.
  for (Particle& p : particles_) {
    const Material& material = materials_[p.material];
    const real horizon = p.horizon / p.scale;
    const InfluenceKind kind = material.params.influence;
    std::size_t found = families_.size();
    for (std::size_t f = 0; f < families_.size(); ++f) {
      if (families_[f].shape == p.shape && families_[f].horizon == horizon && families_[f].influence == kind)
        found = f;
    }
    if (found == families_.size()) families_.push_back(build_family(p.shape, horizon, kind));
    p.family = static_cast<index_t>(found);
  }
  const index_t nodes = node_count();
  bond_offsets_.assign(static_cast<std::size_t>(nodes) + 1, 0);
  for (const Particle& p : particles_) {
    const BondFamilies& f = families_[p.family];
    for (index_t a = 0; a < p.node_count; ++a) {
      bond_offsets_[p.first_node + a + 1] = f.offsets[a + 1] - f.offsets[a];
    }
  }
  for (index_t i = 0; i < nodes; ++i) bond_offsets_[i + 1] += bond_offsets_[i];

  // Each force model's constants only where some particle uses it (8 and 24 bytes per node).
  bool any_lps = false, any_pmb = false;
  for (const Particle& p : particles_) {
    any_lps = any_lps || materials_[p.material].params.model == ForceModel::lps;
    any_pmb = any_pmb || materials_[p.material].params.model == ForceModel::pmb;
  }
  lps_coefficients_.assign(any_lps ? nodes : 0, {});
  pmb_stiffness_.assign(any_pmb ? nodes : 0, 0);
  std::vector<index_t> isolated;
  in_parallel([&] {
#pragma omp for schedule(static)
    for (std::int64_t ii = 0; ii < static_cast<std::int64_t>(nodes); ++ii) {
      const index_t i = static_cast<index_t>(ii);
      const Material& material = materials_[node_material_[i]];
      const NodeBonds bonds = node_bonds(i);
      real m = 0, first_moment = 0;
      for (index_t b = 0; b < bonds.count; ++b) {
        const real r = bonds.length(b), w = bonds.weight(b);
        m += w * r * r;
        first_moment += w * r;
      }
      if (bonds.count == 0) {
#pragma omp critical(granulate_isolated)
        isolated.push_back(i);
      }
      if (material.params.model == ForceModel::pmb && first_moment > 0) {
        pmb_stiffness_[i] = dimension_ * dimension_ * material.dilatation_modulus / first_moment;
      }
      if (material.params.model == ForceModel::lps && m > 0) {
        const real d = lps_dimension();
        const real a = material.deviatoric_factor;
        const real G = material.params.shear_modulus;
        lps_coefficients_[i].dilatation_scale = d / m;
        lps_coefficients_[i].dilatation_coupling = (d * material.dilatation_modulus - a * G / d) / m;
        lps_coefficients_[i].deviatoric_stiffness = a * G / m;
      }
    }
  });
  if (!isolated.empty()) {
    std::sort(isolated.begin(), isolated.end());
    const index_t i = isolated[0];
    throw InputError("node " + std::to_string(i) + " of particle " + std::to_string(node_particle_[i]) +
                     " has no neighbour within the horizon (" + std::to_string(isolated.size()) +
                     " such nodes); increase the horizon or refine the mesh");
  }
}

void Model::build_bond_schedule() {
  // Blocks of consecutive nodes with about 1/64 of the bonds to evaluate (block_bonds): enough
  // blocks per colour for the threads, few enough that a block's work dwarfs its scheduling.
  // - Particles of up to whole_particle_bonds_ forward bonds are not cut: consecutive ones form
  //   a block of 1/64 of the model's bonds. Their blocks never share a node, so many-grain
  //   models need one colour.
  // - Larger particles numbered in bands (every bond joins nodes less than a quarter of the
  //   particle apart, as on lattices and our meshes) are cut into ranges of 1/64 of their own
  //   bonds (the cut depends on the particle alone): a range touches only the ranges within a
  //   band, so each colour holds at least about four ranges.
  // - Larger particles numbered otherwise (a mesh file numbered at random, say) would need a
  //   colour per range: their nodes gather instead (each evaluates all its bonds and writes only
  //   its own sums), twice the bond evaluations but parallel.
  cut_bond_blocks();
  colour_bond_blocks();
}

void Model::cut_bond_blocks() {
  const index_t n = node_count();
  std::size_t forward_total = 0;
  std::vector<std::size_t> particle_forward(particles_.size(), 0);
  for (index_t i = 0; i < n; ++i) {
    const NodeBonds bonds = node_bonds(i);
    forward_total += static_cast<std::size_t>(bonds.count - bonds.forward);
    particle_forward[node_particle_[i]] += static_cast<std::size_t>(bonds.count - bonds.forward);
  }
  // Whole particles are grouped into blocks of a share of the model's bonds (their nodes take
  // their terms in node order, whatever block they are in); a particle is cut, and its ranges
  // sized, by its own bonds alone, so that a distributed run's part (a subset of the
  // particles) sums every node's terms in the whole model's order.
  const std::size_t group = block_bonds(forward_total);
  BondSchedule& s = bond_schedule_;
  s = {};
  s.particle_gathers.assign(particles_.size(), 0);
  s.block_starts.push_back(0);
  std::size_t in_block = 0;  // bonds evaluated by the open block
  auto close_block = [&](index_t end) {
    if (s.block_starts.back() != end) s.block_starts.push_back(end);
    in_block = 0;
  };
  for (std::size_t q = 0; q < particles_.size(); ++q) {
    const Particle& particle = particles_[q];
    const index_t first = particle.first_node, last = first + particle.node_count;
    if (particle_forward[q] <= whole_particle_bonds_) {
      in_block += particle_forward[q];
      if (in_block >= group) close_block(last);
      continue;
    }
    close_block(first);
    index_t band = 0;  // the longest bond, in node numbers
    for (index_t i = first; i < last; ++i) {
      const NodeBonds bonds = node_bonds(i);
      if (bonds.count > bonds.forward) band = std::max(band, bonds.neighbor(bonds.count - 1) - i);
    }
    const bool gathers = 4 * std::size_t{band} > particle.node_count;
    s.particle_gathers[q] = gathers ? 1 : 0;
    const std::size_t range = block_bonds(particle_forward[q]);
    for (index_t i = first; i < last; ++i) {
      const NodeBonds bonds = node_bonds(i);
      in_block += static_cast<std::size_t>(gathers ? bonds.count : bonds.count - bonds.forward);
      if (in_block >= range) close_block(i + 1);
    }
    close_block(last);
  }
  close_block(n);
}

void Model::colour_bond_blocks() {
  // Greedy colouring in block order: a block takes the smallest colour that no block touching
  // one of its nodes (itself or, unless it gathers, a forward neighbour) has yet; colours past
  // 64 are not shared.
  const index_t n = node_count();
  BondSchedule& s = bond_schedule_;
  const index_t blocks = static_cast<index_t>(s.block_starts.size() - 1);
  std::vector<std::uint64_t> taken_at(n, 0);  // bit c: a block of colour c touches the node
  std::vector<index_t> colour(blocks, 0);
  index_t colours = 0;
  std::vector<index_t> touched;
  for (index_t k = 0; k < blocks; ++k) {
    touched.clear();
    for (index_t i = s.block_starts[k]; i < s.block_starts[k + 1]; ++i) {
      touched.push_back(i);
      if (s.particle_gathers[node_particle_[i]]) continue;
      const NodeBonds bonds = node_bonds(i);
      for (index_t b = bonds.forward; b < bonds.count; ++b) touched.push_back(bonds.neighbor(b));
    }
    std::uint64_t used = 0;
    for (index_t i : touched) used |= taken_at[i];
    if (~used == 0) {
      colour[k] = std::max<index_t>(colours, 64);  // a colour of its own
    } else {
      colour[k] = static_cast<index_t>(std::countr_one(used));
      for (index_t i : touched) taken_at[i] |= std::uint64_t{1} << colour[k];
    }
    colours = std::max(colours, colour[k] + 1);
  }
  s.colour_offsets.assign(colours + 1, 0);
  for (index_t k = 0; k < blocks; ++k) ++s.colour_offsets[colour[k] + 1];
  for (index_t c = 0; c < colours; ++c) s.colour_offsets[c + 1] += s.colour_offsets[c];
  s.blocks.resize(blocks);
  std::vector<index_t> next(s.colour_offsets.begin(), s.colour_offsets.end() - 1);
  for (index_t k = 0; k < blocks; ++k) s.blocks[next[colour[k]]++] = k;
}

std::optional<index_t> Model::bond_between(index_t i, index_t j) const {
  if (i >= node_count() || j >= node_count() || node_particle_[i] != node_particle_[j]) return std::nullopt;
  const NodeBonds bonds = node_bonds(i);
  const index_t b = bonds.find(j);
  return b == bonds.count ? std::nullopt : std::optional<index_t>{b};
}

index_t NodeBonds::find(index_t j) const {
  const index_t local = j - first_node;
  const index_t* found = std::lower_bound(neighbors, neighbors + count, local);
  return found != neighbors + count && *found == local ? static_cast<index_t>(found - neighbors) : count;
}

index_t Model::fragments(const BondStates& intact, index_t* labels) const {
  return fragments_in(intact, 0, node_count(), labels);
}

index_t Model::fragments_in(const BondStates& intact, index_t first, index_t count, index_t* labels) const {
  // Union-find; the root of a set is always its smallest node, so labels are deterministic.
  std::vector<index_t> parent(count);
  for (index_t k = 0; k < count; ++k) parent[k] = k;
  auto root = [&](index_t k) {
    while (parent[k] != k) {
      parent[k] = parent[parent[k]];
      k = parent[k];
    }
    return k;
  };
  for (index_t k = 0; k < count; ++k) {
    const NodeBonds bonds = node_bonds(first + k);
    for (index_t b = 0; b < bonds.count; ++b) {
      if (!intact.intact(first + k, b)) continue;
      const index_t a = root(k), c = root(bonds.neighbor(b) - first);
      if (a < c) parent[c] = a;
      if (c < a) parent[a] = c;
    }
  }
  index_t fragments = 0;
  for (index_t k = 0; k < count; ++k) {
    labels[k] = first + root(k);
    if (labels[k] == first + k) ++fragments;
  }
  return fragments;
}

void Model::fragments_among(const BondStates& intact, const std::vector<index_t>& nodes, index_t* labels,
                            std::vector<std::array<index_t, 2>>& leaving) const {
  constexpr index_t outside = std::numeric_limits<index_t>::max();
  std::vector<index_t> place(node_count(), outside);
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    if (nodes[k] >= node_count() || (k > 0 && nodes[k] <= nodes[k - 1]))
      throw InputError("fragments_among: the nodes must increase and be the model's");
    place[nodes[k]] = static_cast<index_t>(k);
  }
  // Union-find over places; a set's root is its smallest place, so its smallest node.
  std::vector<index_t> parent(nodes.size());
  for (std::size_t k = 0; k < nodes.size(); ++k) parent[k] = static_cast<index_t>(k);
  auto root = [&](index_t k) {
    while (parent[k] != k) {
      parent[k] = parent[parent[k]];
      k = parent[k];
    }
    return k;
  };
  leaving.clear();
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const NodeBonds bonds = node_bonds(nodes[k]);
    for (index_t b = 0; b < bonds.count; ++b) {
      if (!intact.intact(nodes[k], b)) continue;
      const index_t j = bonds.neighbor(b);
      if (place[j] == outside) {
        leaving.push_back({nodes[k], j});
        continue;
      }
      const index_t a = root(static_cast<index_t>(k)), c = root(place[j]);
      if (a < c) parent[c] = a;
      if (c < a) parent[a] = c;
    }
  }
  for (std::size_t k = 0; k < nodes.size(); ++k) labels[k] = nodes[root(static_cast<index_t>(k))];
}

real Model::stable_time_step() const {
  real dt = std::numeric_limits<real>::infinity();
  for (index_t i = 0; i < node_count(); ++i) {
    const Material& material = materials_[node_material_[i]];
    const NodeBonds bonds = node_bonds(i);
    real stiffness = 0;
    if (material.params.model == ForceModel::lps) {
      const auto& ci = lps_coefficients_[i];
      real moment = 0;
      for (index_t b = 0; b < bonds.count; ++b) {
        stiffness += bonds.weight(b) *
                     (ci.deviatoric_stiffness + lps_coefficients_[bonds.neighbor(b)].deviatoric_stiffness);
        moment += bonds.weight(b) * bonds.length(b);
      }
      stiffness += 2.0 * std::abs(ci.dilatation_coupling) * ci.dilatation_scale * moment * moment;
    } else {
      for (index_t b = 0; b < bonds.count; ++b) {
        stiffness +=
            (pmb_stiffness_[i] + pmb_stiffness_[bonds.neighbor(b)]) * bonds.weight(b) / bonds.length(b);
      }
    }
    if (stiffness > 0) dt = std::min(dt, std::sqrt(2.0 * density(i) / stiffness));
  }
  return dt;
}

}  // namespace granulate
