// Sums over contact nodes (per slot, or per body) that a distributed run's processes can make
// apart and add up to one process's bits: the terms of each block of kRunBlock node indices
// summed in the order they come (node order), each block's sum added exactly (ExactAccumulator).
// A process holding whole blocks makes the same block sums (docs/parallel.md).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "granulate/exact_accumulator.hpp"
#include "granulate/run_sums.hpp"

namespace granulate {

template <int width>
class BlockSums {
 public:
  using Terms = std::array<real, width>;

  /// Starts a sweep over `count` items (slots or bodies), none summed yet: each is from its
  /// first add.
  void start(std::size_t count) {
    for (std::size_t k = 0; k < used_; ++k)
      if (items_[k] < index_.size()) index_[items_[k]] = none;  // only those taken: O(used)
    index_.resize(count, none);
    used_ = 0;
  }
  /// Starts a sweep with the items `summed`(item) ready, so that threads may add to them apart.
  template <class Summed>
  void start(std::size_t count, Summed summed) {
    start(count);
    for (std::size_t k = 0; k < count; ++k)
      if (summed(k)) take(k);
  }
  /// Whether an item has sums here.
  bool summed(std::size_t item) const { return item < index_.size() && index_[item] != none; }
  /// Adds node i's terms to an item (taken on its first terms, unless made ready); an item's
  /// nodes come in node order within a sweep.
  void add(std::size_t item, index_t i, const Terms& terms) {
    if (index_[item] == none) take(item);
    const std::size_t k = index_[item];
    const std::int64_t block = i / kRunBlock;
    if (block != block_[k]) flush(k), block_[k] = block;
    for (int c = 0; c < width; ++c) partial_[k][c] += terms[c];
  }
  /// Ends a sweep: the blocks' sums added; the next sweep adds on to them.
  void finish_sweep() {
    for (std::size_t k = 0; k < used_; ++k) flush(k);
  }
  /// Ends one item's sweep (items swept apart, in parallel).
  void finish_sweep(std::size_t item) { flush(index_[item]); }
  /// The items with sums, in the order they were taken.
  std::span<const std::size_t> items() const { return {items_.data(), used_}; }
  /// An item's sums (after finish_sweep).
  Terms rounded(std::size_t item) const { return sums_[index_[item]].rounded(); }
  /// An item's exact sums (after finish_sweep): what a process sends of it.
  const ExactSums<width>& exact(std::size_t item) const { return sums_[index_[item]]; }

 private:
  static constexpr std::size_t none = ~std::size_t{0};
  void take(std::size_t item) {
    const std::size_t k = index_[item] = used_++;
    if (block_.size() < used_) {
      items_.resize(used_);
      block_.resize(used_);
      partial_.resize(used_);
      sums_.resize(used_);
    }
    items_[k] = item;
    block_[k] = -1;
    partial_[k] = Terms{};
    sums_[k].clear();
  }
  void flush(std::size_t k) {
    if (block_[k] < 0) return;
    for (int c = 0; c < width; ++c) sums_[k].sum[c].add(partial_[k][c]);
    partial_[k] = Terms{};
    block_[k] = -1;
  }
  std::vector<std::size_t> index_;  // per item: its place below, or none
  std::size_t used_ = 0;
  std::vector<std::size_t> items_;   // per place: its item
  std::vector<std::int64_t> block_;  // per item summed: the block of its partial sums, or -1
  std::vector<Terms> partial_;
  std::vector<ExactSums<width>> sums_;
};

}  // namespace granulate
