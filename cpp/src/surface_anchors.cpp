#include "granulate/surface_anchors.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include "granulate/cell_grid.hpp"
#include "granulate/contact/surface_law.hpp"
#include "granulate/types.hpp"

namespace granulate {
namespace {

using vec = std::array<real, 3>;

real det3(const vec& a, const vec& b, const vec& c) {
  return a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
         a[2] * (b[0] * c[1] - b[1] * c[0]);
}

/// w with sum_k w_k columns_k = target (Cramer's rule; in 2D the third column is (0, 0, 1)).
std::array<real, 3> solve(std::array<vec, 3> columns, const vec& target, int dimension) {
  if (dimension == 2) columns[2] = {0, 0, 1};
  const real det = det3(columns[0], columns[1], columns[2]);
  std::array<real, 3> w{0, 0, 0};
  for (int k = 0; k < dimension; ++k) {
    std::array<vec, 3> replaced = columns;
    replaced[k] = target;
    w[k] = det3(replaced[0], replaced[1], replaced[2]) / det;
  }
  return w;
}

/// The nodes within `radius` of node a, nearest first (ties by index), at most `count`.
std::vector<index_t> nearest(const CellGrid& grid, const std::vector<real>& x, index_t a, real radius,
                             int dimension, std::size_t count) {
  std::vector<std::pair<real, index_t>> near;
  grid.for_each_within(x, a, radius, dimension, [&](index_t j, real r2) { near.push_back({r2, j}); });
  std::sort(near.begin(), near.end());
  std::vector<index_t> nodes;
  for (std::size_t k = 0; k < near.size() && k < count; ++k) nodes.push_back(near[k].second);
  return nodes;
}

/// The d candidates whose bond directions from a span best: the largest |det| of the unit
/// vectors (1 when orthogonal; in 2D with (0, 0, 1) as third column), the first such in
/// nearest-first order; empty if none exceeds 0.2.
std::vector<index_t> best_span(std::span<const real> x, index_t a, std::span<const index_t> candidates,
                               int dimension) {
  std::vector<vec> unit;
  for (const index_t j : candidates) {
    vec u{x[3 * j] - x[3 * a], x[3 * j + 1] - x[3 * a + 1], x[3 * j + 2] - x[3 * a + 2]};
    const real length = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (real& c : u) c /= length;
    unit.push_back(u);
  }
  const vec z{0, 0, 1};
  real best = 0.2;
  std::vector<index_t> chosen;
  const std::size_t n = candidates.size();
  for (std::size_t p = 0; p < n; ++p) {
    for (std::size_t q = p + 1; q < n; ++q) {
      if (dimension == 2) {
        const real s = std::abs(det3(unit[p], unit[q], z));
        if (s > best) best = s, chosen = {candidates[p], candidates[q]};
        continue;
      }
      for (std::size_t r = q + 1; r < n; ++r) {
        const real s = std::abs(det3(unit[p], unit[q], unit[r]));
        if (s > best) best = s, chosen = {candidates[p], candidates[q], candidates[r]};
      }
    }
  }
  return chosen;
}

/// The surface curvature of every anchored node (see surface_curvature), into its anchor.
void estimate_curvatures(SurfaceAnchors& result, const std::vector<real>& x, std::span<const real> offsets,
                         std::span<const real> depths, real mesh_size, int dimension) {
  const std::size_t count = result.anchors.size();
  std::vector<real> points(3 * count), normals(3 * count);
  for (index_t a = 0; a < result.slot.size(); ++a) {
    const index_t k = result.slot[a];
    if (k == SurfaceAnchors::none) continue;
    const vec o{offsets[3 * a], offsets[3 * a + 1], offsets[3 * a + 2]};
    const real length = std::sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
    const real depth = depths.empty() ? 0.0 : depths[a];
    for (int c = 0; c < 3; ++c) {
      normals[3 * k + c] = o[c] / length;
      points[3 * k + c] = x[3 * a + c] + depth * normals[3 * k + c];
    }
  }
  const real radius = 2 * mesh_size;
  const CellGrid grid = CellGrid::build(points, 0, static_cast<index_t>(count), radius);
  std::vector<index_t> near;
  for (index_t k = 0; k < count; ++k) {
    near.clear();
    grid.for_each_within(points, k, radius, dimension, [&](index_t j, real) { near.push_back(j); });
    std::sort(near.begin(), near.end());  // the sums in a fixed order
    result.anchors[k].curvature =
        static_cast<float>(mesh_size * surface_curvature(points, normals, k, near, radius));
  }
}

}  // namespace

real surface_curvature(std::span<const real> points, std::span<const real> normals, index_t a,
                       std::span<const index_t> neighbours, real radius) {
  const real cos_limit = std::cos(std::numbers::pi / 6);
  real bend = 0, spread = 0;
  for (const index_t b : neighbours) {
    if (b == a) continue;
    real turn = 0, along = 0, d2 = 0;
    for (int c = 0; c < 3; ++c) {
      const real ds = points[3 * b + c] - points[3 * a + c];
      turn += (normals[3 * b + c] - normals[3 * a + c]) * ds;
      along += normals[3 * b + c] * normals[3 * a + c];
      d2 += ds * ds;
    }
    if (!(along > cos_limit) || !(d2 > 0)) continue;
    const real w = contact::surface_weight(std::sqrt(d2) / radius);
    bend += w * turn;
    spread += w * d2;
  }
  return spread > 0 ? bend / spread : 0.0;
}

bool span_anchors(std::span<const real> x, index_t a, std::span<const index_t> candidates,
                  const std::array<real, 3>& target, int dimension, index_t first, SurfaceAnchor& anchor) {
  const std::vector<index_t> chosen = best_span(x, a, candidates, dimension);
  if (chosen.empty()) return false;
  std::array<vec, 3> columns{};
  for (std::size_t k = 0; k < chosen.size(); ++k) {
    for (int c = 0; c < 3; ++c) columns[k][c] = x[3 * chosen[k] + c] - x[3 * a + c];
  }
  const std::array<real, 3> w = solve(columns, target, dimension);
  anchor.nodes = {SurfaceAnchor::no_anchor, SurfaceAnchor::no_anchor, SurfaceAnchor::no_anchor};
  anchor.weights = {0, 0, 0};
  for (std::size_t k = 0; k < chosen.size(); ++k) {
    anchor.nodes[k] = chosen[k] - first;
    anchor.weights[k] = static_cast<float>(w[k]);
  }
  return true;
}

SurfaceAnchors build_surface_anchors(std::span<const real> positions, std::span<const real> offsets,
                                     std::span<const real> depths, real mesh_size, int dimension) {
  const index_t n = static_cast<index_t>(positions.size() / 3);
  SurfaceAnchors result;
  const std::vector<real> x(positions.begin(), positions.end());
  const real radius = 1.75 * mesh_size;
  const CellGrid grid = CellGrid::build(x, 0, n, radius);
  const std::size_t candidates = dimension == 2 ? 12 : 18;
  result.slot.assign(n, SurfaceAnchors::none);
  for (index_t a = 0; a < n; ++a) {
    const vec o{offsets[3 * a], offsets[3 * a + 1], offsets[3 * a + 2]};
    if (o[0] == 0 && o[1] == 0 && o[2] == 0) continue;
    const vec target{0.5 * mesh_size * o[0], 0.5 * mesh_size * o[1], 0.5 * mesh_size * o[2]};
    SurfaceAnchor anchor;
    if (!span_anchors(x, a, nearest(grid, x, a, radius, dimension, candidates), target, dimension, 0, anchor))
      continue;
    const real reach = std::sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
    anchor.reach = static_cast<float>(reach);
    if (!depths.empty()) anchor.depth = static_cast<float>(depths[a] / mesh_size);
    result.slot[a] = static_cast<index_t>(result.anchors.size());
    result.anchors.push_back(anchor);
  }
  estimate_curvatures(result, x, offsets, depths, mesh_size, dimension);
  return result;
}

}  // namespace granulate
