// The state: everything that changes in time.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "granulate/types.hpp"

namespace granulate {

/// Intact (1) or broken (0) state of every bond copy (see BondFamilies), one bit each. Node i's
/// bits start on a byte of their own, so threads that each update their own nodes never write
/// the same byte. Bond b of node i is bit b of node(i); its global number is bond_offsets[i] + b.
class BondStates {
 public:
  /// Every bond intact; bond_offsets: Model::bond_offsets() (nodes + 1 entries).
  void reset(const std::vector<std::size_t>& bond_offsets);
  std::uint8_t* node(index_t i) { return bits_.data() + byte_offsets_[i]; }
  const std::uint8_t* node(index_t i) const { return bits_.data() + byte_offsets_[i]; }
  static bool intact(const std::uint8_t* node_bits, index_t b) { return (node_bits[b >> 3] >> (b & 7)) & 1u; }
  static void clear(std::uint8_t* node_bits, index_t b) {
    node_bits[b >> 3] = static_cast<std::uint8_t>(node_bits[b >> 3] & ~(1u << (b & 7)));
  }
  bool intact(index_t i, index_t b) const { return intact(node(i), b); }
  /// One byte per bond copy in global order (checkpoints, Python), and back (false: the size
  /// does not match).
  std::vector<std::uint8_t> unpacked(const std::vector<std::size_t>& bond_offsets) const;
  bool assign_unpacked(const std::vector<std::size_t>& bond_offsets, const std::vector<std::uint8_t>& states);
  /// Broken copies among the bonds of nodes first .. last-1.
  std::uint64_t broken(const std::vector<std::size_t>& bond_offsets, index_t first, index_t last) const;
  /// Intact copies among the bonds of node i.
  index_t intact_count(const std::vector<std::size_t>& bond_offsets, index_t i) const;
  std::size_t bit_bytes() const { return bits_.capacity(); }  ///< 1/8 per bond
  std::size_t offset_bytes() const { return byte_offsets_.capacity() * sizeof(std::size_t); }  ///< 8 per node

 private:
  std::vector<std::size_t> byte_offsets_;  // nodes + 1
  std::vector<std::uint8_t> bits_;
};

struct State {
  std::vector<real> positions;   ///< x, nodes x 3 [m]
  std::vector<real> velocities;  ///< v, nodes x 3 [m/s]
  std::vector<real> forces;      ///< net force density f, nodes x 3 [N/m^3; per unit volume also in 2D]
  BondStates bonds;              ///< intact or broken, per bond copy
  std::vector<real> dilatation;  ///< theta_i of LPS nodes (0 for PMB nodes)
  real time = 0;                 ///< [s]
  std::uint64_t step = 0;
};

}  // namespace granulate
