#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <vector>

#include "granulate/types.hpp"

namespace granulate::contact {

/// What a collision of two bodies (or a body and a wall) remembers, from the step they first
/// touch until they are back where they touched or slid apart (ContactModel::slot_dashpots),
/// through the gaps of chattering surface nodes in between.
struct Collision {
  real approach = 0;                     ///< x: how far the bodies approached since they touched [m]
  real work = 0;                         ///< W = sum F dx: the contact springs' work over x [J]
  std::array<real, 3> normal{0, 0, 0};   ///< unit normal of the last step in contact
  std::array<real, 3> rolling{0, 0, 0};  ///< theta: the rolling spring's rotation [rad]
  float exponent = 1;                    ///< p of F ~ x^p implied by W = F x / (p + 1), in [1, 3]
  /// tau = sum dt / t_c over the steps in contact: the time since the touch in collision
  /// durations t_c = pi sqrt(m / K_s) (half the period of the secant spring K_s = F / x on the
  /// reduced mass m: an impact ends near tau = 1)
  float phase = 0;
  /// The bodies' sideways travel at the contact since they last touched [m] (zero while in
  /// contact): a gap in which they slid apart by more than the contact radius ends the
  /// collision (ContactModel::slot_dashpots).
  std::array<float, 3> slide{0, 0, 0};

  bool operator==(const Collision&) const = default;
};

/// The share of a collision's turned force (ContactModel::slot_redirects) at phase tau: 1 up to
/// 1.5 collision durations (an impact, its chattering included), cos^2 down to 0 at 3, then 0
/// (a lasting contact: a resting, rolling or slowly loaded one).
inline real impact_share(real phase) {
  constexpr real full = 1.5, none = 3.0;
  if (phase <= full) return 1.0;
  if (phase >= none) return 0.0;
  const real c = std::cos(0.5 * std::numbers::pi * (phase - full) / (none - full));
  return c * c;
}

/// The collisions in progress, one record per body-pair slot that has one. A slot holds the
/// index of its record (4 bytes); records live in a pool only while their collision lasts, so a
/// shattered sample, whose fragments make many slots of which few collide, does not pay a
/// record per slot. A slot without a record reads as Collision{} (no collision).
///
/// Records are opened and closed by one thread in slot order, and `renumber` (at list builds)
/// lays the pool out again in slot order: the pool is the same for any thread count, and it is
/// never read in pool order.
class CollisionStore {
 public:
  /// `slots` slots, none with a record.
  void reset(std::size_t slots) {
    record_of_slot_.assign(slots, none);
    records_.clear();
    free_.clear();
  }

  std::size_t slot_count() const { return record_of_slot_.size(); }

  /// The slot's record, or nullptr.
  const Collision* find(std::size_t slot) const {
    const index_t r = record_of_slot_[slot];
    return r == none ? nullptr : &records_[r];
  }
  Collision* find(std::size_t slot) {
    const index_t r = record_of_slot_[slot];
    return r == none ? nullptr : &records_[r];
  }

  /// The slot's record, or Collision{} for a slot without one.
  Collision get(std::size_t slot) const {
    const Collision* c = find(slot);
    return c ? *c : Collision{};
  }

  /// The slot's approach x (0 without a collision).
  real approach(std::size_t slot) const {
    const Collision* c = find(slot);
    return c ? c->approach : 0;
  }

  /// The slot's record, opened (as Collision{}) if it has none.
  Collision& open(std::size_t slot) {
    index_t& r = record_of_slot_[slot];
    if (r == none) {
      if (free_.empty()) {
        r = static_cast<index_t>(records_.size());
        records_.emplace_back();
      } else {
        r = free_.back();
        free_.pop_back();
        records_[r] = Collision{};
      }
    }
    return records_[r];
  }

  /// The collision is over: the slot's record, if any, is freed.
  void close(std::size_t slot) {
    index_t& r = record_of_slot_[slot];
    if (r == none) return;
    free_.push_back(r);
    r = none;
  }

  /// After a list build: new slot k takes the record of old slot old_of_new[k] (`none`: no old
  /// slot, no record); records of old slots that no new slot takes are dropped. The pool is
  /// laid out again in slot order, holding the live records only.
  void renumber(const std::vector<index_t>& old_of_new) {
    std::vector<index_t> record_of_slot(old_of_new.size(), none);
    std::vector<Collision> records;
    for (std::size_t k = 0; k < old_of_new.size(); ++k) {
      const index_t old = old_of_new[k];
      if (old == none || record_of_slot_[old] == none) continue;
      record_of_slot[k] = static_cast<index_t>(records.size());
      records.push_back(records_[record_of_slot_[old]]);
    }
    record_of_slot_ = std::move(record_of_slot);
    records_ = std::move(records);
    free_.clear();
  }

  /// Records in use (open collisions).
  std::size_t open_count() const { return records_.size() - free_.size(); }

  std::size_t memory_bytes() const {
    return record_of_slot_.capacity() * sizeof(index_t) + records_.capacity() * sizeof(Collision) +
           free_.capacity() * sizeof(index_t);
  }

  static constexpr index_t none = std::numeric_limits<index_t>::max();

 private:
  std::vector<index_t> record_of_slot_;  // per slot: its record in records_, or none
  std::vector<Collision> records_;
  std::vector<index_t> free_;  // records of ended collisions, to reuse
};

}  // namespace granulate::contact
