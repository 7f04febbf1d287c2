#include "granulate/walls.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace granulate {
namespace {

using vec = std::array<real, 3>;

real dot(const vec& a, const vec& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
real norm(const vec& a) {
  return std::sqrt(dot(a, a));
}
vec cross(const vec& a, const vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

/// Rodrigues rotation of v about unit axis k by angle a.
vec rotate(const vec& v, const vec& k, real a) {
  const real c = std::cos(a), s = std::sin(a);
  const vec kxv = cross(k, v);
  const real kv = dot(k, v);
  return {v[0] * c + kxv[0] * s + k[0] * kv * (1 - c), v[1] * c + kxv[1] * s + k[1] * kv * (1 - c),
          v[2] * c + kxv[2] * s + k[2] * kv * (1 - c)};
}

void normalise(vec& v, const char* what) {
  const real n = norm(v);
  if (!(n > 0) || !std::isfinite(n))
    throw InputError(std::string("wall ") + what + " must be a non-zero vector");
  for (real& c : v) c /= n;
}

/// `bins` as one list, `items`, and where each bin starts in it, `start` (one more than bins).
void flatten(const std::vector<std::vector<index_t>>& bins, std::vector<index_t>& start,
             std::vector<index_t>& items) {
  start.assign(bins.size() + 1, 0);
  items.clear();
  for (std::size_t b = 0; b < bins.size(); ++b) {
    items.insert(items.end(), bins[b].begin(), bins[b].end());
    start[b + 1] = static_cast<index_t>(items.size());
  }
}

/// Whether edge a of the polygon crosses the ray from p towards +x (one end above p, one not).
bool crosses_ray(const std::vector<std::array<real, 2>>& v, std::size_t a, const vec& p) {
  const auto& p0 = v[a];
  const auto& p1 = v[(a + 1) % v.size()];
  return (p0[1] > p[1]) != (p1[1] > p[1]) &&
         p[0] < p0[0] + (p[1] - p0[1]) * (p1[0] - p0[0]) / (p1[1] - p0[1]);
}

/// Whether p lies inside the polygon: the parity of the edges the ray from p towards +x
/// crosses, of every edge.
bool inside_polygon(const std::vector<std::array<real, 2>>& v, const vec& p) {
  bool inside = false;
  for (std::size_t a = 0; a < v.size(); ++a) inside ^= crosses_ray(v, a, p);
  return inside;
}

/// The same parity of the edges of p's band only: an edge the ray crosses has an end above
/// p's height and one not, so its band range holds p's band (and none does when p is outside
/// the polygon's heights).
bool inside_polygon_by_band(const WallSurface& s, const vec& p) {
  const auto& g = s.edge_grid;
  if (!(p[1] >= g.lowest && p[1] < g.highest)) return false;
  bool inside = false;
  const auto band = static_cast<std::size_t>(g.band_of(p[1]));
  for (index_t k = g.band_start[band]; k < g.band_start[band + 1]; ++k)
    inside ^= crosses_ray(s.vertices, g.band_edges[k], p);
  return inside;
}

/// The nearest of a polygon's edges to p: its distance and the normal of its closest point
/// towards p (on an edge's interior the edge's normal, at a vertex the direction to p). Edges
/// are offered in increasing order; a tie keeps the first.
struct NearestEdge {
  const std::vector<std::array<real, 2>>& v;
  const vec& p;
  real best = std::numeric_limits<real>::max();
  vec normal{0, 0, 0};

  void offer(std::size_t a) {
    const auto& p0 = v[a];
    const auto& p1 = v[(a + 1) % v.size()];
    const real ex = p1[0] - p0[0], ey = p1[1] - p0[1];
    const real t = std::clamp(((p[0] - p0[0]) * ex + (p[1] - p0[1]) * ey) / (ex * ex + ey * ey), 0.0, 1.0);
    const real dx = p[0] - (p0[0] + t * ex), dy = p[1] - (p0[1] + t * ey);
    const real d = std::sqrt(dx * dx + dy * dy);
    if (!(d < best)) return;
    best = d;
    if (d > 0 && (t == 0.0 || t == 1.0)) {
      normal = {dx / d, dy / d, 0};
    } else {
      const real len = std::sqrt(ex * ex + ey * ey);
      normal = {ey / len, -ex / len, 0};  // right-hand normal, turned towards p
      if (normal[0] * dx + normal[1] * dy < 0) normal = {-normal[0], -normal[1], 0};
    }
  }
};

/// The signed distance (positive outside) and outward normal of p from the polygon's nearest
/// edge; `inside`: p inside the polygon.
WallContact signed_polygon_distance(const NearestEdge& nearest, bool inside) {
  WallContact c;
  c.distance = inside ? -nearest.best : nearest.best;
  c.normal = inside ? vec{-nearest.normal[0], -nearest.normal[1], 0} : nearest.normal;
  if (nearest.best == 0) c.normal = {0, 0, 0};
  return c;
}

void build_edge_grid(WallSurface& s) {
  auto& g = s.edge_grid;
  const auto& v = s.vertices;
  const std::size_t n = v.size();
  std::array<real, 2> lo{std::numeric_limits<real>::max(), std::numeric_limits<real>::max()};
  std::array<real, 2> hi{std::numeric_limits<real>::lowest(), std::numeric_limits<real>::lowest()};
  std::vector<real> lengths(n);
  for (std::size_t a = 0; a < n; ++a) {
    const auto& p0 = v[a];
    const auto& p1 = v[(a + 1) % n];
    for (int k = 0; k < 2; ++k) lo[k] = std::min(lo[k], p0[k]), hi[k] = std::max(hi[k], p0[k]);
    lengths[a] = std::max(std::abs(p1[0] - p0[0]), std::abs(p1[1] - p0[1]));
  }
  // Cells about the median edge's size, at most 16 a vertex: short edges in a cell or a few,
  // long ones in every cell along them.
  std::nth_element(lengths.begin(), lengths.begin() + static_cast<std::ptrdiff_t>(n / 2), lengths.end());
  real cell = std::max({lengths[n / 2], 1e-9 * std::max(hi[0] - lo[0], hi[1] - lo[1]), 1e-300});
  for (;;) {
    for (int k = 0; k < 2; ++k)
      g.dims[k] = std::max<std::int64_t>(1, static_cast<std::int64_t>((hi[k] - lo[k]) / cell) + 1);
    if (g.dims[0] * g.dims[1] <= 16 * static_cast<std::int64_t>(n) + 16) break;
    cell *= 1.5;
  }
  g.origin = lo;
  g.cell_size = cell;
  std::vector<std::vector<index_t>> bins(static_cast<std::size_t>(g.dims[0] * g.dims[1]));
  for (std::size_t a = 0; a < n; ++a) {
    const auto& p0 = v[a];
    const auto& p1 = v[(a + 1) % n];
    std::array<std::int64_t, 2> first{}, last{};
    for (int k = 0; k < 2; ++k) {
      first[k] = g.cell_of(std::min(p0[k], p1[k]), k);
      last[k] = g.cell_of(std::max(p0[k], p1[k]), k);
    }
    for (std::int64_t y = first[1]; y <= last[1]; ++y)
      for (std::int64_t x = first[0]; x <= last[0]; ++x)
        bins[y * g.dims[0] + x].push_back(static_cast<index_t>(a));
  }
  flatten(bins, g.cell_start, g.cell_edges);
  // Horizontal bands, one an edge up to 4,096, over the vertices' heights.
  g.lowest = lo[1];
  g.highest = hi[1];
  g.bands = std::clamp<std::int64_t>(static_cast<std::int64_t>(n), 1, 4096);
  g.band_height = hi[1] > lo[1] ? (hi[1] - lo[1]) / static_cast<real>(g.bands) : 1.0;
  std::vector<std::vector<index_t>> band_bins(static_cast<std::size_t>(g.bands));
  for (std::size_t a = 0; a < n; ++a) {
    const real y0 = v[a][1], y1 = v[(a + 1) % n][1];
    for (std::int64_t b = g.band_of(std::min(y0, y1)); b <= g.band_of(std::max(y0, y1)); ++b)
      band_bins[static_cast<std::size_t>(b)].push_back(static_cast<index_t>(a));
  }
  flatten(band_bins, g.band_start, g.band_edges);
}

/// The contact of p with a polygon surface within `reach` (Wall::contacts). The nearest edge is
/// sought among the edges whose boxes share a cell with the box of p widened by the reach (and
/// a margin for round-off): every edge within the reach is among them, offered in order, so a
/// contact found there is the one all edges give. Only a point on the particles' far side with
/// no edge that near (deep in an obstacle, or out of a container) asks every edge.
bool polygon_contact(const WallSurface& s, const vec& p, real reach, WallContact& out) {
  const auto& g = s.edge_grid;
  const bool inside = inside_polygon_by_band(s, p);
  const real widened = reach + 1e-9 * (reach + g.cell_size + std::abs(p[0]) + std::abs(p[1]));
  thread_local std::vector<index_t> candidates;
  candidates.clear();
  for (std::int64_t y = g.cell_of(p[1] - widened, 1); y <= g.cell_of(p[1] + widened, 1); ++y) {
    for (std::int64_t x = g.cell_of(p[0] - widened, 0); x <= g.cell_of(p[0] + widened, 0); ++x) {
      const auto c = static_cast<std::size_t>(y * g.dims[0] + x);
      candidates.insert(candidates.end(), g.cell_edges.begin() + g.cell_start[c],
                        g.cell_edges.begin() + g.cell_start[c + 1]);
    }
  }
  std::sort(candidates.begin(), candidates.end());
  candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
  NearestEdge near{s.vertices, p};
  for (const index_t a : candidates) near.offer(a);
  if (near.best <= reach) {
    out = signed_polygon_distance(near, inside);
  } else {
    if (inside == s.inside) return false;  // on the particles' side, beyond the reach
    out = polygon_distance(s, p);
  }
  if (s.inside) {
    out.distance = -out.distance;
    for (real& c : out.normal) c = -c;
  }
  return true;
}

void build_triangle_grid(WallSurface& s) {
  auto& g = s.grid;
  std::array<real, 3> lo{}, hi{};
  lo.fill(std::numeric_limits<real>::max());
  hi.fill(std::numeric_limits<real>::lowest());
  real extent = 0;
  auto bounds = [&](const std::array<index_t, 3>& t, int k) {
    real tlo = std::numeric_limits<real>::max(), thi = std::numeric_limits<real>::lowest();
    for (index_t v : t) {
      tlo = std::min(tlo, s.mesh_vertices[v][k]);
      thi = std::max(thi, s.mesh_vertices[v][k]);
    }
    return std::make_pair(tlo, thi);
  };
  for (const auto& t : s.mesh_triangles) {
    for (int k = 0; k < 3; ++k) {
      const auto [tlo, thi] = bounds(t, k);
      lo[k] = std::min(lo[k], tlo);
      hi[k] = std::max(hi[k], thi);
      extent = std::max(extent, thi - tlo);
    }
  }
  // Cells about the size of the largest triangle, at most ~64 per triangle in all.
  real cell = std::max(extent, 1e-12);
  for (;;) {
    std::int64_t cells = 1;
    for (int k = 0; k < 3; ++k) {
      g.dims[k] = std::max<std::int64_t>(1, static_cast<std::int64_t>((hi[k] - lo[k]) / cell) + 1);
      cells *= g.dims[k];
    }
    if (cells <= 64 * static_cast<std::int64_t>(s.mesh_triangles.size()) + 64) break;
    cell *= 1.5;
  }
  g.origin = lo;
  g.cell_size = cell;
  const std::size_t cells = static_cast<std::size_t>(g.dims[0] * g.dims[1] * g.dims[2]);
  std::vector<std::vector<index_t>> bins(cells);
  for (index_t t = 0; t < s.mesh_triangles.size(); ++t) {
    std::array<std::int64_t, 3> a{}, b{};
    for (int k = 0; k < 3; ++k) {
      const auto [tlo, thi] = bounds(s.mesh_triangles[t], k);
      a[k] = std::clamp<std::int64_t>(static_cast<std::int64_t>((tlo - lo[k]) / cell), 0, g.dims[k] - 1);
      b[k] = std::clamp<std::int64_t>(static_cast<std::int64_t>((thi - lo[k]) / cell), 0, g.dims[k] - 1);
    }
    for (std::int64_t z = a[2]; z <= b[2]; ++z)
      for (std::int64_t y = a[1]; y <= b[1]; ++y)
        for (std::int64_t x = a[0]; x <= b[0]; ++x) bins[(z * g.dims[1] + y) * g.dims[0] + x].push_back(t);
  }
  flatten(bins, g.cell_start, g.cell_triangles);
}

/// Closest triangle to p within reach: signed distance (positive on the particles' side) and
/// the normal towards the particles. Returns false when no triangle is within reach.
bool triangle_mesh_contact(const WallSurface& s, const vec& p, real reach, WallContact& out) {
  const auto& g = s.grid;
  std::array<std::int64_t, 3> a{}, b{};
  for (int k = 0; k < 3; ++k) {
    const real lo = (p[k] - reach - g.origin[k]) / g.cell_size,
               hi = (p[k] + reach - g.origin[k]) / g.cell_size;
    if (hi < 0 || lo >= static_cast<real>(g.dims[k])) return false;
    a[k] = std::max<std::int64_t>(0, static_cast<std::int64_t>(lo));
    b[k] = std::min<std::int64_t>(g.dims[k] - 1, static_cast<std::int64_t>(hi));
  }
  real best = reach * reach;
  bool found = false;
  vec best_point{}, best_face{};
  for (std::int64_t z = a[2]; z <= b[2]; ++z)
    for (std::int64_t y = a[1]; y <= b[1]; ++y)
      for (std::int64_t x = a[0]; x <= b[0]; ++x) {
        const std::int64_t cell = (z * g.dims[1] + y) * g.dims[0] + x;
        for (index_t k = g.cell_start[cell]; k < g.cell_start[cell + 1]; ++k) {
          const auto& t = s.mesh_triangles[g.cell_triangles[k]];
          const vec& va = s.mesh_vertices[t[0]];
          const vec& vb = s.mesh_vertices[t[1]];
          const vec& vc = s.mesh_vertices[t[2]];
          const vec q = closest_point_on_triangle(p, va, vb, vc);
          const real d2 =
              (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]);
          if (d2 < best) {
            best = d2;
            found = true;
            best_point = q;
            best_face = cross({vb[0] - va[0], vb[1] - va[1], vb[2] - va[2]},
                              {vc[0] - va[0], vc[1] - va[1], vc[2] - va[2]});
          }
        }
      }
  if (!found) return false;
  const real face_norm = norm(best_face);
  vec face{best_face[0] / face_norm, best_face[1] / face_norm, best_face[2] / face_norm};
  if (s.inside) face = {-face[0], -face[1], -face[2]};  // towards the particles
  const vec offset{p[0] - best_point[0], p[1] - best_point[1], p[2] - best_point[2]};
  const real distance = std::sqrt(best);
  const real side = dot(offset, face);
  if (distance > 0 && std::abs(side) > 1e-12 * distance) {
    const real sign = side > 0 ? 1.0 : -1.0;
    out = {sign * distance,
           {sign * offset[0] / distance, sign * offset[1] / distance, sign * offset[2] / distance}};
  } else {
    out = {side >= 0 ? distance : -distance, face};
  }
  return true;
}

}  // namespace

WallContact polygon_distance(const WallSurface& s, const std::array<real, 3>& p) {
  NearestEdge every{s.vertices, p};
  for (std::size_t a = 0; a < s.vertices.size(); ++a) every.offer(a);
  return signed_polygon_distance(every, inside_polygon(s.vertices, p));
}

std::array<real, 3> closest_point_on_triangle(const std::array<real, 3>& p, const std::array<real, 3>& a,
                                              const std::array<real, 3>& b, const std::array<real, 3>& c) {
  const vec ab{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, ac{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const vec ap{p[0] - a[0], p[1] - a[1], p[2] - a[2]};
  const real d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const vec bp{p[0] - b[0], p[1] - b[1], p[2] - b[2]};
  const real d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const real vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const real v = d1 / (d1 - d3);
    return {a[0] + v * ab[0], a[1] + v * ab[1], a[2] + v * ab[2]};
  }
  const vec cp{p[0] - c[0], p[1] - c[1], p[2] - c[2]};
  const real d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const real vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const real w = d2 / (d2 - d6);
    return {a[0] + w * ac[0], a[1] + w * ac[1], a[2] + w * ac[2]};
  }
  const real va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const real w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {b[0] + w * (c[0] - b[0]), b[1] + w * (c[1] - b[1]), b[2] + w * (c[2] - b[2])};
  }
  const real denominator = 1 / (va + vb + vc);
  const real v = vb * denominator, w = vc * denominator;
  return {a[0] + ab[0] * v + ac[0] * w, a[1] + ab[1] * v + ac[1] * w, a[2] + ab[2] * v + ac[2] * w};
}

