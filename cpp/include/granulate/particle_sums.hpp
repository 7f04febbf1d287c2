// The sums over each particle's nodes that its row of a particle table is made of
// (granulate.particle_table.motion): one pass for the mass, centre and velocity, one about the
// centre for the angular momentum and the inertia tensor.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "granulate/types.hpp"

namespace granulate {

/// Per particle p with nodes i (mass m_i, position x_i, velocity v_i), each sum taken in node
/// order, every product rounded before it is added (the file is built without contraction
/// into fused multiply-adds):
///   mass M = sum m_i; centre c = (sum m_i x_i) / M; velocity V = (sum m_i v_i) / M;
///   momentum L = sum m_i (a_i x u_i), a_i = x_i - c, u_i = v_i - V;
///   inertia I = sum m_i (|a_i|^2 1 - a_i a_i^T) as xx, yy, zz, xy, xz, yz;
///   spread = sum m_i |a_i|^2 (|a|^2 = (a_x^2 + a_y^2) + a_z^2).
/// Vectors are 3 numbers a particle, the inertia 6.
struct ParticleSums {
  std::vector<real> mass, centre, velocity, momentum, inertia, spread;
};

/// ParticleSums of `count` particles from per-node `owner` (each node's particle, < count),
/// `mass`, `positions` and `velocities` (3 numbers a node). A particle with no node has zero
/// mass and a centre and velocity of 0 / 0.
ParticleSums particle_sums(std::span<const std::uint32_t> owner, std::span<const real> mass,
                           std::span<const real> positions, std::span<const real> velocities,
                           std::size_t count);

}  // namespace granulate
