// A snapshot damaged the ways the fuzzing suites try: its bytes mutated, the engine's bytes
// inside it mutated (the engine's own tests craft single fields of them: test_world_state.cc,
// test_limits.cc), or one of the server's fields crafted (ids, colours, the id counter, settings,
// limits and dt).
#pragma once

#include <cstdint>
#include <cstring>
#include <string>

#include "fuzz_support.h"
#include "tumble/v1/snapshot.pb.h"

namespace tumble::testing {

inline std::string damaged_snapshot(Hostile& h, const std::string& good) {
  if (h.chance(0.3)) return h.mutate(good);
  v1::snapshot::WorldSnapshot s;
  if (!s.ParseFromString(good) || s.ids_size() == 0) return good;
  const int slot = h.integer(0, s.ids_size() - 1);
  switch (h.integer(0, 9)) {
    case 0:
    case 1:
      *s.mutable_engine_state() = h.mutate(s.engine_state());
      break;
    case 2:
    case 3: {
      // A hostile number (NaN, 1e308, -0...) over any 8 bytes past the engine's 40-byte header,
      // the length kept: a mass, a speed, an inertia entry, a count or an index of a body.
      std::string& engine = *s.mutable_engine_state();
      if (engine.size() < 48) break;
      const double value = h.special();
      std::memcpy(engine.data() + h.integer(40, static_cast<int>(engine.size()) - 8), &value, 8);
      break;
    }
    case 4:
      s.set_ids(slot, s.ids(h.integer(0, s.ids_size() - 1)));  // perhaps two slots with one id
      break;
    case 5:
      for (int k = h.integer(1, 1000); k > 0; --k) {
        s.add_ids(0);
        s.add_colors(0);
      }
      break;
    case 6:
      s.set_next_id(UINT64_MAX);
      break;
    case 7:
      s.mutable_settings()->mutable_solver()->set_iterations(h.integer(-5, 5000));
      break;
    case 8:
      s.mutable_settings()->mutable_limits()->set_max_size(h.special());
      break;
    default:
      s.set_dt(h.special());
  }
  return s.SerializeAsString();
}

}  // namespace tumble::testing
