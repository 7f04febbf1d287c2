// The surface law (contact/surface_law.hpp): the gap of a point from a surface of points with
// normals and curvatures, its gradient, and the forces of its energy.
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

#include "check.hpp"
#include "granulate/contact/surface_law.hpp"
#include "granulate/surface_anchors.hpp"

using namespace granulate;
using contact::SurfacePoint;
using contact::vec3;

namespace {

/// Points scattered on a sphere of radius R about the origin, with radial normals and 1/R.
std::vector<SurfacePoint> sphere_points(real radius, std::size_t count, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<real> normal(0, 1);
  std::vector<SurfacePoint> points;
  for (std::size_t k = 0; k < count; ++k) {
    vec3 u{normal(rng), normal(rng), normal(rng)};
    const real size = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    SurfacePoint p;
    for (int c = 0; c < 3; ++c) {
      p.normal[c] = u[c] / size;
      p.position[c] = radius * p.normal[c];
    }
    p.curvature = 1 / radius;
    points.push_back(p);
  }
  return points;
}

contact::SurfaceGap gap_at(const std::vector<SurfacePoint>& points, const vec3& p, real support) {
  contact::SurfaceGap sums;
  for (const SurfacePoint& point : points) sums.add(contact::point_terms(point, p, support));
  return sums;
}

/// E = k delta^2 tau(S) / 2 of a probe of radius r at p.
real energy(const std::vector<SurfacePoint>& points, const vec3& p, real support, real radius, real k) {
  const contact::SurfaceGap sums = gap_at(points, p, support);
  if (!sums.reached()) return 0;
  const real overlap = radius - sums.gap();
  return overlap > 0 ? 0.5 * k * overlap * overlap * contact::surface_taper(sums.weight) : 0.0;
}

}  // namespace

TEST_CASE("the surface gap is the distance to a sphere whose points lie scattered on it") {
  const real radius = 1.0, support = 0.4;
  const auto points = sphere_points(radius, 4000, 7);
  std::mt19937 rng(3);
  std::normal_distribution<real> normal(0, 1);
  for (int trial = 0; trial < 50; ++trial) {
    vec3 u{normal(rng), normal(rng), normal(rng)};
    const real size = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (const real lift : {-0.1, 0.0, 0.15}) {
      const vec3 p{(radius + lift) * u[0] / size, (radius + lift) * u[1] / size,
                   (radius + lift) * u[2] / size};
      const contact::SurfaceGap sums = gap_at(points, p, support);
      CHECK(sums.reached());
      CHECK_NEAR(sums.gap(), lift, 1e-12, 1e-12);
      const vec3 g = sums.gradient();
      for (int c = 0; c < 3; ++c) CHECK_NEAR(g[c], u[c] / size, 1e-12, 1e-12);
    }
  }
}

TEST_CASE("the surface gap of a plane of points is the height above it, with no tilt") {
  std::vector<SurfacePoint> points;
  std::mt19937 rng(5);
  std::uniform_real_distribution<real> spread(-1, 1);
  for (int k = 0; k < 300; ++k) {
    SurfacePoint p;
    p.position = {spread(rng), spread(rng), 0};
    p.normal = {0, 0, 1};
    points.push_back(p);
  }
  const contact::SurfaceGap sums = gap_at(points, {0.1, -0.2, 0.05}, 0.3);
  CHECK_NEAR(sums.gap(), 0.05, 1e-14, 1e-15);
  const vec3 g = sums.gradient();
  CHECK(std::abs(g[0]) < 1e-14 && std::abs(g[1]) < 1e-14);
  CHECK_CLOSE(g[2], 1.0, 1e-14);
}

/// Points h apart on a face of a prism through the origin: outward normal n, running from the
/// origin along the unit vector `along` (n . along = 0, both in the x-z plane) for `count`
/// spacings, and 8 spacings either way in y. `first` = 1 leaves out the points at the origin.
void add_face(std::vector<SurfacePoint>& points, const vec3& n, const vec3& along, int first, int count,
              real h) {
  for (int m = first; m <= count; ++m)
    for (int l = -8; l <= 8; ++l) {
      SurfacePoint point;
      point.position = {m * h * along[0], l * h, m * h * along[2]};
      point.normal = n;
      points.push_back(point);
    }
}

/// 2D: points h apart on the line y = 0 (normal +y), or on a circle of radius R about the
/// origin (radial normals, curvature 1/R).
std::vector<SurfacePoint> line_points(real h) {
  std::vector<SurfacePoint> points;
  for (int m = -20; m <= 20; ++m) {
    SurfacePoint point;
    point.position = {m * h, 0, 0};
    point.normal = {0, 1, 0};
    points.push_back(point);
  }
  return points;
}

