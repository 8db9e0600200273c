// The service benchmarks' world: 1000 spheres drifting apart without gravity. Steps are cheap, so
// the tables show the cost of serving and publishing, not the solver's; a frame is the full 1000
// poses (64 kB), dt 1 ms.
#pragma once

#include <chrono>
#include <cstdint>

#include "scenes/scene.h"

namespace tumble::bench {

inline SceneDef drifting_spheres(int threads) {
  SceneDef scene;
  scene.world.threads = threads;
  scene.name = "drift-1000";
  scene.dt = 0.001;
  scene.world.gravity = Vec3::Zero();
  scene.world.solver.sleeping = false;
  for (int i = 0; i < 1000; ++i) {
    BodyDef ball;
    ball.shape = SphereDef{0.2};
    ball.position = Vec3(i % 10, (i / 10) % 10, i / 100);
    ball.linear_velocity = Vec3(0.01 * (i % 3), 0.01 * (i % 5), 0.01);
    scene.bodies.push_back(ball);
  }
  return scene;
}

// The system clock in ns since the epoch, as frames carry the time their step ended.
inline std::uint64_t unix_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

}  // namespace tumble::bench
