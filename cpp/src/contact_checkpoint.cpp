// The contact model's state in a checkpoint: lists, springs, collisions; checked when restored.
#include <algorithm>
#include <cmath>

#include "contact_vectors.hpp"
#include "granulate/contact/contact_model.hpp"

namespace granulate {
using namespace contact_vectors;

namespace {

bool all_finite(const std::vector<real>& values) {
  return std::all_of(values.begin(), values.end(), [](real v) { return std::isfinite(v); });
}

/// CSR lists over n nodes: offsets from 0, never decreasing, ending at the partner count;
/// partners are other nodes.
bool valid_lists(const std::vector<index_t>& offsets, const std::vector<index_t>& partners, index_t n) {
  if (offsets.size() != static_cast<std::size_t>(n) + 1 || offsets.front() != 0 ||
      offsets.back() != partners.size())
    return false;
  for (index_t i = 0; i < n; ++i) {
    if (offsets[i + 1] < offsets[i]) return false;
    for (index_t e = offsets[i]; e < offsets[i + 1]; ++e)
      if (partners[e] >= n || partners[e] == i) return false;
  }
  return true;
}

}  // namespace

ContactCheckpoint ContactModel::checkpoint() const {
  ContactCheckpoint c;
  c.built = built_;
  c.positions_at_build.assign(positions_at_build_.begin(), positions_at_build_.end());
  c.time_at_build = time_at_build_;
  c.broken_at_build = broken_at_build_;
  c.skin = skin_;
  c.slots = slots_;
  c.particle_slot_count = particle_slot_count_;
  // Written out per slot (format 4), Collision{} for the slots without one.
  for (std::size_t slot = 0; slot < slots_.size(); ++slot) {
    const contact::Collision collision = collisions_.get(slot);
    c.slot_approach.push_back(collision.approach);
    c.slot_normal.insert(c.slot_normal.end(), collision.normal.begin(), collision.normal.end());
    c.slot_work.push_back(collision.work);
    c.slot_work.push_back(collision.exponent);
    c.slot_work.push_back(collision.phase);
    c.slot_slide.insert(c.slot_slide.end(), collision.slide.begin(), collision.slide.end());
    if (any_rolling_)
      c.slot_rolling.insert(c.slot_rolling.end(), collision.rolling.begin(), collision.rolling.end());
  }
  c.pair_offsets = pair_offsets_;
  c.pair_partners = pair_partner_;
  for (const vec3& spring : springs_) c.springs.insert(c.springs.end(), spring.begin(), spring.end());
  c.pair_springs = pair_spring_;
  c.wall_springs = wall_spring_;
  c.opened_rest = opened_rest_;
  c.last_time = last_time_;
  c.has_last_time = has_last_time_;
  c.statistics = statistics_;
  c.wall_reactions = wall_reactions_;
  return c;
}

void ContactModel::check_checkpoint(const Model& model, const ContactCheckpoint& saved) const {
  const index_t n = model.node_count();
  const std::size_t slots = saved.slots.size();
  if (saved.slot_approach.size() != slots || saved.slot_normal.size() != 3 * slots ||
      saved.slot_work.size() != 3 * slots || saved.particle_slot_count > slots ||
      (!saved.slot_rolling.empty() && saved.slot_rolling.size() != 3 * slots) ||
      (!saved.slot_slide.empty() && saved.slot_slide.size() != 3 * slots) ||
      (saved.built && saved.positions_at_build.size() != 3 * static_cast<std::size_t>(n)) ||
      saved.wall_reactions.size() != walls_.size() ||
      (!saved.opened_rest.empty() && saved.opened_rest.size() != static_cast<std::size_t>(n))) {
    throw InputError("the checkpoint's contact data do not match this model (nodes or walls differ)");
  }
  // Bodies are numbered below the node count; a wall slot's second entry is a wall. Slots are
  // kept sorted (particle slots, then wall slots), which the merge at list builds relies on.
  for (std::size_t k = 0; k < slots; ++k) {
    const bool wall = k >= saved.particle_slot_count;
    const auto& slot = saved.slots[k];
    const bool sorted = k == 0 || k == saved.particle_slot_count || saved.slots[k - 1] < slot;
    if (slot[0] >= n || slot[1] >= (wall ? walls_.size() : n) || !sorted)
      throw InputError("the checkpoint's contact slots are out of range or out of order");
  }
  const bool finite =
      all_finite(saved.positions_at_build) && all_finite(saved.slot_approach) &&
      all_finite(saved.slot_normal) && all_finite(saved.slot_work) && all_finite(saved.slot_rolling) &&
      all_finite(saved.slot_slide) && all_finite(saved.springs) && all_finite(saved.opened_rest) &&
      std::isfinite(saved.skin) && std::isfinite(saved.time_at_build) && std::isfinite(saved.last_time);
  if (!finite) throw InputError("the checkpoint's contact data hold non-finite values");
  if (!saved.pair_offsets.empty() && !valid_lists(saved.pair_offsets, saved.pair_partners, n))
    throw InputError("the checkpoint's contact lists are out of range (partners past the node count)");
}

real ContactModel::slot_reduced_mass(std::size_t slot) const {
  const index_t bp = slots_[slot][0], bq = slots_[slot][1];
  const real mp = body_kinematic_[bp] ? 0.0 : body_mass_[bp];
  if (slot >= particle_slot_count_) return mp;
  if (bp == bq) return 0.25 * mp;
  const real mq = body_kinematic_[bq] ? 0.0 : body_mass_[bq];
  return mp == 0 || mq == 0 ? mp + mq : mp * mq / (mp + mq);
}

void ContactModel::restore_collisions(const ContactCheckpoint& saved) {
  // A slot whose values are those of no collision gets no record. A checkpoint without rolling
  // rotations (no law had mu_r > 0 then) restores them as zero.
  collisions_.reset(slots_.size());
  for (std::size_t slot = 0; slot < slots_.size(); ++slot) {
    contact::Collision c;
    c.approach = saved.slot_approach[slot];
    c.work = saved.slot_work[3 * slot];
    c.exponent = static_cast<float>(saved.slot_work[3 * slot + 1]);
    c.phase = static_cast<float>(saved.slot_work[3 * slot + 2]);
    if (!saved.slot_slide.empty()) {
      for (int k = 0; k < 3; ++k) c.slide[k] = static_cast<float>(saved.slot_slide[3 * slot + k]);
    }
    for (int k = 0; k < 3; ++k) c.normal[k] = saved.slot_normal[3 * slot + k];
    if (!saved.slot_rolling.empty()) {
      for (int k = 0; k < 3; ++k) c.rolling[k] = saved.slot_rolling[3 * slot + k];
    }
    if (!(c == contact::Collision{})) collisions_.open(slot) = c;
  }
}

void ContactModel::restore(const Model& model, const State& state, const ContactCheckpoint& saved) {
  check_checkpoint(model, saved);
  skin_ = saved.skin;
  bodies_labelled_ = false;        // the restored bonds may differ from the current ones
  relabelled_first_node_.clear();  // the restored slots number the restored bodies
  centres_.forget();               // and so may the detached surface nodes
  newly_broken_.clear();
  slots_ = saved.slots;
  particle_slot_count_ = saved.particle_slot_count;
  restore_collisions(saved);
  built_ = false;
  if (saved.built) {
    // Rebuild the lists from the positions each node was last listed at and the walls at the
    // search's time: the same wall entries (a node's depend only on those), and rebuild()
    // carries each pair's collision history over from the restored slots.
    State at_build = state;
    at_build.time = saved.time_at_build;
    positions_at_build_.assign(saved.positions_at_build.begin(), saved.positions_at_build.end());
    centres_.find(model, state, centring_depths(model),
                  surface_particles_);  // which nodes carry surface points
    // Pair lists updated in place are not those of a search (broken pairs are inserted from
    // the current positions): take the saved ones (a checkpoint without them predates these
    // updates, and a search gives them again).
    const bool saved_lists = saved.pair_offsets.size() == static_cast<std::size_t>(model.node_count()) + 1 &&
                             saved.pair_offsets.back() == saved.pair_partners.size();
    rebuild(model, at_build, saved.broken_at_build, !saved_lists);
    if (saved_lists) {
      pair_offsets_ = saved.pair_offsets;
      pair_partner_ = saved.pair_partners;
      statistics_.list_entries = pair_partner_.size();
      finish_lists(model);
    }
    const std::size_t pool = saved.springs.size() / 3;
    auto valid = [&](const std::vector<index_t>& held, std::size_t entries) {
      return held.size() == entries &&
             std::all_of(held.begin(), held.end(), [&](index_t s) { return s == no_spring || s < pool; });
    };
    if (saved.springs.size() % 3 || !valid(saved.pair_springs, pair_partner_.size()) ||
        !valid(saved.wall_springs, wall_entry_.size())) {
      throw InputError("the checkpoint's friction springs do not match its contact lists");
    }
    springs_.resize(pool);
    for (std::size_t k = 0; k < pool; ++k) {
      springs_[k] = {saved.springs[3 * k], saved.springs[3 * k + 1], saved.springs[3 * k + 2]};
    }
    pair_spring_ = saved.pair_springs;
    wall_spring_ = saved.wall_springs;
    compact_springs();
  }
  opened_rest_ = saved.opened_rest;
  last_time_ = saved.last_time;
  has_last_time_ = saved.has_last_time;
  statistics_ = saved.statistics;
  wall_reactions_ = saved.wall_reactions;
}

}  // namespace granulate
