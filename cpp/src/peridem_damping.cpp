#include "granulate/contact/peridem_damping.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>

#include "granulate/cell_grid.hpp"
#include "granulate/in_parallel.hpp"

namespace granulate::contact {

void PeridemDamping::configure(const Model& model, std::vector<PeridemParticle> particles,
                               std::vector<PeridemPair> pairs) {
  const index_t materials = static_cast<index_t>(model.materials().size());
  if (particles.size() != model.particles().size() || pairs.size() != std::size_t{materials} * materials) {
    throw InputError("PeriDEM damping needs one entry per particle and per pair of materials");
  }
  max_radius_ = 0;
  max_contact_radius_ = 0;
  wall_nodes_.clear();
  for (std::size_t p = 0; p < particles.size(); ++p) {
    const Particle& particle = model.particles()[p];
    const PeridemParticle& d = particles[p];
    if (d.center < particle.first_node || d.center >= particle.first_node + particle.node_count ||
        !(d.radius > 0)) {
      throw InputError("PeriDEM damping: particle " + std::to_string(p) +
                       " needs a centre node of its own and a positive radius");
    }
    max_radius_ = std::max(max_radius_, d.radius);
    if (d.wall) {
      for (index_t k = 0; k < particle.node_count; ++k) wall_nodes_.push_back(particle.first_node + k);
    }
  }
  for (const PeridemPair& pair : pairs) {
    if (!(pair.betan >= 0) || !(pair.kappa >= 0) || !(pair.contact_radius >= 0)) {
      throw InputError("PeriDEM damping: betan, kappa and the contact radius must not be negative");
    }
    if (pair.betan > 0) max_contact_radius_ = std::max(max_contact_radius_, pair.contact_radius);
  }
  particles_ = std::move(particles);
  pairs_ = std::move(pairs);
  material_count_ = materials;
  centers_.clear();
  center_particle_.assign(model.node_count(), 0);
  for (std::size_t p = 0; p < particles_.size(); ++p) {
    if (!particles_[p].wall) centers_.push_back(particles_[p].center);
    center_particle_[particles_[p].center] = static_cast<index_t>(p);
  }
}

void PeridemDamping::add_forces(const Model& model, State& state) const {
  if (particles_.empty() || max_contact_radius_ == 0) return;
  const auto& x = state.positions;
  const auto& v = state.velocities;
  auto& f = state.forces;
  const int dimension = model.dimension();
  const std::size_t count = particles_.size();

  const real reach = 2 * max_radius_ + 1.01 * max_contact_radius_;
  const CellGrid center_grid = CellGrid::build(x, centers_, reach);
  const CellGrid wall_grid = CellGrid::build(x, wall_nodes_, max_contact_radius_);

  in_parallel([&] {
    std::vector<index_t> near;      // particles whose centres are within reach (scratch)
    std::vector<index_t> touching;  // wall nodes within Rc of this particle (scratch)
#pragma omp for schedule(dynamic, 4)
    for (std::int64_t pp = 0; pp < static_cast<std::int64_t>(count); ++pp) {
      const PeridemParticle& me = particles_[pp];
      if (me.wall || (!ghost_.empty() && ghost_[pp])) continue;
      const Particle& particle = model.particles()[pp];
      const index_t c = me.center;
      const real area = std::numbers::pi * me.radius * me.radius;
      const real mass = model.density(c) * area;
      real force[3] = {0, 0, 0};
      auto damp = [&](index_t k, real beta) {  // dashpot along the centre-to-k direction
        real n[3] = {x[3 * k] - x[3 * c], x[3 * k + 1] - x[3 * c + 1], x[3 * k + 2] - x[3 * c + 2]};
        const real length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(length > 0)) return;
        real closing = 0;
        for (int d = 0; d < 3; ++d) {
          n[d] /= length;
          closing += (v[3 * k + d] - v[3 * c + d]) * n[d];
        }
        closing = std::min(0.0, closing);
        for (int d = 0; d < 3; ++d) force[d] += beta * closing * n[d] / area;
      };
      near.clear();
      center_grid.for_each_within(
          x, c, me.radius + max_radius_ + 1.01 * max_contact_radius_, dimension,
          [&](index_t other_center, real r2) {
            const index_t q = center_particle_[other_center];
            const PeridemPair& pair =
                pairs_[particle.material * material_count_ + model.particles()[q].material];
            if (pair.betan > 0 &&
                std::sqrt(r2) < me.radius + particles_[q].radius + 1.01 * pair.contact_radius)
              near.push_back(q);
          });
      std::sort(near.begin(), near.end());
      for (index_t q : near) {
        const PeridemParticle& other = particles_[q];
        const PeridemPair& pair = pairs_[particle.material * material_count_ + model.particles()[q].material];
        const real other_mass = model.density(other.center) * std::numbers::pi * other.radius * other.radius;
        const real reduced = 2 * mass * other_mass / (mass + other_mass);  // harmonic mean
        damp(other.center, pair.betan * std::sqrt(pair.kappa * pair.contact_radius * reduced));
      }
      touching.clear();
      for (index_t a = 0; a < particle.node_count; ++a) {
        const index_t i = particle.first_node + a;
        wall_grid.for_each_within(x, i, max_contact_radius_, dimension, [&](index_t k, real r2) {
          const index_t wall_material = model.particles()[model.node_particle()[k]].material;
          const PeridemPair& pair = pairs_[particle.material * material_count_ + wall_material];
          if (pair.betan > 0 && std::sqrt(r2) < pair.contact_radius) touching.push_back(k);
        });
      }
      std::sort(touching.begin(), touching.end());
      touching.erase(std::unique(touching.begin(), touching.end()), touching.end());
      for (index_t k : touching) {
        const index_t wall_material = model.particles()[model.node_particle()[k]].material;
        const PeridemPair& pair = pairs_[particle.material * material_count_ + wall_material];
        damp(k, pair.betan * std::sqrt(pair.kappa * pair.contact_radius * mass));
      }
      for (index_t a = 0; a < particle.node_count; ++a) {
        const std::size_t i = particle.first_node + a;
        for (int d = 0; d < 3; ++d) f[3 * i + d] += force[d];
      }
    }
  });
}

}  // namespace granulate::contact
