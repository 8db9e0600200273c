// The engine's own bytes for a world's state (World::save_state), documented in
// docs/STATE_FORMAT.md: a fixed header (magic, format version, sizes), then the clock, the body
// slots, the free list and the touching pairs, every number little-endian and exactly as the
// engine holds it. Decoding checks every length before it reads or allocates; the values are then
// checked by WorldInternals::world_from, as for any restored state.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "physics/status.h"
#include "world_state_data.h"

namespace tumble {

inline constexpr char kStateMagic[8] = {'T', 'U', 'M', 'B', 'L', 'E', 'W', 'S'};
inline constexpr std::size_t kStateHeaderBytes = 40;

std::string encode_state(const WorldStateData& state);
// The header alone: magic, version and the sizes, checked against the length.
Result<StateSizes> read_state_header(std::string_view bytes);
// Refusals name where ("slots[3].shape.polyhedron.vertices: 4000 vertices, but 96 bytes left").
Result<WorldStateData> decode_state(std::string_view bytes);

}  // namespace tumble
