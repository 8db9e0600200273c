// One slot of the world's body storage: a body and the generation that makes stale ids fail.
#pragma once

#include <cstdint>

#include "body_state.h"
#include "joint_state.h"
#include "physics/world.h"

namespace tumble {

struct World::Slot {
  Body body;
  std::uint32_t generation = 0;
  bool alive = false;
};

}  // namespace tumble
