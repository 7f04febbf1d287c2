// Sums over groups of nodes (particles, fragments) that give the same bits however the nodes
// are dealt to processes (granulate/run_sums.py): each group's nodes are summed run by run,
// a run being consecutive nodes of the group within one block of kRunBlock node indices, and a
// group's runs are then added in node order. A process holding whole blocks makes the runs of
// its nodes exactly as one holding every node does.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "granulate/types.hpp"

namespace granulate {

/// The node indices of a block: runs never cross a multiple of it.
inline constexpr std::int64_t kRunBlock = 64;

/// Per run: its first node, its node count, its group and its sums (width numbers a run).
struct RunSums {
  std::vector<std::int64_t> first, length, group;
  std::vector<real> sums;
};

/// The runs of `nodes` (increasing node indices, one per entry) with their `groups` and
/// `values` (width numbers an entry): a run is a maximal stretch of entries whose nodes are
/// consecutive, in one group and in one block of kRunBlock nodes; its sums add its entries'
/// values in entry order.
RunSums run_sums(std::span<const std::int64_t> groups, std::span<const std::int64_t> nodes,
                 std::span<const real> values, std::size_t width);

/// The runs of the first sums of groups of nodes, 8 numbers a run: m, V, m x (3), m v (3),
/// from each node's mass m, volume V, position x and velocity v (3 numbers a node), every
/// product rounded before it is added (run_sums.cpp is built without contraction into fused
/// multiply-adds), as NumPy would round it. Runs as run_sums makes them.
RunSums first_runs(std::span<const std::int64_t> groups, std::span<const std::int64_t> nodes,
                   std::span<const real> mass, std::span<const real> volumes, std::span<const real> positions,
                   std::span<const real> velocities);

/// The runs of the sums about each group's centre c and velocity V (`centres`,
/// `centre_velocities`: 3 numbers a group), 10 numbers a run, per node of mass m, position x
/// and velocity v:
///   angular momentum m (a x u), a = x - c, u = v - V (3);
///   inertia m (|a|^2 1 - a a^T) as xx, yy, zz, xy, xz, yz (6);
///   spread m |a|^2, |a|^2 = (a_x^2 + a_y^2) + a_z^2 (1).
RunSums moment_runs(std::span<const std::int64_t> groups, std::span<const std::int64_t> nodes,
                    std::span<const real> mass, std::span<const real> positions,
                    std::span<const real> velocities, std::span<const real> centres,
                    std::span<const real> centre_velocities);

}  // namespace granulate
