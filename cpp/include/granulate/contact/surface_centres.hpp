// Where contact sees the nodes that carry a particle's surface (the anchored nodes of
// surface_anchors.hpp: a mesh's or grid's boundary vertices, a lattice's or conforming
// discretisation's outer layer).
//
// Each such node i has the anchored vector A_i = sum_k w_k (y_k - y_i) (about (h/2) o_i) and
// its outward normal n_i = A_i / |A_i|. From them, for a particle whose laws give its nodes the
// contact radius rho (s_p = rho / (h/2)):
//   the surface point    s_i = y_i + d_i n_i               (on the particle's true surface, d_i
//                        the node's depth),
//   the contact centre   c_i = y_i + (d_i - rho |o_i|) n_i  (rho |o_i| below s_i, so that the
//                        sphere of radius rho reaches every face at a mesh corner; walls, and
//                        node pairs within one body, see the node's sphere there).
// Under the surface law the offset fades where the neighbourhood folds (contact/surface_law.hpp,
// surface_fade of |A_i| / |A_0|): q = y_i + l phi n_i, so a folded node's points slide back to
// the node instead of swinging with a normal that means nothing. With phi = 1:
// A point q = y_i + l n_i moves at v_i + l (1 - n n^T) A_i(v) / |A_i|. A force F on q goes F
// to the node and, as the force (l / |A_i|) (1 - n n^T) F on A_i, -W of that to the node and
// w_k to anchor k (W = sum w_k): F at q in momentum, moment and work. A force along the normal
// stays on the node; only its tangential part reaches the anchors. Particles outside the
// surface law keep the linear form q = y_i + (l / ((h/2) |o_i|)) A_i (the same point at rest;
// it stretches with the neighbourhood), which needs no square root per node and step. A node
// whose bond to one of its anchors breaks takes new anchors under the surface law: the pair
// (triple) of its neighbours within 1.75 h, still bonded to it (all of them, nearest first),
// that spans best, weighted to give the same A_i in the reference (so the same A_i, normal and
// points under any affine motion of the neighbourhood: the point stays where it was, up to the
// neighbourhood's non-affine strain), the choice a function of the bond states alone. Where
// none spans, and outside the surface law, the node is detached: seen at itself from then on,
// with no surface point.
//
// A particle under the surface law whose surface is curved everywhere (every surface point's
// curvature radius 1/kappa between 2 h and 50 h: a disc, a sphere, an ellipse) is round:
// walls see each of its surface points through its osculating sphere, centre o_i = s_i - n_i /
// kappa_i (at length d_i - 1/kappa_i along the normal), instead of its contact sphere, so that
// a rolling disc meets the wall on its circle rather than on the polygon of its points. That
// normal is the reference normal turned with the point's body (contact/body_rotation.hpp), not
// A_i / |A_i|: the anchors' vibration would move o_i by 1/kappa_i times their tilt, ten times
// the spacing's worth, with no force to account for it (ContactModel::osculating_normal).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "granulate/contact/surface_law.hpp"
#include "granulate/model.hpp"
#include "granulate/state.hpp"
#include "granulate/surface_anchors.hpp"

namespace granulate {

class SurfaceCentres {
 public:
  using vec3 = std::array<real, 3>;

  /// Sets each particle's depth s_p (0: its nodes are not centred; one per particle) and the
  /// detached nodes from the bond states (at the first evaluation, and after a restore). A
  /// particle not flagged in `outer_layers` keeps only its nodes on the surface (depth 0, a
  /// mesh's or grid's boundary vertices); a lattice's or conforming outer layer is seen at its
  /// nodes.
  void find(const Model& model, const State& state, std::vector<real> depth,
            const std::vector<std::uint8_t>& outer_layers);
  bool found() const { return found_; }
  void forget() { found_ = false; }
  bool any() const { return any_; }
  /// Whether a particle outside the surface law has its nodes centred (the linear form, whose
  /// points stretch with the anchors).
  bool any_linear() const { return any_linear_; }