std::vector<SurfacePoint> circle_points(real radius, real h) {
  std::vector<SurfacePoint> points;
  const int count = static_cast<int>(std::round(2 * std::numbers::pi * radius / h));
  for (int m = 0; m < count; ++m) {
    const real angle = 2 * std::numbers::pi * m / count;
    SurfacePoint point;
    point.normal = {std::sin(angle), std::cos(angle), 0};
    point.position = {radius * point.normal[0], radius * point.normal[1], 0};
    point.curvature = 1 / radius;
    points.push_back(point);
  }
  return points;
}

/// A surface point (r = 0, k = 1) walked in along path(depth), depth = 0.01 h, 0.02 h, ... up to
/// `deepest`: the first depth at which its energy E fell, or -1 if it never did; `last` is E at
/// the last depth walked.
template <class Path>
real first_fall(const std::vector<SurfacePoint>& points, real support, real deepest, const Path& path,
                real& last) {
  last = 0;
  for (int step = 1; 0.01 * step <= deepest + 1e-12; ++step) {
    const real depth = 0.01 * step;
    const real now = energy(points, path(depth), support, 0.0, 1.0);
    if (now < last) return depth;
    last = now;
  }
  return -1;
}

TEST_CASE("the C1 step: 0 and 1 at its bounds, either way round, and its slope") {
  for (const auto& [zero_at, one_at] : {std::pair<real, real>{0.25, 0.5}, {0.85, 0.5}, {0.0, 0.2}}) {
    CHECK(contact::smooth_step(zero_at, zero_at, one_at) == 0);
    CHECK(contact::smooth_step(one_at, zero_at, one_at) == 1);
    CHECK(contact::smooth_step(2 * zero_at - one_at, zero_at, one_at) == 0);  // beyond the bounds
    CHECK(contact::smooth_step(2 * one_at - zero_at, zero_at, one_at) == 1);
    CHECK_NEAR(contact::smooth_step(0.5 * (zero_at + one_at), zero_at, one_at), 0.5, 1e-15, 0);
    for (int k = 1; k < 20; ++k) {
      const real x = zero_at + 0.05 * k * (one_at - zero_at), step = 1e-7;
      const real slope = (contact::smooth_step(x + step, zero_at, one_at) -
                          contact::smooth_step(x - step, zero_at, one_at)) /
                         (2 * step);
      CHECK_NEAR(contact::smooth_step_slope(x, zero_at, one_at), slope, 1e-6, 1e-9);
    }
  }
}

TEST_CASE("a surface point's energy grows with its depth below a face or a hexagon's corner") {
  // E = k delta^2 tau(S) / 2 of a surface point (r = 0) pushed straight in, at places along a
  // flat face and round a 120 degree corner: it must not fall with depth down to 0.8 h, never
  // pulling a deep probe further in (it peaks 0.87-1.13 h below the face, deeper at the
  // corner). With isotropic weights W(|v| / a) it peaked 0.71-0.80 h below the face, and
  // hexagons in a pile pulled each other through (docs/validation/README.md, "The compression
  // runs under the surface law").
  const real h = 1.0, support = contact::surface_support_factor * h;
  const real c30 = std::sqrt(real(3)) / 2;
  std::vector<SurfacePoint> points;
  add_face(points, {0, 0, 1}, {1, 0, 0}, 0, 10, h);             // the top face, x from 0 to 10 h
  add_face(points, {-c30, 0, 0.5}, {-0.5, 0, -c30}, 1, 10, h);  // the side face below the corner
  for (const real x : {-0.25, 0.0, 0.3, 0.5, 1.0, 3.0, 3.5})
    for (const real y : {0.0, 0.25, 0.5}) {
      real last = 0;
      const real fell =
          first_fall(points, support, 0.8, [&](real depth) { return vec3{x, y, -depth}; }, last);
      if (fell >= 0)
        granulate_test::fail(__FILE__, __LINE__,
                             "E fell at x = " + granulate_test::show(x) + " h, y = " +
                                 granulate_test::show(y) + " h, " + granulate_test::show(fell) + " h deep");
      if (x >= 0) CHECK(last > 0);
    }
}

TEST_CASE("in 2D, a surface point's energy grows with its depth below a line or a circle of points") {
  // Points h apart on a line and on circles of radius 4.5 h to 10 h (a grain of the compression
  // pile is 5 h): E must not fall with depth down to 0.95 h (it peaks at 1.00-1.13 h; with
  // isotropic weights it peaked at 0.74-0.78 h).
  const real h = 1.0, support = contact::surface_support_factor * h;
  for (const real radius : {0.0, 4.5, 5.0, 10.0}) {
    const std::vector<SurfacePoint> points = radius == 0 ? line_points(h) : circle_points(radius, h);
    for (const real along : {0.0, 0.25, 0.5}) {
      auto path = [&](real depth) {
        if (radius == 0) return vec3{along * h, -depth, 0};
        const real angle = along * h / radius;
        return vec3{(radius - depth) * std::sin(angle), (radius - depth) * std::cos(angle), 0};
      };
      real last = 0;
      const real fell = first_fall(points, support, 0.95, path, last);
      if (fell >= 0)
        granulate_test::fail(__FILE__, __LINE__,
                             "E fell at R = " + granulate_test::show(radius) + " h, " +
                                 granulate_test::show(fell) + " h deep");
      CHECK(last > 0);
    }
  }
}

