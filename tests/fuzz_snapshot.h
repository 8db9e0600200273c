// A snapshot damaged the ways the fuzzing suites try: its bytes mutated, or one field crafted
// (hostile masses, inverses, inertia, poses, speeds, shape types and sizes, sleep and warm-start
// indices, free slots, ids, the id counter, a thousand empty slots, settings, limits and dt).
#pragma once

#include <cstdint>
#include <string>

#include "fuzz_support.h"
#include "tumble/v1/snapshot.pb.h"

namespace tumble::testing {

inline std::string damaged_snapshot(Hostile& h, const std::string& good) {
  if (h.chance(0.4)) return h.mutate(good);
  v1::snapshot::WorldSnapshot s;
  if (!s.ParseFromString(good) || s.slots_size() == 0) return good;
  v1::snapshot::Body* b = s.mutable_slots(h.integer(0, s.slots_size() - 1));
  const auto hostile_entry = [&](auto* field, int size) {
    if (field->size() == size) field->Set(h.integer(0, size - 1), h.special());
  };
  switch (h.integer(0, 17)) {
    case 0:
      b->set_mass(h.special());
      break;
    case 1:
      b->set_inverse_mass(h.special());
      break;
    case 2:
      hostile_entry(b->mutable_position(), 3);
      break;
    case 3:
      hostile_entry(b->mutable_linear_velocity(), 3);
      break;
    case 4:
      hostile_entry(b->mutable_angular_velocity(), 3);
      break;
    case 5:
      hostile_entry(b->mutable_inertia_body(), 9);
      break;
    case 6:
      hostile_entry(b->mutable_inverse_inertia_body(), 9);
      break;
    case 7:
      b->mutable_shape()->set_type(static_cast<std::uint32_t>(h.integer(0, 9)));
      break;
    case 8:
      hostile_entry(b->mutable_shape()->mutable_half_extents(), 3);
      break;
    case 9:
      b->set_sleep_island(static_cast<std::uint32_t>(h.integer(0, 1 << 30)));
      break;
    case 10:
      if (s.warm_start().body_a_size() > 0)
        s.mutable_warm_start()->set_body_a(0, static_cast<std::uint32_t>(h.integer(0, 1 << 30)));
      break;
    case 11:
      if (s.warm_start().normal_size() > 0) s.mutable_warm_start()->set_normal(0, h.special());
      break;
    case 12:
      s.add_free_slots(static_cast<std::uint32_t>(h.integer(0, 1 << 30)));
      break;
    case 13:
      for (int k = h.integer(1, 1000); k > 0; --k)
        *s.add_slots() = v1::snapshot::Body();
      break;
    case 14:
      b->set_id(s.slots(0).id());  // two slots with one id
      break;
    case 15:
      s.set_next_id(UINT64_MAX);
      break;
    case 16:
      s.mutable_settings()->mutable_solver()->set_iterations(h.integer(-5, 5000));
      break;
    default:
      if (h.chance(0.5))
        s.mutable_settings()->mutable_limits()->set_max_size(h.special());
      else
        s.set_dt(h.special());
  }
  return s.SerializeAsString();
}

}  // namespace tumble::testing