  /// The nodes whose bond to one of their anchors is among `pairs` (bonds that broke, already
  /// broken in `state`) take new anchors, or are detached (see above); returns those detached.
  std::vector<index_t> detach_anchored(const Model& model, const State& state,
                                       std::span<const std::array<index_t, 2>> pairs);

  /// The nodes node i's anchored vector reads now (its anchors), appended to `out`; none for a
  /// node seen at itself.
  void anchors_of(const Model& model, index_t i, std::vector<index_t>& out) const;

  /// Whether node i is seen away from itself (it has anchors): a cheap test for the hot loops.
  bool moved(index_t i) const { return any_ && anchored_[i]; }
  /// The anchors of node i if it carries a surface point (its particle's nodes are centred and
  /// it is attached), else null.
  const SurfaceAnchor* anchor(const Model& model, index_t i) const {
    if (!moved(i)) return nullptr;
    return kept_anchor(model, model.particles()[model.node_particle()[i]], i);
  }

  /// What one look-up of node i's anchors gives: the anchors (null: the node is seen at
  /// itself), its particle's first node and h, whether its points lie along the normal (the
  /// surface law), and how far out along the normal its surface point (d_i) and its contact
  /// centre (d_i - rho |o_i|) lie [m].
  struct Seen {
    const SurfaceAnchor* anchor = nullptr;
    index_t first = 0;
    real mesh_size = 0, surface_length = 0, centre_length = 0;
    real osculating_radius = 0;  ///< 1 / kappa_i [m] on a round particle, else 0
    bool along_normal = false;
  };
  Seen seen(const Model& model, index_t i) const;
  /// y_i + length n_i at the state's positions (y_i for a node without anchors).
  vec3 point(const State& state, const Seen& s, index_t i, real length) const;
  /// The velocity of that point: v_i + length (1 - n n^T) A_i(v) / |A_i|.
  vec3 point_velocity(const State& state, const Seen& s, index_t i, real length) const;
  /// The force on A_i of a force F on the point y_i + length n_i: (length / |A_i|) (1 - n n^T) F
  /// (length / ((h/2) |o_i|) F outside the surface law).
  vec3 lever(const State& state, const Seen& s, index_t i, real length, const vec3& force) const;
  /// A_i = sum_k w_k (f_k - f_i) of an anchored node for a nodal field f (zero without anchors).
  static vec3 anchored_vector(const Seen& s, const std::vector<real>& field, index_t i);
  /// rho = |A_i| / |A_0|, |A_0| = (h/2) |o_i| the anchored vector's length in the reference
  /// (surface_anchors.hpp): 1 while the neighbourhood keeps its shape, towards 0 as it folds.
  static real stretch(const Seen& s, real size);
  /// How far out along n_i a surface-law point `length` out at rest lies when |A_i| = size:
  /// length phi(rho) (contact/surface_law.hpp, surface_fade).
  static real faded_length(const Seen& s, real length, real size);

  /// Node i's contact centre, and how fast it moves.
  vec3 at_centre(const Model& model, const State& state, index_t i) const {
    const Seen s = seen(model, i);
    return point(state, s, i, s.centre_length);
  }
  vec3 centre_velocity(const Model& model, const State& state, index_t i) const {
    const Seen s = seen(model, i);
    return point_velocity(state, s, i, s.centre_length);
  }
  /// Node i's surface point: where node-pair search and surface contact see the node.
  vec3 at_surface(const Model& model, const State& state, index_t i) const {
    const Seen s = seen(model, i);
    return point(state, s, i, s.surface_length);
  }
  /// How far out along the normal the lists see a node at rest [m]: its surface point's
  /// length under the surface law, else its contact centre's (0 for a node seen at itself).
  static real list_length(const Seen& s) { return s.along_normal ? s.surface_length : s.centre_length; }
  /// Where the node-pair lists see node i: its surface point on a particle under the surface
  /// law, else its contact centre.
  vec3 at_list(const Model& model, const State& state, index_t i) const {
    const Seen s = seen(model, i);
    return point(state, s, i, list_length(s));
  }
  /// Every node's list position (at_list), into x (n x 3; float for the lists, double for a
  /// distributed run's caps).
  template <class T>
  void fill_positions(const Model& model, const State& state, std::vector<T>& x) const;

