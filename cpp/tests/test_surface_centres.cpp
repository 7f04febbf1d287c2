// Surface points (contact/surface_centres.hpp): s = y + d phi(|A| / |A_0|) A / |A|, its velocity,
// and the lever that carries a force on s back to the node and its anchors, where the
// neighbourhood is intact, where it has folded part way (the fade's transition) and where it has
// folded past it.
#include <array>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "check.hpp"
#include "fixtures.hpp"
#include "granulate/contact/surface_centres.hpp"
#include "granulate/simulation.hpp"

using namespace granulate;
using vec3 = SurfaceCentres::vec3;

namespace {

constexpr real h = 1e-3;
constexpr index_t face_node = 2;  // (0, 2h) on the face x = 0 of the 5 x 5 grid

/// A 2D particle of 5 x 5 nodes, spacing h, its boundary nodes h/2 below the surface.
std::shared_ptr<Model> grid_particle() {
  auto model = std::make_shared<Model>(2, PlaneMode::strain);
  const index_t material = model->add_material(granulate_test::test_material());
  std::vector<real> positions, volumes, offsets, depths;
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 5; ++j) {
      positions.insert(positions.end(), {i * h, j * h, 0.0});
      volumes.push_back(h * h);
      const real ox = i == 0 ? -1.0 : i == 4 ? 1.0 : 0.0, oy = j == 0 ? -1.0 : j == 4 ? 1.0 : 0.0;
      offsets.insert(offsets.end(), {ox, oy, 0.0});
      depths.push_back(ox != 0 || oy != 0 ? 0.5 * h : 0.0);
    }
  }
  const index_t shape = model->add_shape(positions, volumes, h, offsets, depths);
  model->add_particle(shape, material, positions, 1.0);
  return model;
}

/// Moves node i by a fraction of A_i / W towards its anchors, so that |A_i| shrinks to
/// `stretch` |A_0|, then jitters every node by up to 0.02 h.
void fold(const SurfaceCentres::Seen& seen, State& state, index_t i, real stretch) {
  const vec3 a = SurfaceCentres::anchored_vector(seen, state.positions, i);
  real total = 0;
  for (std::size_t k = 0; k < seen.anchor->nodes.size(); ++k)
    if (seen.anchor->nodes[k] != SurfaceAnchor::no_anchor) total += seen.anchor->weights[k];
  for (int c = 0; c < 2; ++c) state.positions[3 * i + c] += (1 - stretch) * a[c] / total;
  std::mt19937 rng(17);
  std::uniform_real_distribution<real> jitter(-0.02 * h, 0.02 * h);
  for (std::size_t k = 0; k < state.positions.size(); ++k)
    if (k % 3 != 2) state.positions[k] += jitter(rng);
}

/// Checks, for node i at the state's positions, that the point's velocity is its derivative
/// along the node velocities, and that the lever does the point force's virtual work.
void check_point_motion(const SurfaceCentres& centres, const Model& model, State state, index_t i) {
  const SurfaceCentres::Seen seen = centres.seen(model, i);
  std::mt19937 rng(5);
  std::uniform_real_distribution<real> unit(-1, 1);
  for (std::size_t k = 0; k < state.velocities.size(); ++k) state.velocities[k] = k % 3 == 2 ? 0 : unit(rng);
  const real step = 1e-7 * h;
  auto moved = [&](real by) {
    State shifted = state;
    for (std::size_t k = 0; k < shifted.positions.size(); ++k)
      shifted.positions[k] += by * state.velocities[k];
    return centres.point(shifted, seen, i, seen.surface_length);
  };
  const vec3 plus = moved(step), minus = moved(-step);
  const vec3 rate = centres.point_velocity(state, seen, i, seen.surface_length);
  const vec3 force{unit(rng), unit(rng), 0};
  const vec3 on_a = centres.lever(state, seen, i, seen.surface_length, force);
  const vec3 a_rate = SurfaceCentres::anchored_vector(seen, state.velocities, i);
  real work = 0, lever_work = 0;
  for (int c = 0; c < 3; ++c) {
    const real slope = (plus[c] - minus[c]) / (2 * step);
    CHECK_NEAR(rate[c], slope, 1e-6, 1e-7);
    work += force[c] * slope;
    lever_work += force[c] * state.velocities[3 * i + c] + on_a[c] * a_rate[c];
  }
  CHECK_NEAR(lever_work, work, 1e-6, 1e-7);
}

}  // namespace

TEST_CASE("surface points move with their nodes, and their lever does their force's work, folded or not") {
  auto model = grid_particle();
  Simulation sim(model);
  SurfaceCentres centres;
  centres.find(*model, sim.state(), {0.5}, {1});
  const SurfaceCentres::Seen seen = centres.seen(*model, face_node);
  CHECK(seen.anchor != nullptr && seen.along_normal);
  CHECK_CLOSE(seen.surface_length, 0.5 * h, 1e-6);
  // At rest the point lies h/2 out along the outward normal, on the face x = -h/2.
  const vec3 rest = centres.point(sim.state(), seen, face_node, seen.surface_length);
  CHECK_NEAR(rest[0], -0.5 * h, 1e-6, 1e-9);
  CHECK_NEAR(rest[1], 2 * h, 1e-6, 1e-9);
  auto size_of = [&](const State& state) {
    const vec3 a = SurfaceCentres::anchored_vector(seen, state.positions, face_node);
    return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  };
  // |A| / |A_0| = 1 (phi = 1), 0.38 (phi and phi' both matter), 0.2 (phi = 0: the point is the node).
  for (const real stretch : {1.0, 0.38, 0.2}) {
    State state = sim.state();
    fold(seen, state, face_node, stretch);
    CHECK_NEAR(SurfaceCentres::stretch(seen, size_of(state)), stretch, 0, 0.05);
    check_point_motion(centres, *model, state, face_node);
    if (stretch < contact::fade_start) {
      const vec3 q = centres.point(state, seen, face_node, seen.surface_length);
      for (int c = 0; c < 3; ++c) CHECK(q[c] == state.positions[3 * face_node + c]);
    }
  }
}
