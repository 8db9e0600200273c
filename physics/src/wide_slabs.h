// A ray against four boxes at once, and the order in which a four-wide tree's walk takes the
// children it reaches: shared by the mesh's tree (ray_mesh.cc) and the bodies' query tree
// (query_index.h). Lane by lane the arithmetic is the scalar slab test's, so a walk reaches the
// same boxes on any machine and at any vector width.
#pragma once

#include <array>

#include "physics/math.h"
#include "wide.h"

namespace tumble {

// The ray origin + t d in every lane: its origin and 1/d (±inf along an axis it does not move on).
struct WideRay {
  std::array<Wide, 3> from, scale;
};

TUMBLE_INLINE WideRay wide_ray(const Vec3& origin, const Vec3& inverse) {
  return {{wide(origin.x()), wide(origin.y()), wide(origin.z())},
          {wide(inverse.x()), wide(inverse.y()), wide(inverse.z())}};
}

// Where the ray enters each of four boxes (lane k: min[axis][k] to max[axis][k]) within
// [0, t_max]; `reached` gets the lanes whose box it meets there. A direction of 0 gives ±inf
// outside the slab and NaN on its plane, which compares false and leaves the lane's interval as
// it was: inside, conservatively.
TUMBLE_INLINE Wide enter_boxes(const WideRay& ray, const std::array<Wide, 3>& min,
                               const std::array<Wide, 3>& max, double t_max, WideMask* reached) {
  Wide enter = wide(0), leave = wide(t_max);
  for (int axis = 0; axis < 3; ++axis) {
    const Wide low = (min[axis] - ray.from[axis]) * ray.scale[axis];
    const Wide high = (max[axis] - ray.from[axis]) * ray.scale[axis];
    const WideMask swapped = low > high;
    const Wide near = select(swapped, high, low), far = select(swapped, low, high);
    enter = select(near > enter, near, enter);
    leave = select(far < leave, far, leave);
  }
  *reached = enter <= leave;
  return enter;
}

// Calls take(k) for each lane k of `reached` that exists(k) allows, the farthest entry first, so
// that a stack pops the nearest first (an insertion sort of at most four; ties in lane order).
template <class Exists, class Take>
TUMBLE_INLINE void farthest_first(WideMask reached, Wide enter, Exists&& exists, Take&& take) {
  std::array<int, 4> lanes;
  std::array<double, 4> entries;
  int count = 0;
  for (int k = 0; k < 4; ++k) {
    if (!reached[k] || !exists(k)) continue;
    int slot = count++;
    for (; slot > 0 && entries[slot - 1] < enter[k]; --slot) {
      entries[slot] = entries[slot - 1];
      lanes[slot] = lanes[slot - 1];
    }
    entries[slot] = enter[k];
    lanes[slot] = k;
  }
  for (int slot = 0; slot < count; ++slot)
    take(lanes[slot]);
}

}  // namespace tumble
