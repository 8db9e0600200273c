// A warmed-up step on one thread calls no allocator at all, C's included: every C allocation
// function of the program is replaced here by a counting one over glibc's own (__libc_*), so that
// allocations made inside libraries count too. libgomp once made and freed a team of one for each
// of a step's six OpenMP regions whose `if` clause was false (parallel.h).
#include <gtest/gtest.h>

#include <atomic>
#include <cerrno>
#include <cstddef>

#include "scene_runner.h"
#include "scenes/standard.h"

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void __libc_free(void*);
}

namespace {
std::atomic<bool> counting{false};
std::atomic<long> calls{0};
void count() {
  if (counting.load(std::memory_order_relaxed)) calls.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

extern "C" {
void* malloc(std::size_t size) {
  count();
  return __libc_malloc(size);
}
void* calloc(std::size_t n, std::size_t size) {
  count();
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t size) {
  count();
  return __libc_realloc(p, size);
}
void* memalign(std::size_t align, std::size_t size) {
  count();
  return __libc_memalign(align, size);
}
void* aligned_alloc(std::size_t align, std::size_t size) {
  count();
  return __libc_memalign(align, size);
}
int posix_memalign(void** out, std::size_t align, std::size_t size) {
  count();
  *out = __libc_memalign(align, size);
  return *out != nullptr ? 0 : ENOMEM;
}
void free(void* p) {
  __libc_free(p);
}
}

namespace tumble::testing {
namespace {

long allocations_in_steps(SceneDef scene, int steps, int threads = 1, int warm_up = 30) {
  scene.world.threads = threads;
  World world = build(scene);
  run(world, scene.dt, warm_up);  // scratch memory grows to its size
  calls = 0;
  counting = true;
  for (int s = 0; s < steps; ++s)
    EXPECT_TRUE(world.step(scene.dt).is_ok());
  counting = false;
  return calls.load();
}

TEST(NoMalloc, OneThreadStepsCallNoAllocator) {
  EXPECT_EQ(allocations_in_steps(slide_scene(), 100), 0);
  EXPECT_EQ(allocations_in_steps(spin_scene(), 100), 0);
  SceneDef tower = tower_scene(5);
  tower.world.solver.sleeping = false;
  EXPECT_EQ(allocations_in_steps(tower, 100), 0);
  // Islands large enough to be coloured and swept by the (one-thread) team path.
  SceneDef pyramid = pyramid_scene(12);
  pyramid.world.solver.sleeping = false;
  EXPECT_EQ(allocations_in_steps(pyramid, 20), 0);
  // Fast bodies swept by continuous collision every step: a 10 cm box at 300 m/s bouncing
  // between two walls.
  SceneDef fast = bullet_scene();
  fast.duration = 100;
  fast.bodies[0].restitution = 1;
  BodyDef far_wall = fast.bodies[1];
  far_wall.position.x() = -12;
  fast.bodies.push_back(far_wall);
  EXPECT_EQ(allocations_in_steps(fast, 100), 0);
  World world = build(fast);
  std::uint32_t swept = 0;
  run(world, fast.dt, 130, [&](long) { swept += world.last_step().swept_bodies; });
  EXPECT_GT(swept, 100u);  // the sweep really ran in those steps
}

// On a team too, once warmed up: the per-thread working memory of the islands' and the colours'
// stages grows on every thread to what any needed (a step may hand the tallest island to another
// thread), and the team's region clocks and barrier allocate nothing.
TEST(NoMalloc, TwoThreadStepsOfALandedPileCallNoAllocator) {
  SceneDef pile = pile_scene(1000);
  pile.world.solver.sleeping = false;
  EXPECT_EQ(allocations_in_steps(pile, 20, 2, 150), 0);
}

// Terrain, as a heightfield and as a mesh: the pairs keep each thread's contact room (its
// manifolds' points, a mesh's triangles and faces found) and their extra manifolds' slots from
// step to step.
TEST(NoMalloc, StepsOnTerrainCallNoAllocator) {
  SceneDef pile = terrain_pile_scene(64);
  pile.world.solver.sleeping = false;
  EXPECT_EQ(allocations_in_steps(pile, 20, 1, 200), 0);
  SceneDef on_mesh = terrain_mesh_pile_scene(64);
  on_mesh.world.solver.sleeping = false;
  EXPECT_EQ(allocations_in_steps(on_mesh, 20, 1, 200), 0);
}

// Compounds: each pair's room for one manifold per pair of parts is laid out afresh every step in
// arrays that keep their size, jacks against the ground and each other. (Jacks only: the
// dumbbells of compound-pile roll away for ever, and the grid's lists grow as they spread.)
TEST(NoMalloc, StepsOfCompoundsCallNoAllocator) {
  SceneDef pile = compound_pile_scene(64);
  for (BodyDef& body : pile.bodies)
    if (std::holds_alternative<CompoundDef>(body.shape)) body.shape = pile.bodies[1].shape;
  pile.world.solver.sleeping = false;
  EXPECT_EQ(allocations_in_steps(pile, 20, 1, 200), 0);
}

// Jointed islands: the direct solve of a double pendulum and of an arm on its motors (auto),
// ragdolls in a pile on the ground (auto: the tree with soft contacts), and a ragdoll whose
// contacts, limits and cones are one LCP (exact, exact_joints.h; Lemke's pivots allocated until
// its column was taken in two steps).
TEST(NoMalloc, JointedStepsCallNoAllocator) {
  for (const char* name : {"double-pendulum", "arm", "ragdolls:4"}) {
    SceneDef scene = standard_scene(name).value();
    scene.world.solver.sleeping = false;
    EXPECT_EQ(allocations_in_steps(scene, 30, 1, 240), 0) << name;
  }
  SceneDef ragdoll = standard_scene("ragdolls:1").value();
  ragdoll.world.solver.sleeping = false;
  ragdoll.world.solver.kind = SolverKind::kExact;
  EXPECT_EQ(allocations_in_steps(ragdoll, 30, 1, 240), 0);
}

}  // namespace
}  // namespace tumble::testing
