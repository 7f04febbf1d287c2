// Contact against a body's smooth surface: the gap of a point from a surface given by points with
// normals and curvatures (an implicit moving least-squares surface with osculating spheres).
//
// Body B's surface near a probe point p is seen through its surface points k (position s_k,
// unit outward normal n_k, mean curvature kappa_k; see contact/surface_centres.hpp) within the
// support radius a of p. Each point's osculating sphere (a plane where kappa = 0) gives the
// signed distance of p from the surface as seen from k,
//   d_k = (|kappa v + n_k| - 1) / kappa = (2 n_k . v + kappa |v|^2) / (|kappa v + n_k| + 1),
// v = p - s_k (the second form holds for every kappa, 0 included), and the surface is their
// weighted mean (after Kolluri 2005, "Provably good moving least squares", with spheres for
// planes),
//   g(p) = sum_k w_k d_k / sum_k w_k,   w_k = W(|t_k| / a) chi(|v| / a),
// W(q) = (1 - q)^4 (1 + 4 q) (Wendland C2, zero for q >= 1) of the probe's distance along the
// point's tangent plane, t_k = v - (n_k . v) n_k, cut off smoothly in the distance |v| by chi
// (1 to |v| = reach_start a, 0 from reach_end a). g is exact (the distance to the sphere, at
// any p in reach) for points on a sphere or circle with radial normals and curvature 1/R, and
// on a plane, however irregular the points and whatever the weights; a lattice's outer layer,
// a conforming discretisation's and a mesh's boundary differ only in where the points lie. Its
// gradient
//   G = dg/dp = sum_k [w_k u_k + (d_k - g) e_k] / S,   u_k = (kappa v + n_k) / |kappa v + n_k|,
//   e_k = dw_k/dp = chi W'(|t|/a) t / (a |t|) + W chi'(|v|/a) v / (a |v|),  S = sum_k w_k,
// is the surface's normal there: smooth, with no node-scale tilt, whatever the two meshes.
// The weight counts a point by the probe's place along the surface, not by its depth below
// it: with the isotropic W(|v| / a) (Kolluri's) S fell with depth, and so did the energy
// below, which peaked 0.71-0.80 h below a face of points h apart (a = 1.5 h) and fell deeper
// in: a probe pressed that far was pulled in, and hexagon corners pressed together in a pile
// pulled each other through and broke bonds at a twentieth of the grains' strength. With the
// tangential weight E grows with depth to 0.87-1.13 h below a face in 3D (deeper at a corner)
// and to 1.00-1.13 h in 2D, where chi ends the points' reach (cpp/tests/test_surface_law.cpp).
//
// A probe of contact radius r (0 for a surface point, which touches when it crosses the
// surface; rho for a node without one) has the energy E = k delta^2 tau(S) / 2, delta = r - g > 0.
// The taper tau(S) = c^2 (3 - 2 c), c = S / S_0 (1 for c >= 1), brings E smoothly to zero where
// the probe leaves the reach of the last points (past a corner or the edge of a fragment's old
// surface, where a mean of one point's plane would still say "inside" and E would jump, or
// deeper than chi reaches, where the gap is a mean of weights near zero that swings as points
// come and go); on a surface S is well above S_0. E depends only on the vectors p - s_k and
// on the normals n_k, so it is unchanged by a translation or rotation of everything: the exact
// forces below sum to zero in force and in moment (linear and angular momentum are conserved to
// round-off) and do no work over a closed path (energy is conserved). With P = k delta tau (the
// push) and Q = k delta^2 tau'(S) / 2:
//   on p:      P G - Q sum_k e_k,
//   on s_k:   -P G_k + Q e_k,      G_k = [w_k u_k + (d_k - g) e_k] / S   (sum_k G_k = G),
//   on n_k:    P (w_k / S) (v - (n_k . v) n_k) / |kappa v + n_k| + (P (d_k - g) / S - Q) m_k,
//              m_k = dw_k/dn_k = -chi W'(|t|/a) (n_k . v) t / (a |t|)   (tangential parts;
//              contact/surface_centres.hpp turns them into forces on the nodes that carry n_k).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "granulate/types.hpp"

