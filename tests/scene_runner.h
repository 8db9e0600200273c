// Runs scenes for the dynamics tests and measures them the way ../shared/SCENES.md does.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <vector>

#include "physics/world.h"
#include "scenes/scene.h"
#include "scenes/standard.h"

namespace tumble::testing {

inline World build(const SceneDef& scene) {
  Result<World> world = make_world(scene);
  EXPECT_TRUE(world.ok()) << world.error();
  return std::move(world).value();
}

// Dynamic bodies in slot order.
inline std::vector<BodyView> dynamic_bodies(const World& world) {
  std::vector<BodyView> out;
  for (std::uint32_t i = 0; i < world.slot_count(); ++i)
    if (const BodyView b = world.body(world.id_at(i)); b && !b->is_static()) out.push_back(b);
  return out;
}

// FNV-1a over the bits of every dynamic body's pose and velocities.
inline std::uint64_t state_hash(const World& world) {
  std::uint64_t hash = 1469598103934665603ull;
  auto mix = [&](double value) {
    std::uint64_t bits;
    std::memcpy(&bits, &value, sizeof bits);
    for (int i = 0; i < 8; ++i) {
      hash ^= (bits >> (8 * i)) & 0xFF;
      hash *= 1099511628211ull;
    }
  };
  for (const BodyView b : dynamic_bodies(world)) {
    for (int k = 0; k < 3; ++k) {
      mix(b->position()[k]);
      mix(b->linear_velocity()[k]);
      mix(b->angular_velocity()[k]);
    }
    for (int k = 0; k < 4; ++k)
      mix(b->orientation().coeffs()[k]);
  }
  return hash;
}

inline double kinetic_energy(BodyView b) {
  const Vec3 w_body = b.orientation().conjugate() * b.angular_velocity();
  return 0.5 * b.mass() * b.linear_velocity().squaredNorm() +
         0.5 * w_body.dot(b.inertia_body() * w_body);
}

inline double total_energy(const World& world) {
  double e = 0;
  for (const BodyView b : dynamic_bodies(world))
    e += kinetic_energy(b) - b->mass() * world.settings().gravity.dot(b->position());
  return e;
}

// The lowest point of a box below z = 0 (0 when none is).
inline double corner_depth(BodyView b) {
  if (b.shape().type() != ShapeType::kBox) return 0;
  double lowest = 0;
  const Vec3 h = b.shape().half_extents();
  for (int i = 0; i < 8; ++i) {
    const Vec3 corner((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(), (i & 4) ? h.z() : -h.z());
    lowest = std::min(lowest, (b.orientation() * corner + b.position()).z());
  }
  return -lowest;
}

inline bool all_finite(const World& world) {
  for (const BodyView b : dynamic_bodies(world))
    if (!is_finite(b->position()) || !is_finite(b->linear_velocity()) ||
        !is_finite(b->orientation()))
      return false;
  return true;
}

// Steps `world` for `steps` steps of `dt`, calling `each` after every step.
inline void run(World& world, double dt, long steps, const std::function<void(long)>& each = {}) {
  for (long s = 1; s <= steps; ++s) {
    ASSERT_TRUE(world.step(dt).is_ok());
    if (each) each(s);
  }
}

}  // namespace tumble::testing
