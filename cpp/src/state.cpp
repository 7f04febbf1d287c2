#include "granulate/state.hpp"

namespace granulate {

void BondStates::reset(const std::vector<std::size_t>& bond_offsets) {
  const std::size_t nodes = bond_offsets.empty() ? 0 : bond_offsets.size() - 1;
  byte_offsets_.assign(nodes + 1, 0);
  for (std::size_t i = 0; i < nodes; ++i) {
    byte_offsets_[i + 1] = byte_offsets_[i] + (bond_offsets[i + 1] - bond_offsets[i] + 7) / 8;
  }
  bits_.assign(byte_offsets_[nodes], 0xff);
}

std::vector<std::uint8_t> BondStates::unpacked(const std::vector<std::size_t>& bond_offsets) const {
  std::vector<std::uint8_t> out(bond_offsets.empty() ? 0 : bond_offsets.back());
  for (std::size_t i = 0; i + 1 < bond_offsets.size(); ++i) {
    const std::uint8_t* bits = node(static_cast<index_t>(i));
    const index_t count = static_cast<index_t>(bond_offsets[i + 1] - bond_offsets[i]);
    for (index_t b = 0; b < count; ++b) out[bond_offsets[i] + b] = intact(bits, b) ? 1 : 0;
  }
  return out;
}

bool BondStates::assign_unpacked(const std::vector<std::size_t>& bond_offsets,
                                 const std::vector<std::uint8_t>& states) {
  if (states.size() != (bond_offsets.empty() ? 0 : bond_offsets.back())) return false;
  reset(bond_offsets);
  for (std::size_t i = 0; i + 1 < bond_offsets.size(); ++i) {
    std::uint8_t* bits = node(static_cast<index_t>(i));
    const index_t count = static_cast<index_t>(bond_offsets[i + 1] - bond_offsets[i]);
    for (index_t b = 0; b < count; ++b) {
      if (!states[bond_offsets[i] + b]) clear(bits, b);
    }
  }
  return true;
}

std::uint64_t BondStates::broken(const std::vector<std::size_t>& bond_offsets, index_t first,
                                 index_t last) const {
  std::uint64_t count = 0;
  for (index_t i = first; i < last; ++i)
    count += bond_offsets[i + 1] - bond_offsets[i] - intact_count(bond_offsets, i);
  return count;
}

index_t BondStates::intact_count(const std::vector<std::size_t>& bond_offsets, index_t i) const {
  const std::uint8_t* bits = node(i);
  const index_t bonds = static_cast<index_t>(bond_offsets[i + 1] - bond_offsets[i]);
  index_t count = 0;
  for (index_t b = 0; b < bonds; ++b) count += intact(bits, b) ? 1 : 0;
  return count;
}

}  // namespace granulate