void Wall::validate(int dimension) {
  if (surfaces.empty()) throw InputError("wall '" + name + "' has no surface");
  function.validate();
  if (motion == Motion::translation) normalise(direction, "translation direction");
  if (motion == Motion::rotation) {
    normalise(axis, "rotation axis");
    if (dimension == 2 && (std::abs(axis[2]) != 1.0))
      throw InputError("in 2D, walls rotate about the z axis");
  }
  extent = 0;
  for (WallSurface& s : surfaces) {
    switch (s.kind) {
      case WallSurface::Kind::plane:
        normalise(s.normal, "plane normal");
        if (dimension == 2 && s.normal[2] != 0)
          throw InputError("a 2D plane wall needs a normal in the x-y plane");
        extent =
            std::max(extent, norm({s.point[0] - center[0], s.point[1] - center[1], s.point[2] - center[2]}));
        break;
      case WallSurface::Kind::box_inside:
      case WallSurface::Kind::box_outside:
        for (int k = 0; k < dimension; ++k) {
          if (!(s.upper[k] > s.lower[k]))
            throw InputError("wall box '" + name + "': upper must exceed lower");
        }
        for (int corner = 0; corner < 8; ++corner) {
          const vec q{(corner & 1) ? s.upper[0] : s.lower[0], (corner & 2) ? s.upper[1] : s.lower[1],
                      (corner & 4) ? s.upper[2] : s.lower[2]};
          extent = std::max(extent, norm({q[0] - center[0], q[1] - center[1], q[2] - center[2]}));
        }
        break;
      case WallSurface::Kind::circle_inside:
      case WallSurface::Kind::circle_outside:
        if (!(s.radius > 0)) throw InputError("wall circle '" + name + "': radius must be positive");
        if (dimension == 2) s.normal = {0, 0, 1};
        normalise(s.normal, "cylinder axis");
        extent =
            std::max(extent, norm({s.point[0] - center[0], s.point[1] - center[1], s.point[2] - center[2]}) +
                                 s.radius);
        break;
      case WallSurface::Kind::triangles:
        if (dimension != 3) throw InputError("triangle-mesh walls are 3D; use polygons in 2D");
        if (s.mesh_triangles.empty())
          throw InputError("wall '" + name + "': the triangle mesh has no triangles");
        for (std::size_t t = 0; t < s.mesh_triangles.size(); ++t) {
          const auto& tri = s.mesh_triangles[t];
          for (index_t v : tri) {
            if (v >= s.mesh_vertices.size()) {
              throw InputError("wall '" + name + "': triangle " + std::to_string(t) +
                               " refers to a missing vertex");
            }
          }
          const vec& a = s.mesh_vertices[tri[0]];
          const vec& b = s.mesh_vertices[tri[1]];
          const vec& c = s.mesh_vertices[tri[2]];
          if (!(norm(cross({b[0] - a[0], b[1] - a[1], b[2] - a[2]},
                           {c[0] - a[0], c[1] - a[1], c[2] - a[2]})) > 0)) {
            throw InputError("wall '" + name + "': triangle " + std::to_string(t) +
                             " has zero area; remove degenerate triangles from the mesh");
          }
        }
        for (const auto& v : s.mesh_vertices) {
          extent = std::max(extent, norm({v[0] - center[0], v[1] - center[1], v[2] - center[2]}));
        }
        build_triangle_grid(s);
        break;
      case WallSurface::Kind::polygon:
        if (dimension != 2) throw InputError("polygon walls are 2D; use planes or boxes in 3D");
        if (s.vertices.size() < 3) throw InputError("wall polygon '" + name + "' needs at least 3 vertices");
        for (const auto& v : s.vertices) {
          extent = std::max(extent, std::hypot(v[0] - center[0], v[1] - center[1]));
        }
        build_edge_grid(s);
        break;
    }
  }
}

