#include "granulate/contact/body_sums.hpp"

#include "granulate/run_sums.hpp"

namespace granulate {

namespace {

/// Adds the block sums of `count` nodes (in node order) to `sums`: add(i, block) adds node
/// i's `width` terms to its block's sums (a block: the body's nodes within one block of
/// kRunBlock node indices), which are summed in node order, each block's sums added exactly.
template <int width, class Add>
void add_blocks(const index_t* nodes, index_t count, ExactSums<width>& sums, Add add) {
  index_t s = 0;
  while (s < count) {
    std::array<real, width> block{};
    const std::int64_t first = nodes[s] / kRunBlock;
    for (; s < count && nodes[s] / kRunBlock == first; ++s) add(nodes[s], block);
    for (int k = 0; k < width; ++k) sums.sum[k].add(block[k]);
  }
}

}  // namespace

bool splittable(const Model& model, index_t p) {
  return model.particles()[p].node_count >= splittable_particle_nodes;
}

bool measured_order_free(const Model& model, const index_t* nodes, index_t count) {
  if (!splittable(model, model.node_particle()[nodes[0]])) return false;
  return nodes[0] / kRunBlock != nodes[count - 1] / kRunBlock;  // in more than one block
}

real order_free_mass(const Model& model, const index_t* nodes, index_t count) {
  ExactSums<1> mass;
  add_blocks<1>(nodes, count, mass,
                [&](index_t i, std::array<real, 1>& t) { t[0] += model.density(i) * model.volumes()[i]; });
  return mass.sum[0].rounded();
}

vec3 body_origin(const Model& model, index_t first_node) {
  const real* X = model.reference_positions().data() + 3 * first_node;
  return {X[0], X[1], X[2]};
}

CentreSums centre_sums(const Model& model, const State& state, const index_t* nodes, index_t count,
                       const vec3& origin) {
  const real* y = state.positions.data();
  const real* X = model.reference_positions().data();
  CentreSums sums;
  add_blocks<7>(nodes, count, sums, [&](index_t i, std::array<real, 7>& t) {  // t += node i's terms
    const real m = model.density(i) * model.volumes()[i];
    t[0] += m;
    for (int k = 0; k < 3; ++k) {
      t[1 + k] += m * (y[3 * i + k] - origin[k]);
      t[4 + k] += m * (X[3 * i + k] - origin[k]);
    }
  });
  return sums;
}

BodyCentres centres_from(const CentreSums& sums, const vec3& origin) {
  const auto s = sums.rounded();
  BodyCentres centres;
  for (int k = 0; k < 3; ++k) {
    centres.current[k] = origin[k] + s[1 + k] / s[0];
    centres.reference[k] = origin[k] + s[4 + k] / s[0];
  }
  return centres;
}

MotionSums motion_sums(const Model& model, const State& state, const index_t* nodes, index_t count,
                       const vec3& centre) {
  const real* x = state.positions.data();
  const real* v = state.velocities.data();
  MotionSums sums;
  add_blocks<16>(nodes, count, sums, [&](index_t i, std::array<real, 16>& t) {  // t += node i's terms
    const real m = model.density(i) * model.volumes()[i];
    const vec3 r{x[3 * i] - centre[0], x[3 * i + 1] - centre[1], x[3 * i + 2] - centre[2]};
    const vec3 p{m * v[3 * i], m * v[3 * i + 1], m * v[3 * i + 2]};
    t[0] += m;
    for (int k = 0; k < 3; ++k) {
      t[1 + k] += m * r[k];
      t[4 + k] += p[k];
    }
    t[7] += r[1] * p[2] - r[2] * p[1];
    t[8] += r[2] * p[0] - r[0] * p[2];
    t[9] += r[0] * p[1] - r[1] * p[0];
    t[10] += m * r[0] * r[0];
    t[11] += m * r[1] * r[1];
    t[12] += m * r[2] * r[2];
    t[13] += m * r[0] * r[1];
    t[14] += m * r[0] * r[2];
    t[15] += m * r[1] * r[2];
  });
  return sums;
}

BodyMotion motion_from(const MotionSums& sums, const vec3& centre, int dimension) {
  const auto s = sums.rounded();
  return motion_about(centre, s[0], {s[1], s[2], s[3]}, {s[4], s[5], s[6]}, {s[7], s[8], s[9]},
                      {s[10], s[11], s[12], s[13], s[14], s[15]}, dimension);
}

MomentSums moment_sums(const Model& model, const State& state, const index_t* nodes, index_t count,
                       const BodyCentres& centres) {
  const real* y = state.positions.data();
  const real* X = model.reference_positions().data();
  const vec3& c = centres.current;
  const vec3& C = centres.reference;
  MomentSums sums;
  add_blocks<16>(nodes, count, sums, [&](index_t i, std::array<real, 16>& t) {  // t += node i's terms
    const real m = model.density(i) * model.volumes()[i];
    const vec3 a{y[3 * i] - c[0], y[3 * i + 1] - c[1], y[3 * i + 2] - c[2]};
    const vec3 b{X[3 * i] - C[0], X[3 * i + 1] - C[1], X[3 * i + 2] - C[2]};
    t[0] += m;
    for (int r = 0; r < 3; ++r) {
      t[1 + r] += m * a[r];
      t[4 + r] += m * b[r];
      for (int k = 0; k < 3; ++k) t[7 + 3 * r + k] += m * a[r] * b[k];
    }
  });
  return sums;
}

contact::matrix3 moment_from(const MomentSums& sums) {
  const auto s = sums.rounded();
  contact::matrix3 moment{};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) moment[3 * r + c] = s[7 + 3 * r + c] - s[1 + r] * s[4 + c] / s[0];
  return moment;
}

BodyMotion measure_order_free(const Model& model, const State& state, const index_t* nodes, index_t count,
                              int dimension) {
  const vec3 origin = body_origin(model, nodes[0]);
  const vec3 centre = centres_from(centre_sums(model, state, nodes, count, origin), origin).current;
  return motion_from(motion_sums(model, state, nodes, count, centre), centre, dimension);
}

contact::matrix3 moment_order_free(const Model& model, const State& state, const index_t* nodes,
                                   index_t count) {
  const vec3 origin = body_origin(model, nodes[0]);
  const BodyCentres centres = centres_from(centre_sums(model, state, nodes, count, origin), origin);
  return moment_from(moment_sums(model, state, nodes, count, centres));
}

}  // namespace granulate
