// Small helpers the contact model's source files share: products of arrays of three reals, a
// symmetric 3x3 matrix times a vector, and giving back the memory of shrunken lists.
#pragma once

#include <array>
#include <vector>

#include "granulate/types.hpp"

namespace granulate::contact_vectors {

using vec = std::array<real, 3>;

inline vec cross(const vec& a, const vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

inline real dot(const vec& a, const vec& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/// Symmetric 3x3 matrix (xx, yy, zz, xy, xz, yz) times a vector.
inline vec symmetric_times(const std::array<real, 6>& m, const vec& v) {
  return {m[0] * v[0] + m[3] * v[1] + m[4] * v[2], m[3] * v[0] + m[1] * v[1] + m[5] * v[2],
          m[4] * v[0] + m[5] * v[1] + m[2] * v[2]};
}

/// Gives back a vector's memory once it holds under half its capacity: lists shrink as bodies
/// part, and a shattered sample's largest lists would otherwise stay allocated for the run.
template <class T>
void release_excess(std::vector<T>& v) {
  if (v.capacity() > 2 * v.size() + 64) v.shrink_to_fit();
}

/// Keeps a vector's capacity at its size: for the per-step arrays of the touching bodies and
/// contacts, whose few entries are cheap to reallocate when their count changes, so that their
/// memory is what the step needs rather than what the busiest step of the run did.
template <class T>
void fit_exactly(std::vector<T>& v) {
  if (v.capacity() > v.size()) v.shrink_to_fit();
}

}  // namespace granulate::contact_vectors