std::array<real, 3> Wall::to_reference(const real* x, real t) const {
  vec p{x[0], x[1], x[2]};
  if (motion == Motion::translation) {
    const real u = function.value(t);
    for (int k = 0; k < 3; ++k) p[k] -= u * direction[k];
  } else if (motion == Motion::rotation) {
    const vec r = rotate({p[0] - center[0], p[1] - center[1], p[2] - center[2]}, axis, -function.value(t));
    p = {center[0] + r[0], center[1] + r[1], center[2] + r[2]};
  }
  return p;
}

std::array<real, 3> Wall::rotate_to_world(const std::array<real, 3>& v, real t) const {
  return motion == Motion::rotation ? rotate(v, axis, function.value(t)) : v;
}

std::array<real, 3> Wall::velocity_at(const real* x, real t) const {
  if (motion == Motion::translation) {
    const real rate = function.rate(t);
    return {rate * direction[0], rate * direction[1], rate * direction[2]};
  }
  if (motion == Motion::rotation) {
    return cross(angular_velocity(t), {x[0] - center[0], x[1] - center[1], x[2] - center[2]});
  }
  return {0, 0, 0};
}

std::array<real, 3> Wall::angular_velocity(real t) const {
  if (motion != Motion::rotation) return {0, 0, 0};
  const real rate = function.rate(t);
  return {axis[0] * rate, axis[1] * rate, axis[2] * rate};
}