  std::size_t memory_bytes() const {
    return depth_.capacity() * sizeof(real) + anchor_slot_.capacity() * sizeof(index_t) +
           anchored_.capacity() + surface_.capacity() + round_.capacity() +
           spare_.capacity() * sizeof(SurfaceAnchor);
  }

  /// The bounds of a round particle's curvature radii, over its h (see above).
  static constexpr real round_radius_min = 2, round_radius_max = 50;

 private:
  /// The factor f of the linear form y_i + f A_i outside the surface law: length / ((h/2) |o_i|).
  static real linear_scale(const Seen& s, real length);
  /// |A_0| = (h/2) |o_i|, the anchored vector's length in the reference (surface_anchors.hpp).
  static real reference_length(const Seen& s) { return 0.5 * s.mesh_size * s.anchor->reach; }
  static real length_of(const vec3& a);
  void detach(index_t i);
  /// Node i's anchors from the bonds it still has (see above), or detached if none span (or
  /// outside the surface law): returns whether it keeps anchors.
  bool reanchor(const Model& model, const State& state, index_t i);
  /// Node i's neighbours within anchor_reach h still bonded to it, nearest first (ties by
  /// index): those reanchor chooses from.
  static std::vector<index_t> bonded_within_reach(const Model& model, const State& state, index_t i);
  /// How near a node's new anchors lie, in mesh sizes (reference distance).
  static constexpr real anchor_reach = 1.75;
  /// Whether one of the bonds of node i to the anchors `a` has broken.
  static bool anchor_bond_broken(const Model& model, const State& state, index_t i, const SurfaceAnchor& a);
  /// Whether every surface point of the shape has a curvature radius within the round bounds.
  static bool is_round(const Shape& shape);
  /// Node i's anchors from the shape (none for an outer-layer node of a particle not under the
  /// surface law).
  const SurfaceAnchor* lookup(const Model& model, index_t i) const;
  /// The anchors of node i of `particle`, which is seen at them (moved): from anchor_slot_ under
  /// the surface law, else from its shape.
  const SurfaceAnchor* kept_anchor(const Model& model, const Particle& particle, index_t i) const {
    const SurfaceAnchors& anchors = model.shapes()[particle.shape].anchors;
    if (anchor_slot_.empty()) return anchors.of(i - particle.first_node);
    const index_t slot = anchor_slot_[i];
    return (slot & spare_bit) ? &spare_[slot & ~spare_bit] : &anchors.anchors[slot];
  }
  /// Marks an anchor_slot_ that is a place in spare_, not in the shape's anchors.
  static constexpr index_t spare_bit = index_t{1} << 31;

