// granulate._core's checkpoints: the core state and contact history as a dict, and back.
#include "bindings.hpp"

namespace granulate::bindings {

using namespace nb::literals;

namespace {

/// A flat array of T from a dict entry (a checkpoint), copied; a missing or mistyped entry is an
/// InputError naming it.
template <class T>
std::vector<T> entry(const nb::dict& data, const char* key) {
  if (!data.contains(key)) throw InputError(std::string("the checkpoint has no '") + key + "' entry");
  try {
    auto array = nb::cast<nb::ndarray<const T, nb::ndim<1>, nb::c_contig, nb::device::cpu>>(data[key]);
    return std::vector<T>(array.data(), array.data() + array.shape(0));
  } catch (const nb::cast_error&) {
    throw InputError(std::string("the checkpoint's '") + key + "' entry has the wrong type or shape");
  }
}

template <class T>
T scalar(const nb::dict& data, const char* key) {
  if (!data.contains(key)) throw InputError(std::string("the checkpoint has no '") + key + "' entry");
  try {
    return nb::cast<T>(data[key]);
  } catch (const nb::cast_error&) {
    throw InputError(std::string("the checkpoint's '") + key + "' entry has the wrong type");
  }
}

}  // namespace

nb::dict checkpoint_dict(const Simulation& self) {
  const State& s = self.state();
  const ContactCheckpoint c = self.contact().checkpoint();
  nb::dict d;
  d["positions"] = copy_out(s.positions);
  d["velocities"] = copy_out(s.velocities);
  d["forces"] = copy_out(s.forces);
  d["bond_intact"] = copy_out(s.bonds.unpacked(self.model().bond_offsets()));
  d["dilatation"] = copy_out(s.dilatation);
  d["time"] = s.time;
  d["step"] = s.step;
  d["contact_built"] = c.built;
  d["contact_positions_at_build"] = copy_out(c.positions_at_build);
  d["contact_time_at_build"] = c.time_at_build;
  d["contact_broken_at_build"] = c.broken_at_build;
  d["contact_skin"] = c.skin;
  std::vector<index_t> slots;
  for (const auto& slot : c.slots) slots.insert(slots.end(), slot.begin(), slot.end());
  d["contact_slots"] = copy_out(slots);
  d["contact_particle_slot_count"] = c.particle_slot_count;
  d["contact_slot_approach"] = copy_out(c.slot_approach);
  d["contact_slot_normal"] = copy_out(c.slot_normal);
  d["contact_slot_work"] = copy_out(c.slot_work);
  d["contact_slot_rolling"] = copy_out(c.slot_rolling);
  d["contact_slot_slide"] = copy_out(c.slot_slide);
  d["contact_last_time"] = c.last_time;
  d["contact_has_last_time"] = c.has_last_time;
  d["contact_statistics"] = copy_out(
      std::vector<std::uint64_t>{c.statistics.rebuilds, c.statistics.list_entries, c.statistics.node_contacts,
                                 c.statistics.wall_contacts, c.statistics.list_updates});
  d["contact_overlaps"] = copy_out(std::vector<real>{c.statistics.deepest_overlap,
                                                     static_cast<real>(c.statistics.half_overlap_step),
                                                     static_cast<real>(c.statistics.full_overlap_step)});
  d["contact_pair_offsets"] = copy_out(c.pair_offsets);
  d["contact_pair_partners"] = copy_out(c.pair_partners);
  d["contact_springs"] = copy_out(c.springs);
  d["contact_pair_springs"] = copy_out(c.pair_springs);
  d["contact_wall_springs"] = copy_out(c.wall_springs);
  d["contact_opened_rest"] = copy_out(c.opened_rest);
  std::vector<real> reactions;
  for (const auto& r : c.wall_reactions) reactions.insert(reactions.end(), r.begin(), r.end());
  d["contact_wall_reactions"] = copy_out(reactions);
  return d;
}

void restore_dict(Simulation& self, const nb::dict& d) {
  State s;
  s.positions = entry<real>(d, "positions");
  s.velocities = entry<real>(d, "velocities");
  s.forces = entry<real>(d, "forces");
  if (!s.bonds.assign_unpacked(self.model().bond_offsets(), entry<std::uint8_t>(d, "bond_intact"))) {
    throw InputError("the checkpoint's state does not match this model (nodes or bonds differ)");
  }
  s.dilatation = entry<real>(d, "dilatation");
  s.time = scalar<real>(d, "time");
  s.step = scalar<std::uint64_t>(d, "step");
  ContactCheckpoint c;
  c.built = scalar<bool>(d, "contact_built");
  c.positions_at_build = entry<real>(d, "contact_positions_at_build");
  c.time_at_build = scalar<real>(d, "contact_time_at_build");
  c.broken_at_build = scalar<std::uint64_t>(d, "contact_broken_at_build");
  c.skin = scalar<real>(d, "contact_skin");
  const auto slots = entry<index_t>(d, "contact_slots");
  if (slots.size() % 2) throw InputError("the checkpoint's contact slots are malformed");
  for (std::size_t k = 0; k < slots.size(); k += 2) c.slots.push_back({slots[k], slots[k + 1]});
  c.particle_slot_count = scalar<std::uint64_t>(d, "contact_particle_slot_count");
  c.slot_approach = entry<real>(d, "contact_slot_approach");
  c.slot_normal = entry<real>(d, "contact_slot_normal");
  c.slot_work = entry<real>(d, "contact_slot_work");
  // Written since rolling resistance exists; a checkpoint without it had none.
  if (d.contains("contact_slot_rolling")) c.slot_rolling = entry<real>(d, "contact_slot_rolling");
  // Written since sideways travel ends collisions; a checkpoint without it had none.
  if (d.contains("contact_slot_slide")) c.slot_slide = entry<real>(d, "contact_slot_slide");
  c.last_time = scalar<real>(d, "contact_last_time");
  c.has_last_time = scalar<bool>(d, "contact_has_last_time");
  const auto statistics = entry<std::uint64_t>(d, "contact_statistics");
  if (statistics.size() != 5) throw InputError("the checkpoint's contact statistics are malformed");
  c.statistics = {statistics[0], statistics[4], statistics[1], statistics[2], statistics[3]};
  // Written since distributed runs rebuild parts from checkpoints; a checkpoint without it
  // starts the record anew.
  if (d.contains("contact_overlaps")) {
    const auto overlaps = entry<real>(d, "contact_overlaps");
    if (overlaps.size() != 3) throw InputError("the checkpoint's contact overlaps are malformed");
    c.statistics.deepest_overlap = overlaps[0];
    c.statistics.half_overlap_step = static_cast<std::uint64_t>(overlaps[1]);
    c.statistics.full_overlap_step = static_cast<std::uint64_t>(overlaps[2]);
  }
  c.pair_offsets = entry<index_t>(d, "contact_pair_offsets");
  c.pair_partners = entry<index_t>(d, "contact_pair_partners");
  c.springs = entry<real>(d, "contact_springs");
  c.pair_springs = entry<index_t>(d, "contact_pair_springs");
  c.wall_springs = entry<index_t>(d, "contact_wall_springs");
  c.opened_rest = entry<real>(d, "contact_opened_rest");
  const auto reactions = entry<real>(d, "contact_wall_reactions");
  if (reactions.size() % 6) throw InputError("the checkpoint's wall reactions are malformed");
  for (std::size_t k = 0; k < reactions.size(); k += 6) {
    c.wall_reactions.push_back({reactions[k], reactions[k + 1], reactions[k + 2], reactions[k + 3],
                                reactions[k + 4], reactions[k + 5]});
  }
  self.restore(s, c);
}

}  // namespace granulate::bindings
