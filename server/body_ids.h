// The ids clients see. world.proto promises that an id never names another body, across every
// removal, reset, scene load and restore; the engine's BodyId (slot and generation) starts over
// with each new World, so the server hands out its own: a counter that never goes back, mapped
// to the engine's ids both ways.
#pragma once

#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

#include "physics/world.h"

namespace tumble::server {

class BodyIds {
 public:
  // Follows the world after a change: a body new to its slot gets the next id, a body gone
  // loses its id for good.
  void sync(const World& world);
  // Forgets every body (the world was replaced); the counter goes on.
  void clear();
  // Gives the bodies of a restored world the ids they had (by slot; 0 where there is no body),
  // and moves the counter past them and past `next`; bodies without one get new ids.
  void adopt(const World& world, std::span<const std::uint64_t> ids, std::uint64_t next);

  // The body's id (0 for a body not synced yet).
  std::uint64_t wire(BodyId id) const {
    return id.index < by_slot_.size() && generation_[id.index] == id.generation ? by_slot_[id.index]
                                                                                : 0;
  }
  // The body an id names now, or an invalid BodyId when it names none.
  BodyId find(std::uint64_t wire) const;
  std::uint64_t next() const { return next_; }
  // Ids by slot (0 for slots without a body), as snapshots store them.
  const std::vector<std::uint64_t>& by_slot() const { return by_slot_; }

 private:
  void forget_slot(std::uint32_t slot);
  std::vector<std::uint64_t> by_slot_;
  std::vector<std::uint32_t> generation_;  // of the body each slot's id was issued to
  std::unordered_map<std::uint64_t, BodyId> by_wire_;
  std::uint64_t next_ = 1;  // ids start at 1; 0 names nothing
};

}  // namespace tumble::server