namespace granulate::contact {

using vec3 = std::array<real, 3>;

/// One point of a body's contact surface in the current configuration.
struct SurfacePoint {
  vec3 position{0, 0, 0};  ///< s [m]
  vec3 normal{0, 0, 0};    ///< unit outward normal
  real curvature = 0;      ///< mean curvature kappa [1/m]: 1/R on a convex sphere, 0 on a plane
};

/// The support radius of a body's surface points, over its mesh size: large enough that a
/// probe anywhere on the surface of a rotated lattice or of a mesh has several points in reach,
/// small enough that the next layer of nodes in does not reach the surface.
inline constexpr real surface_support_factor = 1.5;

/// The C1 step s(x) = b^2 (3 - 2 b), b = (x - zero_at) / (one_at - zero_at): 0 up to zero_at,
/// 1 from one_at (either bound may be the larger), smooth between. The reach, the taper, the
/// facing shares and the fade below are such steps.
inline real smooth_step(real x, real zero_at, real one_at) {
  const real b = (x - zero_at) / (one_at - zero_at);
  if (!(b > 0)) return 0;
  if (!(b < 1)) return 1;
  return b * b * (3 - 2 * b);
}

/// ds/dx = 6 b (1 - b) / (one_at - zero_at) between the bounds, 0 outside.
inline real smooth_step_slope(real x, real zero_at, real one_at) {
  const real b = (x - zero_at) / (one_at - zero_at);
  if (!(b > 0) || !(b < 1)) return 0;
  return 6 * b * (1 - b) / (one_at - zero_at);
}

/// Where a point's weight falls from whole to nothing with the probe's distance from it:
/// chi(q) = 1 for q = |v| / a <= reach_start, b^2 (3 - 2 b) with b = (reach_end - q) /
/// (reach_end - reach_start) between, 0 from q = reach_end (see above): the points' reach is
/// reach_end a. The weights must end where the taper does: a taper of tangential weights cut
/// off from q = 0.7 to 1, over a gap of Kolluri's weights, kept probes at the edge of reach,
/// where the gap's weights summed to a twentieth of a face's, at a tenth of their energy; their
/// gaps swung as points came and went, and an isolated drum of soft grains gained 1 % energy in
/// a step (test_soft_grains_crushed_on_thin_protrusions_keep_their_energy).
inline constexpr real reach_start = 0.5, reach_end = 0.85;

/// chi(q) (see reach_start).
inline real reach_cutoff(real q) {
  return smooth_step(q, reach_end, reach_start);
}

/// d chi / dq.
inline real reach_cutoff_slope(real q) {
  return smooth_step_slope(q, reach_end, reach_start);
}

/// S_0 of the taper: the weight of one point at 0.54 of the support radius.
inline constexpr real surface_coverage = 0.2;

/// tau(S) = c^2 (3 - 2 c), c = S / S_0, and 1 for c >= 1 (see above).
inline real surface_taper(real weight) {
  return smooth_step(weight, 0, surface_coverage);
}

/// d tau / dS.
inline real surface_taper_slope(real weight) {
  return smooth_step_slope(weight, 0, surface_coverage);
}

/// The points of a probe's sums are those whose normals face the probe: the faces at a corner
/// (down to a 37 degree wedge) count together, the far side of a wall or protrusion thinner
/// than the support does not (its normals point the other way, and would pull a deep probe
/// through). A probe with a surface point of its own (normal n_p) faces along -n_p, and a
/// point's share psi(c), c = n_k . (-n_p), rises smoothly from 0 at c = facing_start (143
/// degrees) to 1 at facing_end (120 degrees), psi = b^2 (3 - 2 b); its derivatives (on n_k and
/// on n_p) keep the energy exact. A probe without one (a node on a crack face) faces along
/// the normal of its nearest point, and counts the points with c > facing_start whole. The
/// nearest point's normal had been every probe's reference: when the nearest point changed
/// at a corner, points left or joined the sums at once, and the energy jumped (an isolated
/// elastic assembly of soft grains in a drum with thin protrusions gained energy at such
/// steps).
inline constexpr real facing_start = -0.8, facing_end = -0.5;

/// c = n_k . facing.
inline real facing_cosine(const SurfacePoint& point, const vec3& facing) {
  return point.normal[0] * facing[0] + point.normal[1] * facing[1] + point.normal[2] * facing[2];
}

/// psi of point k for a probe facing along `facing`: smooth (see facing_start), or whole or
/// nothing.
inline real facing_share(const SurfacePoint& point, const vec3& facing, bool smooth) {
  const real c = facing_cosine(point, facing);
  if (!smooth) return c > facing_start ? 1.0 : 0.0;
  return smooth_step(c, facing_start, facing_end);
}

/// d psi / d c (0 where psi is whole or nothing).
inline real facing_share_slope(const SurfacePoint& point, const vec3& facing, bool smooth) {
  return smooth ? smooth_step_slope(facing_cosine(point, facing), facing_start, facing_end) : 0.0;
}

/// A surface point's fade phi(rho), rho = |A| / |A_0|: its anchored vector against the
/// reference's (contact/surface_centres.hpp). The point's weight in the sums of the probes that
/// see it is phi w, and its own probe's stiffness phi k: 1 while its neighbourhood keeps its
/// shape (rho >= fade_end), 0 where the neighbourhood has folded so far that the normal
/// A / |A| means nothing (rho <= fade_start), and phi = c^2 (3 - 2 c), c = (rho - fade_start) /
/// (fade_end - fade_start), between. Without it, a grain crushed flat at a contact (a soft
/// grain hitting a thin protrusion at 70 % of its wave speed) took |A| to 0.007 |A_0|, the
/// levers 1 / |A| of its points' forces made the contact hundreds of times stiffer than the
/// time step allows, and an isolated elastic assembly gained energy twelvefold; the fade keeps
/// those levers below 1 / (fade_start |A_0|). Its forces (phi' along n on A) keep the energy
/// exact.
inline constexpr real fade_start = 0.25, fade_end = 0.5;

/// phi(rho) (see fade_start).
inline real surface_fade(real rho) {
  return smooth_step(rho, fade_start, fade_end);
}

/// d phi / d rho.
inline real surface_fade_slope(real rho) {
  return smooth_step_slope(rho, fade_start, fade_end);
}

/// Wendland's C2 kernel W(q) = (1 - q)^4 (1 + 4 q), q = distance / support, zero for q >= 1.
inline real surface_weight(real q) {
  if (!(q < 1)) return 0;
  const real u = 1 - q;
  return u * u * u * u * (1 + 4 * q);
}

/// dW/dq = -20 q (1 - q)^3.
inline real surface_weight_slope(real q) {
  if (!(q < 1)) return 0;
  const real u = 1 - q;
  return -20 * q * u * u * u;
}

/// A round particle's surface point's share of a wall contact (contact/surface_centres.hpp):
/// its osculating sphere meets the wall at the chord c = r |n + m| from the point (r = 1 /
/// kappa, n its normal, m the wall's towards the particle), and w = c_d W(c / a) with a = 1.5 h
/// and c_d = 1 in 2D, 7 / (2.25 pi) in 3D, the integral of W over the line (plane) divided by
/// h (h^2): with points h apart, sum_k w_k is about 1 around the contact however the particle
/// has turned.
inline real osculating_scale(int dimension) {
  return dimension == 2 ? 1.0 : 7.0 / (2.25 * std::numbers::pi);
}

/// The terms of one surface point for a probe at p: its weight w, distance d, gradient u of d,
/// gradient e of w, the tangential sensitivity t = (v - (n . v) n) / |kappa v + n| of d to its
/// normal, and m, the tangential gradient of w on its normal.
struct PointTerms {
  real weight = 0, distance = 0;
  vec3 gradient{0, 0, 0}, weight_gradient{0, 0, 0}, normal_sensitivity{0, 0, 0}, weight_normal{0, 0, 0};
};

/// The terms of point k for a probe at p with support radius a (weight 0 out of reach).
inline PointTerms point_terms(const SurfacePoint& point, const vec3& p, real support) {
  PointTerms t;
  const vec3 v{p[0] - point.position[0], p[1] - point.position[1], p[2] - point.position[2]};
  const real length2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
  const real length = std::sqrt(length2);
  const real cut = reach_cutoff(length / support);
  if (cut == 0) return t;
  const real kappa = point.curvature;
  const vec3& n = point.normal;
  const real along = n[0] * v[0] + n[1] * v[1] + n[2] * v[2];
  // |t| and its derivatives: d|t|/dp = t / |t|, d|t|/dn = -(n . v) t / |t| (tangential).
  const real side = std::sqrt(std::max(length2 - along * along, real(0)));
  const real lateral = surface_weight(side / support);
  t.weight = cut * lateral;
  if (t.weight == 0) return t;
  const vec3 a{kappa * v[0] + n[0], kappa * v[1] + n[1], kappa * v[2] + n[2]};
  const real size = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  t.distance = (2 * along + kappa * length2) / (size + 1);
  const real lateral_slope = side > 0 ? cut * surface_weight_slope(side / support) / (support * side) : 0.0;
  const real cut_slope =
      length > 0 ? lateral * reach_cutoff_slope(length / support) / (support * length) : 0.0;
  for (int c = 0; c < 3; ++c) {
    const real tangential = v[c] - along * n[c];
    t.gradient[c] = a[c] / size;
    t.weight_gradient[c] = lateral_slope * tangential + cut_slope * v[c];
    t.normal_sensitivity[c] = tangential / size;
    t.weight_normal[c] = -lateral_slope * along * tangential;
  }
  return t;
}

/// The terms of a point whose weight is faded by phi (surface_fade): w and its gradients times
/// phi.
inline PointTerms faded(PointTerms t, real fade) {
  t.weight *= fade;
  for (int c = 0; c < 3; ++c) {
    t.weight_gradient[c] *= fade;
    t.weight_normal[c] *= fade;
  }
  return t;
}

/// The sums over a body's points in reach of one probe, and from them the gap g and its
/// gradient G (see above).
struct SurfaceGap {
  real weight = 0;       ///< S = sum w_k
  real weighted = 0;     ///< sum w_k d_k
  vec3 pull{0, 0, 0};    ///< sum w_k u_k + d_k e_k
  vec3 spread{0, 0, 0};  ///< sum e_k

  void add(const PointTerms& t) {
    weight += t.weight;
    weighted += t.weight * t.distance;
    for (int c = 0; c < 3; ++c) {
      pull[c] += t.weight * t.gradient[c] + t.distance * t.weight_gradient[c];
      spread[c] += t.weight_gradient[c];
    }
  }
  bool reached() const { return weight > 0; }
  real gap() const { return weighted / weight; }
  /// G = (sum w u + sum d e - g sum e) / S.
  vec3 gradient() const {
    const real g = gap();
    return {(pull[0] - g * spread[0]) / weight, (pull[1] - g * spread[1]) / weight,
            (pull[2] - g * spread[2]) / weight};
  }
};

/// G_k, point k's share of the gradient, given the probe's gap g and weight sum S.
inline vec3 point_share(const PointTerms& t, real gap, real weight) {
  return {(t.weight * t.gradient[0] + (t.distance - gap) * t.weight_gradient[0]) / weight,
          (t.weight * t.gradient[1] + (t.distance - gap) * t.weight_gradient[1]) / weight,
          (t.weight * t.gradient[2] + (t.distance - gap) * t.weight_gradient[2]) / weight};
}

}  // namespace granulate::contact
