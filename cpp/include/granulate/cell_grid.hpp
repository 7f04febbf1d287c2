// A uniform grid of cells over a range of nodes (counting sort), for fixed-radius searches.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "granulate/types.hpp"

namespace granulate {

class CellGrid {
 public:
  /// Grid over nodes first .. first+count-1 of x (n x 3, double or float), cells of at least
  /// cell_size. The cell count is capped at ~64 per node (sparse sets get larger cells; searches
  /// stay correct). Distances are computed in double precision from the stored values.
  template <class T>
  static CellGrid build(const std::vector<T>& x, index_t first, index_t count, real cell_size) {
    return build(x, count, cell_size, [first](index_t a) { return first + a; });
  }

  /// Grid over an explicit list of nodes.
  template <class T>
  static CellGrid build(const std::vector<T>& x, const std::vector<index_t>& nodes, real cell_size) {
    return build(x, static_cast<index_t>(nodes.size()), cell_size, [&nodes](index_t a) { return nodes[a]; });
  }

  /// Calls visit(j, r^2) for every grid node j != i with |x_j - x_i| <= radius (x_i may be
  /// any point of the x array, inside the grid or not). Cells are visited in a fixed order.
  template <class T, class Visit>
  void for_each_within(const std::vector<T>& x, index_t i, real radius, int dimension, Visit&& visit) const {
    if (cell_nodes_.empty()) return;
    const std::size_t at = 3 * static_cast<std::size_t>(i);
    const std::array<real, 3> xi{x[at], x[at + 1], x[at + 2]};
    const real limit = radius * radius * (1.0 + 1e-10);
    std::array<std::int64_t, 3> lo{}, hi{};
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::max<std::int64_t>(0, coordinate(xi[k] - radius, k));
      hi[k] = std::min<std::int64_t>(dims_[k] - 1, coordinate(xi[k] + radius, k));
      if (k == 2 && dimension == 2) lo[k] = hi[k] = 0;
      if (lo[k] > hi[k]) return;
    }
    for (std::int64_t cz = lo[2]; cz <= hi[2]; ++cz) {
      for (std::int64_t cy = lo[1]; cy <= hi[1]; ++cy) {
        for (std::int64_t cx = lo[0]; cx <= hi[0]; ++cx) {
          const std::int64_t cell = (cz * dims_[1] + cy) * dims_[0] + cx;
          for (index_t k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
            const index_t j = cell_nodes_[k];
            if (j == i) continue;
            const std::size_t jt = 3 * static_cast<std::size_t>(j);
            const real dx = real(x[jt]) - xi[0], dy = real(x[jt + 1]) - xi[1], dz = real(x[jt + 2]) - xi[2];
            const real r2 = dx * dx + dy * dy + dz * dz;
            if (r2 <= limit) visit(j, r2);
          }
        }
      }
    }
  }

 private:
  std::int64_t coordinate(real value, int axis) const {
    const real c = (value - origin_[axis]) / cell_size_;
    if (c < 0) return -1;
    if (c >= static_cast<real>(dims_[axis])) return dims_[axis];
    return static_cast<std::int64_t>(c);
  }

  template <class T, class NodeOf>
  static CellGrid build(const std::vector<T>& x, index_t count, real cell_size, NodeOf node_of) {
    CellGrid grid;
    if (count == 0) return grid;
    std::array<real, 3> lo{}, hi{};
    lo.fill(std::numeric_limits<real>::max());
    hi.fill(std::numeric_limits<real>::lowest());
    for (index_t a = 0; a < count; ++a) {
      const std::size_t i = node_of(a);
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], real(x[3 * i + k]));
        hi[k] = std::max(hi[k], real(x[3 * i + k]));
      }
    }
    for (;;) {
      std::int64_t cells = 1;
      for (int k = 0; k < 3; ++k) {
        grid.dims_[k] = std::max<std::int64_t>(1, static_cast<std::int64_t>((hi[k] - lo[k]) / cell_size) + 1);
        cells *= grid.dims_[k];
      }
      if (cells <= 64 * static_cast<std::int64_t>(count) + 1024) break;
      cell_size *= 1.5;
    }
    grid.origin_ = lo;
    grid.cell_size_ = cell_size;
    const std::int64_t cells = grid.dims_[0] * grid.dims_[1] * grid.dims_[2];
    grid.cell_start_.assign(static_cast<std::size_t>(cells) + 1, 0);
    std::vector<std::int64_t> node_cell(count);
    for (index_t a = 0; a < count; ++a) {
      const T* p = &x[3 * static_cast<std::size_t>(node_of(a))];
      node_cell[a] = (grid.clamped(p[2], 2) * grid.dims_[1] + grid.clamped(p[1], 1)) * grid.dims_[0] +
                     grid.clamped(p[0], 0);
      ++grid.cell_start_[node_cell[a] + 1];
    }
    for (std::size_t c = 0; c + 1 < grid.cell_start_.size(); ++c)
      grid.cell_start_[c + 1] += grid.cell_start_[c];
    grid.cell_nodes_.resize(count);
    std::vector<index_t> fill(grid.cell_start_.begin(), grid.cell_start_.end() - 1);
    for (index_t a = 0; a < count; ++a) grid.cell_nodes_[fill[node_cell[a]]++] = node_of(a);
    return grid;
  }

  std::int64_t clamped(real value, int axis) const {
    return std::clamp<std::int64_t>(static_cast<std::int64_t>((value - origin_[axis]) / cell_size_), 0,
                                    dims_[axis] - 1);
  }

  std::array<real, 3> origin_{};
  real cell_size_ = 1;
  std::array<std::int64_t, 3> dims_{1, 1, 1};
  std::vector<index_t> cell_start_;  // size cells + 1
  std::vector<index_t> cell_nodes_;  // node ids, by cell
};

}  // namespace granulate
