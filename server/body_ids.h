// The ids clients see. world.proto promises that an id never names another body (or joint),
// across every removal, reset, scene load and restore; the engine's ids (slot and generation)
// start over with each new World, so the server hands out its own: a counter that never goes
// back, mapped to the engine's ids both ways. Bodies and joints each have their own counter.
#pragma once

#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

#include "physics/world.h"

namespace tumble::server {

// How a world lists the things of one kind by slot.
struct BodySlots {
  using Id = BodyId;
  static std::uint32_t count(const World& world) { return world.slot_count(); }
  static BodyId at(const World& world, std::uint32_t slot) { return world.id_at(slot); }
};
struct JointSlots {
  using Id = JointId;
  static std::uint32_t count(const World& world) { return world.joint_slot_count(); }
  static JointId at(const World& world, std::uint32_t slot) { return world.joint_at(slot); }
};

template <class Slots>
class SlotIds {
 public:
  using Id = typename Slots::Id;
  // Follows the world after a change: a thing new to its slot gets the next id, one gone loses
  // its id for good.
  void sync(const World& world);
  // Forgets everything (the world was replaced); the counter goes on.
  void clear();
  // Gives the things of a restored world the ids they had (by slot; 0 where there is none),
  // and moves the counter past them and past `next`; things without one get new ids.
  void adopt(const World& world, std::span<const std::uint64_t> ids, std::uint64_t next);

  // The thing's id (0 for one not synced yet).
  std::uint64_t wire(Id id) const {
    return id.index < by_slot_.size() && generation_[id.index] == id.generation ? by_slot_[id.index]
                                                                                : 0;
  }
  // What an id names now, or an invalid id when it names nothing.
  Id find(std::uint64_t wire) const {
    const auto found = by_wire_.find(wire);
    return found == by_wire_.end() ? Id{} : found->second;
  }
  std::uint64_t next() const { return next_; }
  // Ids by slot (0 for empty slots), as snapshots store them.
  const std::vector<std::uint64_t>& by_slot() const { return by_slot_; }

 private:
  void forget_slot(std::uint32_t slot);
  std::vector<std::uint64_t> by_slot_;
  std::vector<std::uint32_t> generation_;  // of what each slot's id was issued to
  std::unordered_map<std::uint64_t, Id> by_wire_;
  std::uint64_t next_ = 1;  // ids start at 1; 0 names nothing
};

using BodyIds = SlotIds<BodySlots>;
using JointIds = SlotIds<JointSlots>;

extern template class SlotIds<BodySlots>;
extern template class SlotIds<JointSlots>;

}  // namespace tumble::server