  bool found_ = false;
  bool any_ = false;
  bool any_linear_ = false;
  std::vector<real> depth_;             // per particle
  std::vector<std::uint8_t> surface_;   // per particle: under the surface law
  std::vector<std::uint8_t> round_;     // per particle: round (see above)
  std::vector<std::uint8_t> anchored_;  // per node: seen at its anchors (0 once detached)
  // Per node under the surface law: its anchors, as a place in the shape's anchors (lookup()'s),
  // or with spare_bit, in spare_.
  std::vector<index_t> anchor_slot_;
  std::vector<SurfaceAnchor> spare_;  // the anchors taken after bonds broke (reanchor)
};

inline real SurfaceCentres::linear_scale(const Seen& s, real length) {
  return length / reference_length(s);
}

inline real SurfaceCentres::length_of(const vec3& a) {
  return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
}

inline SurfaceCentres::Seen SurfaceCentres::seen(const Model& model, index_t i) const {
  // One look-up of the particle: a node still marked as anchored has the anchors find() found.
  Seen s;
  if (!moved(i)) return s;
  const index_t p = model.node_particle()[i];
  const Particle& particle = model.particles()[p];
  s.anchor = kept_anchor(model, particle, i);
  s.first = particle.first_node;
  s.mesh_size = particle.mesh_size;
  s.along_normal = surface_[p] != 0;
  s.surface_length = s.anchor->depth * particle.mesh_size;
  s.centre_length = (s.anchor->depth - 0.5 * depth_[p] * s.anchor->reach) * particle.mesh_size;
  if (round_[p]) s.osculating_radius = particle.mesh_size / s.anchor->curvature;
  return s;
}

inline SurfaceCentres::vec3 SurfaceCentres::anchored_vector(const Seen& s, const std::vector<real>& field,
                                                            index_t i) {
  vec3 sum{0, 0, 0};
  if (s.anchor == nullptr) return sum;
  const real* f = field.data();
  const SurfaceAnchor& a = *s.anchor;
  for (std::size_t k = 0; k < a.nodes.size() && a.nodes[k] != SurfaceAnchor::no_anchor; ++k) {
    const index_t j = s.first + a.nodes[k];
    for (int d = 0; d < 3; ++d) sum[d] += a.weights[k] * (f[3 * j + d] - f[3 * i + d]);
  }
  return sum;
}

inline real SurfaceCentres::stretch(const Seen& s, real size) {
  return size / reference_length(s);
}

inline real SurfaceCentres::faded_length(const Seen& s, real length, real size) {
  return length * contact::surface_fade(stretch(s, size));
}

inline SurfaceCentres::vec3 SurfaceCentres::point(const State& state, const Seen& s, index_t i,
                                                  real length) const {
  const real* y = state.positions.data();
  vec3 q{y[3 * i], y[3 * i + 1], y[3 * i + 2]};
  if (length == 0 || s.anchor == nullptr) return q;
  const vec3 a = anchored_vector(s, state.positions, i);
  const real size = length_of(a);
  const real scale = s.along_normal ? faded_length(s, length, size) / size : linear_scale(s, length);
  for (int d = 0; d < 3; ++d) q[d] += scale * a[d];
  return q;
}

inline SurfaceCentres::vec3 SurfaceCentres::point_velocity(const State& state, const Seen& s, index_t i,
                                                           real length) const {
  // The rate of the point's offset is the lever map of A_i's rate.
  const real* v = state.velocities.data();
  if (length == 0 || s.anchor == nullptr) return {v[3 * i], v[3 * i + 1], v[3 * i + 2]};
  const vec3 rate = lever(state, s, i, length, anchored_vector(s, state.velocities, i));
  return {v[3 * i] + rate[0], v[3 * i + 1] + rate[1], v[3 * i + 2] + rate[2]};
}

inline SurfaceCentres::vec3 SurfaceCentres::lever(const State& state, const Seen& s, index_t i, real length,
                                                  const vec3& force) const {
  if (length == 0 || s.anchor == nullptr) return {0, 0, 0};
  if (!s.along_normal) {
    const real scale = linear_scale(s, length);
    return {scale * force[0], scale * force[1], scale * force[2]};
  }
  // q = y + length phi(rho) n, rho = |A| / |A_0|: the tangential lever length phi / |A|, and
  // the fade's radial one length phi' / |A_0| = length phi' rho / |A| (0 unless folded).
  const vec3 a = anchored_vector(s, state.positions, i);
  const real size = length_of(a);
  const vec3 n{a[0] / size, a[1] / size, a[2] / size};
  const real normal_part = n[0] * force[0] + n[1] * force[1] + n[2] * force[2];
  const real rho = stretch(s, size);
  const real tangential = length * contact::surface_fade(rho) / size;
  const real radial = length * contact::surface_fade_slope(rho) * rho / size;
  vec3 on_a;
  for (int d = 0; d < 3; ++d)
    on_a[d] = tangential * (force[d] - normal_part * n[d]) + radial * normal_part * n[d];
  return on_a;
}

}  // namespace granulate
