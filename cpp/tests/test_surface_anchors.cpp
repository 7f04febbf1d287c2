// Surface anchors: the contact centre of a boundary vertex as a weighted sum of bond vectors.
#include <array>
#include <cmath>
#include <vector>

#include "check.hpp"
#include "granulate/surface_anchors.hpp"

using namespace granulate;

namespace {

/// A 5 x 5 grid of spacing h (2D), its boundary offsets as meshes.boundary_offsets gives them.
struct Grid {
  std::vector<real> positions, offsets;
};

Grid square_grid(real h) {
  Grid g;
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 5; ++j) {
      g.positions.insert(g.positions.end(), {i * h, j * h, 0.0});
      g.offsets.insert(g.offsets.end(), {i == 0   ? -1.0
                                         : i == 4 ? 1.0
                                                  : 0.0,
                                         j == 0   ? -1.0
                                         : j == 4 ? 1.0
                                                  : 0.0,
                                         0.0});
    }
  }
  return g;
}

/// c_a - y_a = -sum_k w_k (y_k - y_a) for positions y.
std::array<real, 3> offset(const SurfaceAnchor& anchor, const std::vector<real>& y, index_t a) {
  std::array<real, 3> c{0, 0, 0};
  for (std::size_t k = 0; k < 3 && anchor.nodes[k] != SurfaceAnchor::no_anchor; ++k) {
    for (int d = 0; d < 3; ++d) c[d] -= anchor.weights[k] * (y[3 * anchor.nodes[k] + d] - y[3 * a + d]);
  }
  return c;
}

/// The grid moved by y = F x + t, F a rotation by 0.3 rad times a stretch (row-major, 2 x 2).
struct Moved {
  std::array<real, 4> F;
  std::vector<real> y;
};

Moved stretched_and_turned(const Grid& g) {
  const real c = std::cos(0.3), s = std::sin(0.3);
  Moved m{{1.1 * c, -0.9 * s, 1.1 * s, 0.9 * c}, std::vector<real>(g.positions.size())};
  for (std::size_t a = 0; a < m.y.size() / 3; ++a) {
    const real x0 = g.positions[3 * a], x1 = g.positions[3 * a + 1];
    m.y[3 * a] = m.F[0] * x0 + m.F[1] * x1 + 2.0;
    m.y[3 * a + 1] = m.F[2] * x0 + m.F[3] * x1 - 1.0;
  }
  return m;
}

}  // namespace

TEST_CASE("surface anchors put a face node's centre h/2 inside, a corner's h/2 from both faces") {
  const real h = 0.1;
  const Grid g = square_grid(h);
  const SurfaceAnchors anchors = build_surface_anchors(g.positions, g.offsets, {}, h, 2);
  CHECK(anchors.of(12) == nullptr);  // the middle node
  CHECK(anchors.anchors.size() == 16);
  const auto face = offset(*anchors.of(2), g.positions, 2);  // (0, 2h) on the face x = 0
  CHECK_CLOSE(face[0], 0.5 * h, 1e-7);
  CHECK_CLOSE(face[1], 0.0, 1e-7);
  const auto corner = offset(*anchors.of(0), g.positions, 0);  // (0, 0)
  CHECK_CLOSE(corner[0], 0.5 * h, 1e-7);
  CHECK_CLOSE(corner[1], 0.5 * h, 1e-7);
}

TEST_CASE("surface anchors follow any affine motion of the neighbourhood") {
  const real h = 0.1;
  const Grid g = square_grid(h);
  const SurfaceAnchors anchors = build_surface_anchors(g.positions, g.offsets, {}, h, 2);
  // y = F x + t: the offset is F (h/2, h/2).
  const auto [F, y] = stretched_and_turned(g);
  const auto moved = offset(*anchors.of(0), y, 0);
  CHECK_CLOSE(moved[0], F[0] * 0.5 * h + F[1] * 0.5 * h, 1e-7);
  CHECK_CLOSE(moved[1], F[2] * 0.5 * h + F[3] * 0.5 * h, 1e-7);
}

TEST_CASE("anchors taken again without a broken bond give the same anchored vector in any affine motion") {
  // The face node (0, 2h) anchored anew from its neighbours but the one its first anchors
  // use first (as after that bond broke): the same offset at rest and after y = F x + t.
  const real h = 0.1;
  const Grid g = square_grid(h);
  const SurfaceAnchors anchors = build_surface_anchors(g.positions, g.offsets, {}, h, 2);
  const index_t a = 2;
  const SurfaceAnchor& first = *anchors.of(a);
  const std::array<real, 3> minus_a = offset(first, g.positions, a);
  const std::array<real, 3> target{-minus_a[0], -minus_a[1], -minus_a[2]};
  std::vector<index_t> candidates;
  for (const index_t j : {1, 3, 7, 6, 8}) {  // within 1.75 h, nearest first
    if (j != first.nodes[0]) candidates.push_back(j);
  }
  SurfaceAnchor again;
  CHECK(span_anchors(g.positions, a, candidates, target, 2, 0, again));
  CHECK(again.nodes[0] != first.nodes[0] && again.nodes[1] != first.nodes[0]);
  const auto rest = offset(again, g.positions, a);
  CHECK_CLOSE(rest[0], minus_a[0], 1e-7);
  CHECK_CLOSE(rest[1], minus_a[1], 1e-7);
  const std::vector<real> y = stretched_and_turned(g).y;
  const auto moved = offset(again, y, a), before = offset(first, y, a);
  CHECK_CLOSE(moved[0], before[0], 1e-7);
  CHECK_CLOSE(moved[1], before[1], 1e-7);
  // Candidates on one line span nothing: no anchors, and `again` keeps what it had.
  const std::vector<index_t> line{1, 3};
  SurfaceAnchor none = again;
  CHECK(!span_anchors(g.positions, a, line, target, 2, 0, none));
  CHECK(none.nodes == again.nodes);
}
