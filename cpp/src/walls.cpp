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

/// Signed distance from p to a polygon's boundary (positive outside) and the outward normal
/// of the closest point (2D, z ignored).
WallContact polygon_distance(const std::vector<std::array<real, 2>>& v, const vec& p) {
  real best = std::numeric_limits<real>::max();
  vec best_normal{0, 0, 0};
  bool inside = false;
  const std::size_t n = v.size();
  for (std::size_t a = 0; a < n; ++a) {
    const auto& p0 = v[a];
    const auto& p1 = v[(a + 1) % n];
    if ((p0[1] > p[1]) != (p1[1] > p[1]) &&
        p[0] < p0[0] + (p[1] - p0[1]) * (p1[0] - p0[0]) / (p1[1] - p0[1])) {
      inside = !inside;
    }
    const real ex = p1[0] - p0[0], ey = p1[1] - p0[1];
    const real t = std::clamp(((p[0] - p0[0]) * ex + (p[1] - p0[1]) * ey) / (ex * ex + ey * ey), 0.0, 1.0);
    const real dx = p[0] - (p0[0] + t * ex), dy = p[1] - (p0[1] + t * ey);
    const real d = std::sqrt(dx * dx + dy * dy);
    if (d < best) {
      best = d;
      // On an edge's interior the normal is the edge normal; at a vertex, the direction to p.
      if (d > 0 && (t == 0.0 || t == 1.0)) {
        best_normal = {dx / d, dy / d, 0};
      } else {
        const real len = std::sqrt(ex * ex + ey * ey);
        best_normal = {ey / len, -ex / len, 0};  // right-hand normal; fixed below by the inside test
        if (best_normal[0] * dx + best_normal[1] * dy < 0)
          best_normal = {-best_normal[0], -best_normal[1], 0};
      }
    }
  }
  WallContact c;
  c.distance = inside ? -best : best;
  // Normal pointing away from the polygon's interior.
  c.normal = inside ? vec{-best_normal[0], -best_normal[1], 0} : best_normal;
  if (best == 0) c.normal = {0, 0, 0};
  return c;
}

}  // namespace

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
      case WallSurface::Kind::polygon:
        if (dimension != 2) throw InputError("polygon walls are 2D; use planes or boxes in 3D");
        if (s.vertices.size() < 3) throw InputError("wall polygon '" + name + "' needs at least 3 vertices");
        for (const auto& v : s.vertices) {
          extent = std::max(extent, std::hypot(v[0] - center[0], v[1] - center[1]));
        }
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
    const vec w{axis[0] * function.rate(t), axis[1] * function.rate(t), axis[2] * function.rate(t)};
    return cross(w, {x[0] - center[0], x[1] - center[1], x[2] - center[2]});
  }
  return {0, 0, 0};
}

real Wall::motion_bound(real t0, real t1) const {
  if (motion == Motion::fixed) return 0;
  const real change = std::abs(function.value(t1) - function.value(t0));
  if (motion == Motion::translation) return change;
  return 2.0 * extent * std::sin(std::min(change, std::numbers::pi) / 2.0);  // chord of the farthest point
}

void Wall::contacts(std::size_t surface, const std::array<real, 3>& p, real reach, int dimension,
                    std::vector<WallContact>& out) const {
  const WallSurface& s = surfaces[surface];
  switch (s.kind) {
    case WallSurface::Kind::plane: {
      const real d = dot({p[0] - s.point[0], p[1] - s.point[1], p[2] - s.point[2]}, s.normal);
      if (d < reach) out.push_back({d, s.normal});
      break;
    }
    case WallSurface::Kind::box_inside:
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
      break;
    case WallSurface::Kind::box_outside: {
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
      } else {  // inside the obstacle: pushed out through the nearest face
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
      break;
    }
    case WallSurface::Kind::circle_inside:
    case WallSurface::Kind::circle_outside: {
      vec r{p[0] - s.point[0], p[1] - s.point[1], p[2] - s.point[2]};
      const real along = dot(r, s.normal);
      for (int k = 0; k < 3; ++k) r[k] -= along * s.normal[k];
      const real rho = norm(r);
      if (!(rho > 0)) break;  // on the axis: no defined normal, and far from the surface
      const vec radial{r[0] / rho, r[1] / rho, r[2] / rho};
      if (s.kind == WallSurface::Kind::circle_inside) {
        if (s.radius - rho < reach) out.push_back({s.radius - rho, {-radial[0], -radial[1], -radial[2]}});
      } else if (rho - s.radius < reach) {
        out.push_back({rho - s.radius, radial});
      }
      break;
    }
    case WallSurface::Kind::polygon: {
      WallContact c = polygon_distance(s.vertices, p);
      if (s.inside) {
        c.distance = -c.distance;
        for (real& v : c.normal) v = -v;
      }
      if (c.distance < reach && (c.normal[0] != 0 || c.normal[1] != 0)) out.push_back(c);
      break;
    }
  }
}

}  // namespace granulate
