#include "body_ids.h"

#include <algorithm>

namespace tumble::server {

template <class Slots>
void SlotIds<Slots>::forget_slot(std::uint32_t slot) {
  if (by_slot_[slot] == 0) return;
  by_wire_.erase(by_slot_[slot]);
  by_slot_[slot] = 0;
}

template <class Slots>
void SlotIds<Slots>::sync(const World& world) {
  const std::uint32_t slots = Slots::count(world);
  for (std::uint32_t slot = slots; slot < by_slot_.size(); ++slot)
    forget_slot(slot);
  by_slot_.resize(slots, 0);
  generation_.resize(slots, 0);
  for (std::uint32_t slot = 0; slot < slots; ++slot) {
    const Id id = Slots::at(world, slot);
    if (by_slot_[slot] != 0 && (!id.is_valid() || generation_[slot] != id.generation))
      forget_slot(slot);
    if (id.is_valid() && by_slot_[slot] == 0) {
      by_slot_[slot] = next_;
      generation_[slot] = id.generation;
      by_wire_[next_] = id;
      ++next_;
    }
  }
}

template <class Slots>
void SlotIds<Slots>::clear() {
  by_slot_.clear();
  generation_.clear();
  by_wire_.clear();
}

template <class Slots>
void SlotIds<Slots>::adopt(const World& world, std::span<const std::uint64_t> ids,
                           std::uint64_t next) {
  clear();
  next_ = std::max(next_, next);
  for (std::uint64_t id : ids)
    next_ = std::max(next_, id + 1);
  const std::uint32_t slots = Slots::count(world);
  by_slot_.assign(slots, 0);
  generation_.assign(slots, 0);
  for (std::uint32_t slot = 0; slot < slots && slot < ids.size(); ++slot) {
    const Id id = Slots::at(world, slot);
    if (!id.is_valid() || ids[slot] == 0 || by_wire_.contains(ids[slot])) continue;
    by_slot_[slot] = ids[slot];
    generation_[slot] = id.generation;
    by_wire_[ids[slot]] = id;
  }
  sync(world);  // anything left without an id gets a new one
}

template class SlotIds<BodySlots>;
template class SlotIds<JointSlots>;

}  // namespace tumble::server
