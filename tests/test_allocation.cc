// Once a scene has warmed up, a step allocates nothing: every stage reuses the world's scratch
// memory. Counted by replacing the global allocation functions for this test program.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "scene_runner.h"

namespace {
std::atomic<long> allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) {
  return operator new(size);
}
void* operator new(std::size_t size, std::align_val_t align) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  const std::size_t a = static_cast<std::size_t>(align);
  if (void* p = std::aligned_alloc(a, (size + a - 1) / a * a)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size, std::align_val_t align) {
  return operator new(size, align);
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete(void* p, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}

namespace tumble::testing {
namespace {

long allocations_in_steps(World& world, double dt, int steps) {
  const long before = allocations.load();
  for (int i = 0; i < steps; ++i)
    EXPECT_TRUE(world.step(dt));
  return allocations.load() - before;
}

// The counter works: the world does allocate while it warms up.
TEST(Allocation, WarmingUpAllocates) {
  SceneDef scene = pyramid_scene(10);
  World world = build(scene);
  EXPECT_GT(allocations_in_steps(world, scene.dt, 1), 0);
}

TEST(Allocation, NoneOnceWarmedUp) {
  struct Case {
    SceneDef scene;
    int threads;
  };
  SceneDef pyramid = pyramid_scene(20);  // one coloured island
  pyramid.world.solver.sleeping = false;
  SceneDef exact_tower = tower_scene(3);  // the exact solver
  exact_tower.world.solver.sleeping = false;
  SceneDef mixed = parse_scene(default_scene_json()).value();  // spheres, capsules, boxes
  for (const Case& c : {Case{pyramid, 1}, Case{pyramid, 2}, Case{exact_tower, 2},
                        Case{pile_scene(64), 2}, Case{mixed, 2}}) {
    SceneDef scene = c.scene;
    scene.world.threads = c.threads;
    SCOPED_TRACE(scene.name + " with " + std::to_string(c.threads) + " threads");
    World world = build(scene);
    run(world, scene.dt, 240);
    EXPECT_EQ(allocations_in_steps(world, scene.dt, 60), 0);
  }
}

}  // namespace
}  // namespace tumble::testing
