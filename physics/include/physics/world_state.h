// A world's whole state as plain data: what World::save_state gives and World::from_state takes
// back, so that a run can be saved and resumed bit for bit. The engine does no I/O; encoding this
// for a file or the network is its callers' business.
#pragma once

#include <cstdint>
#include <vector>

#include "physics/body.h"
#include "physics/step.h"

namespace tumble {

struct WorldSettings;

// The impulse a contact point carried at the end of a step: the next step starts from it (warm
// start), matched by body pair and feature id, or else by the point's position in A's axes.
struct WarmStartImpulse {
  BodyId a, b;
  std::uint64_t feature = 0;
  Vec3 local_a = Vec3::Zero();
  double normal = 0;             // N s
  Vec3 friction = Vec3::Zero();  // N s, world
};

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
  std::vector<WarmStartImpulse> warm_start;  // sorted by (a.index, b.index)
};

}  // namespace tumble
