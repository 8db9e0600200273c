// Snapshot's bytes (proto/tumble/v1/snapshot.proto): a hosted world's whole state, the engine's
// own bytes for its bodies and contacts (World::save_state) wrapped with the server's settings,
// step and body ids, and decoded with every field checked, since the bytes come from a client.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "physics/world.h"

namespace tumble::server {

struct SavedWorld {
  WorldSettings settings;
  std::string state;                   // World::save_state's bytes
  double dt = 0;                       // s per step
  std::vector<std::uint32_t> colours;  // by slot
  // Body ids as clients know them, by slot (0 where none), the next id the server would have
  // given, and the server process that gave them (0: unknown).
  std::vector<std::uint64_t> ids;
  std::uint64_t next_id = 0;
  std::uint64_t server_instance = 0;
  std::uint64_t step = 0;  // the world's step count, for the response (not encoded twice)
  // Joint ids by joint slot (0 where none) and the next joint id, as for bodies.
  std::vector<std::uint64_t> joint_ids;
  std::uint64_t next_joint_id = 0;
};

// Ids stay below 2^53 so that JSON tools (doubles) read them exactly.
constexpr std::uint64_t kMaxBodyId = std::uint64_t{1} << 53;

std::string encode_snapshot(const SavedWorld& saved);
// Refusals name the field ("ids[3]: used by another slot too"). The engine's bytes are checked
// by World::from_state; here only that they hold as many slots as the ids and colours list.
Result<SavedWorld> decode_snapshot(std::string_view bytes);

}  // namespace tumble::server