real Wall::motion_bound(real t0, real t1) const {
  if (motion == Motion::fixed) return 0;
  const real change = std::abs(function.value(t1) - function.value(t0));
  if (motion == Motion::translation) return change;
  return 2.0 * extent * std::sin(std::min(change, std::numbers::pi) / 2.0);  // chord of the farthest point
}

namespace {

/// The faces of a box container within `reach` of p (one entry per face).
void box_inside_contacts(const WallSurface& s, const std::array<real, 3>& p, real reach, int dimension,
                         std::vector<WallContact>& out) {
  for (int k = 0; k < dimension; ++k) {
    const real below = p[k] - s.lower[k], above = s.upper[k] - p[k];
    if (below < reach) {
      WallContact c{below, {0, 0, 0}};
      c.normal[k] = 1;
      out.push_back(c);
    }
    if (above < reach) {
      WallContact c{above, {0, 0, 0}};
      c.normal[k] = -1;
      out.push_back(c);
    }
  }
}

/// A box obstacle within `reach` of p: the nearest point of its surface, or, for p inside it,
/// the nearest face to push it out through.
void box_outside_contact(const WallSurface& s, const std::array<real, 3>& p, real reach, int dimension,
                         std::vector<WallContact>& out) {
  vec q{}, outside{};
  bool is_outside = false;
  for (int k = 0; k < 3; ++k) {
    q[k] = k < dimension ? std::clamp(p[k], s.lower[k], s.upper[k]) : p[k];
    outside[k] = p[k] - q[k];
    is_outside = is_outside || outside[k] != 0;
  }
  if (is_outside) {
    const real d = norm(outside);
    if (d < reach) out.push_back({d, {outside[0] / d, outside[1] / d, outside[2] / d}});
    return;
  }
  WallContact c{std::numeric_limits<real>::lowest(), {0, 0, 0}};
  for (int k = 0; k < dimension; ++k) {
    const real to_lower = p[k] - s.lower[k], to_upper = s.upper[k] - p[k];
    if (-to_lower > c.distance) {
      c = {-to_lower, {0, 0, 0}};
      c.normal[k] = -1;
    }
    if (-to_upper > c.distance) {
      c = {-to_upper, {0, 0, 0}};
      c.normal[k] = 1;
    }
  }
  out.push_back(c);
}

/// A circle (cylinder) seen from inside or outside, within `reach` of p.
void circle_contact(const WallSurface& s, const std::array<real, 3>& p, real reach,
                    std::vector<WallContact>& out) {
  vec r{p[0] - s.point[0], p[1] - s.point[1], p[2] - s.point[2]};
  const real along = dot(r, s.normal);
  for (int k = 0; k < 3; ++k) r[k] -= along * s.normal[k];
  const real rho = norm(r);
  if (!(rho > 0)) return;  // on the axis: no defined normal, and far from the surface
  const vec radial{r[0] / rho, r[1] / rho, r[2] / rho};
  if (s.kind == WallSurface::Kind::circle_inside) {
    if (s.radius - rho < reach) out.push_back({s.radius - rho, {-radial[0], -radial[1], -radial[2]}});
  } else if (rho - s.radius < reach) {
    out.push_back({rho - s.radius, radial});
  }
}

}  // namespace

void Wall::contacts(std::size_t surface, const std::array<real, 3>& p, real reach, int dimension,
                    std::vector<WallContact>& out) const {
  const WallSurface& s = surfaces[surface];
  switch (s.kind) {
    case WallSurface::Kind::plane: {
      const real d = dot({p[0] - s.point[0], p[1] - s.point[1], p[2] - s.point[2]}, s.normal);
      if (d < reach) out.push_back({d, s.normal});
      break;
    }
    case WallSurface::Kind::box_inside: box_inside_contacts(s, p, reach, dimension, out); break;
    case WallSurface::Kind::box_outside: box_outside_contact(s, p, reach, dimension, out); break;
    case WallSurface::Kind::circle_inside:
    case WallSurface::Kind::circle_outside: circle_contact(s, p, reach, out); break;
    case WallSurface::Kind::triangles: {
      WallContact c;
      if (triangle_mesh_contact(s, p, reach, c) && c.distance < reach) out.push_back(c);
      break;
    }
    case WallSurface::Kind::polygon: {
      WallContact c;
      if (polygon_contact(s, p, reach, c) && c.distance < reach && (c.normal[0] != 0 || c.normal[1] != 0))
        out.push_back(c);
      break;
    }
  }
}

}  // namespace granulate
