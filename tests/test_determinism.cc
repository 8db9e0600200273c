// The same scene gives bit-identical states whatever the thread count and from run to run:
// islands share nothing, pairs write their own slots, and every ordering is fixed.
#include <gtest/gtest.h>

#include <cstring>

#include "scene_runner.h"

namespace tumble::testing {
namespace {

// FNV-1a over the bits of every dynamic body's pose and velocities.
std::uint64_t state_hash(const World& world) {
  std::uint64_t hash = 1469598103934665603ull;
  auto mix = [&](double value) {
    std::uint64_t bits;
    std::memcpy(&bits, &value, sizeof bits);
    for (int i = 0; i < 8; ++i) {
      hash ^= (bits >> (8 * i)) & 0xFF;
      hash *= 1099511628211ull;
    }
  };
  for (const Body* b : dynamic_bodies(world)) {
    for (int k = 0; k < 3; ++k) {
      mix(b->position[k]);
      mix(b->linear_velocity[k]);
      mix(b->angular_velocity[k]);
    }
    for (int k = 0; k < 4; ++k)
      mix(b->orientation.coeffs()[k]);
  }
  return hash;
}

std::uint64_t run_with_threads(const SceneDef& base, int threads, long steps) {
  SceneDef scene = base;
  scene.world.threads = threads;
  World world = build(scene);
  run(world, scene.dt, steps);
  return state_hash(world);
}

TEST(Determinism, SameBitsForAnyThreadCountAndRun) {
  for (const SceneDef& scene : {pile_scene(343), pyramid_scene(12)}) {
    SCOPED_TRACE(scene.name);
    const std::uint64_t one = run_with_threads(scene, 1, 180);
    EXPECT_EQ(run_with_threads(scene, 1, 180), one);
    EXPECT_EQ(run_with_threads(scene, 2, 180), one);
    EXPECT_EQ(run_with_threads(scene, 4, 180), one);
  }
}

}  // namespace
}  // namespace tumble::testing