/// The forces of a probe at p against central differences of E; their sums and moments.
void check_forces(const std::vector<SurfacePoint>& points, const vec3& p, real support, real radius, real k);

TEST_CASE("the surface law's forces are minus the gradient of its energy, and balance") {
  // A probe pressed into an irregular, wavy surface: the force on p, on each s_k and on each
  // n_k against central differences of E; the forces sum to zero, and so do their moments.
  // Also at the edge of the points, where the taper brings E to zero.
  std::vector<SurfacePoint> points;
  std::mt19937 rng(11);
  std::uniform_real_distribution<real> spread(-0.5, 0.5), tilt(-0.2, 0.2), bend(-1, 1);
  for (int k = 0; k < 40; ++k) {
    SurfacePoint p;
    p.position = {spread(rng), spread(rng), 0.05 * spread(rng)};
    vec3 n{tilt(rng), tilt(rng), 1};
    const real size = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (real& c : n) c /= size;
    p.normal = n;
    p.curvature = bend(rng);
    points.push_back(p);
  }
  check_forces(points, {0.02, -0.03, 0.0}, 0.45, 0.1, 1e3);
  // Past the edge: only a few points in reach, their weights below the taper's S_0.
  const vec3 edge{0.75, 0.0, 0.0};
  const contact::SurfaceGap sums = gap_at(points, edge, 0.45);
  CHECK(sums.reached() && sums.weight < contact::surface_coverage);
  check_forces(points, edge, 0.45, 0.1, 1e3);
  // Deep below the points, where their weights fall with the end of reach.
  const vec3 deep{0.02, -0.03, -0.36};
  const contact::SurfaceGap deep_sums = gap_at(points, deep, 0.45);
  CHECK(deep_sums.reached() && deep_sums.weight < contact::surface_coverage);
  check_forces(points, deep, 0.45, 0.1, 1e3);
}

void check_forces(const std::vector<SurfacePoint>& points, const vec3& p, real support, real radius, real k) {
  const real step = 1e-7;
  const contact::SurfaceGap sums = gap_at(points, p, support);
  const real overlap = radius - sums.gap();
  const real push = k * overlap * contact::surface_taper(sums.weight);
  const real taper = 0.5 * k * overlap * overlap * contact::surface_taper_slope(sums.weight);
  CHECK(push > 0);
  const vec3 on_probe = [&] {
    const vec3 g = sums.gradient();
    return vec3{push * g[0] - taper * sums.spread[0], push * g[1] - taper * sums.spread[1],
                push * g[2] - taper * sums.spread[2]};
  }();
  vec3 total = on_probe, moment{0, 0, 0};
  auto add_moment = [&](const vec3& at, const vec3& f) {
    moment[0] += at[1] * f[2] - at[2] * f[1];
    moment[1] += at[2] * f[0] - at[0] * f[2];
    moment[2] += at[0] * f[1] - at[1] * f[0];
  };
  add_moment(p, on_probe);
  for (int c = 0; c < 3; ++c) {
    vec3 plus = p, minus = p;
    plus[c] += step;
    minus[c] -= step;
    const real slope =
        (energy(points, plus, support, radius, k) - energy(points, minus, support, radius, k)) / (2 * step);
    CHECK_NEAR(on_probe[c], -slope, 1e-5, 1e-6 * push);
  }
  for (std::size_t j = 0; j < points.size(); ++j) {
    const contact::PointTerms t = contact::point_terms(points[j], p, support);
    const vec3 share = contact::point_share(t, sums.gap(), sums.weight);
    const vec3 on_point{-push * share[0] + taper * t.weight_gradient[0],
                        -push * share[1] + taper * t.weight_gradient[1],
                        -push * share[2] + taper * t.weight_gradient[2]};
    // The force on n_j: push (w/S) t + (push (d - g) / S - Q) m, a tangential vector; moments
    // of a normal: n x F_n.
    const real fraction = t.weight / sums.weight;
    const real pull = push * (t.distance - sums.gap()) / sums.weight - taper;
    vec3 on_normal;
    for (int c = 0; c < 3; ++c)
      on_normal[c] = push * fraction * t.normal_sensitivity[c] + pull * t.weight_normal[c];
    for (int c = 0; c < 3; ++c) total[c] += on_point[c];
    add_moment(points[j].position, on_point);
    add_moment(points[j].normal, on_normal);
    for (int c = 0; c < 3; ++c) {
      auto moved = [&](real by) {
        std::vector<SurfacePoint> shifted = points;
        shifted[j].position[c] += by;
        return energy(shifted, p, support, radius, k);
      };
      CHECK_NEAR(on_point[c], -(moved(step) - moved(-step)) / (2 * step), 1e-5, 1e-6 * push);
      // Turning n_j by a small rotation keeps it a unit vector: the work of on_normal.
      auto turned = [&](real by) {
        std::vector<SurfacePoint> shifted = points;
        vec3& n = shifted[j].normal;
        vec3 axis{0, 0, 0};
        axis[c] = 1;
        const vec3 dn{axis[1] * n[2] - axis[2] * n[1], axis[2] * n[0] - axis[0] * n[2],
                      axis[0] * n[1] - axis[1] * n[0]};
        for (int d = 0; d < 3; ++d) n[d] += by * dn[d];
        const real size = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (real& x : n) x /= size;
        return energy(shifted, p, support, radius, k);
      };
      const vec3& n = points[j].normal;
      vec3 axis{0, 0, 0};
      axis[c] = 1;
      const vec3 dn{axis[1] * n[2] - axis[2] * n[1], axis[2] * n[0] - axis[0] * n[2],
                    axis[0] * n[1] - axis[1] * n[0]};
      const real work = on_normal[0] * dn[0] + on_normal[1] * dn[1] + on_normal[2] * dn[2];
      CHECK_NEAR(work, -(turned(step) - turned(-step)) / (2 * step), 1e-5, 1e-6 * push);
    }
  }
  for (int c = 0; c < 3; ++c) {
    CHECK(std::abs(total[c]) < 1e-12 * push);
    CHECK(std::abs(moment[c]) < 1e-12 * push);
  }
}

