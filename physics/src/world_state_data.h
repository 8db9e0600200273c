// A world's whole state as plain data, between the world and its bytes (state_format.h): what
// World::save_state encodes and World::from_state decodes and checks. Private to the engine;
// the engine's own tests use it to craft states no world would save.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "body_state.h"
#include "contact_record.h"
#include "joint_state.h"
#include "physics/world.h"

namespace tumble {

struct BodySlotState {
  std::uint32_t generation = 0;
  bool alive = false;
  Body body;  // meaningful when alive
};

struct WorldStateData {
  std::vector<BodySlotState> slots;
  std::vector<std::uint32_t> free_slots;  // reused last first
  double time = 0;                        // s
  std::uint64_t step = 0;
  std::vector<ContactPairRecord> contact_pairs;  // sorted by (a.index, b.index), each pair once
  std::vector<JointSlot> joints;                 // by joint slot
  std::vector<std::uint32_t> free_joints;        // reused last first
};

// The way in for save_state, from_state and the engine's tests (a friend of World).
struct WorldInternals {
  static WorldStateData state_of(const World& world);
  // Checks everything (the state may come from a file or the network) and names what is wrong.
  static Result<World> world_from(const WorldSettings& settings, WorldStateData state);
};

}  // namespace tumble