TEST_CASE("surface curvature: 1/R on a sphere, 0 on a plane, faces not averaged across an edge") {
  std::vector<real> points, normals;
  const real radius = 2.0;
  std::mt19937 rng(2);
  std::normal_distribution<real> normal(0, 1);
  for (int k = 0; k < 400; ++k) {
    vec3 u{normal(rng), normal(rng), normal(rng)};
    const real size = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (int c = 0; c < 3; ++c) {
      normals.push_back(u[c] / size);
      points.push_back(radius * u[c] / size);
    }
  }
  std::vector<index_t> all(400);
  for (index_t k = 0; k < 400; ++k) all[k] = k;
  for (const index_t a : {0u, 17u, 399u})
    CHECK_CLOSE(surface_curvature(points, normals, a, all, 1.0), 0.5, 1e-12);
  // Two faces of a box meeting at x = 0: points on z = 0 (x < 0) and on x = 0 (z < 0).
  std::vector<real> box, box_normals;
  for (int k = 0; k < 5; ++k) {
    box.insert(box.end(), {-0.1 * k, 0.1 * (k % 2), 0});
    box_normals.insert(box_normals.end(), {0, 0, 1});
    box.insert(box.end(), {0, 0.1 * (k % 3), -0.1 * k - 0.05});
    box_normals.insert(box_normals.end(), {1, 0, 0});
  }
  std::vector<index_t> near(10);
  for (index_t k = 0; k < 10; ++k) near[k] = k;
  CHECK(surface_curvature(box, box_normals, 0, near, 1.0) == 0.0);
  CHECK(surface_curvature(box, box_normals, 1, near, 1.0) == 0.0);
}

TEST_CASE("osculating shares of points a spacing apart sum to about 1 wherever the contact lies") {
  // The shares c_d W(c / 1.5 h) of points h apart along a line (2D) or on a square grid (3D),
  // about a contact point at every offset: 0.922-1.091 and 0.892-1.170 (the integral is 1).
  const real h = 1e-4, support = contact::surface_support_factor * h;
  for (int step = 0; step <= 20; ++step) {
    const real fx = 0.05 * step;
    real line = 0;
    for (int m = -3; m <= 3; ++m)
      line += contact::osculating_scale(2) * contact::surface_weight(std::abs(m + fx) * h / support);
    CHECK(line > 0.92 && line < 1.10);
    for (int other = 0; other <= 20; ++other) {
      const real fy = 0.05 * other;
      real plane = 0;
      for (int m = -3; m <= 3; ++m)
        for (int n = -3; n <= 3; ++n)
          plane += contact::osculating_scale(3) *
                   contact::surface_weight(std::hypot(m + fx, n + fy) * h / support);
      CHECK(plane > 0.89 && plane < 1.18);
    }
  }
}
