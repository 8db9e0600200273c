// The broad phase's pair set equals brute force on scenes that stress a uniform grid, for both
// methods and for 1 and 2 threads; static-static pairs never appear.
#include <gtest/gtest.h>

#include "broad_phase.h"
#include "test_support.h"

namespace tumble {
namespace {

using testing::Random;

struct Scene {
  std::vector<Aabb> bounds;
  std::vector<std::uint8_t> movable;
};

std::vector<BodyPair> brute_force(const Scene& s) {
  std::vector<BodyPair> pairs;
  for (std::uint32_t i = 0; i < s.bounds.size(); ++i)
    for (std::uint32_t j = i + 1; j < s.bounds.size(); ++j) {
      if (!(s.bounds[i].min.x() <= s.bounds[i].max.x()) ||
          !(s.bounds[j].min.x() <= s.bounds[j].max.x()))
        continue;
      if ((s.movable[i] || s.movable[j]) && s.bounds[i].overlaps(s.bounds[j]))
        pairs.push_back({i, j});
    }
  return pairs;
}

void add_box(Scene& s, const Vec3& centre, const Vec3& half, bool movable) {
  s.bounds.push_back({centre - half, centre + half});
  s.movable.push_back(movable ? 1 : 0);
}

Scene make_scene(const std::string& kind, Random& rng, int n) {
  Scene s;
  const Vec3 offset = kind == "far" ? Vec3(1e5, -1e5, 1e5) : Vec3::Zero();
  for (int i = 0; i < n; ++i) {
    Vec3 centre, half;
    if (kind == "uniform" || kind == "far") {
      centre = rng.vector(0, 20);
      half = rng.vector(0.2, 0.6);
    } else if (kind == "clustered") {
      const Vec3 cluster = Vec3(rng.integer(0, 3), rng.integer(0, 3), 0) * 30;
      centre = cluster + rng.vector(0, 3);
      half = rng.vector(0.1, 0.5);
    } else if (kind == "wide") {  // 1 mm to 100 m, log-uniform
      centre = rng.vector(0, 200);
      half = Vec3::Constant(0.5 * std::pow(10.0, rng.uniform(-3, 2)));
    } else if (kind == "heap") {  // a quarter heaped in a 2 m cube: cells of a hundred boxes
      centre = i % 4 == 0 ? rng.vector(0, 2) : rng.vector(0, 20);
      half = rng.vector(0.2, 0.6);
    } else if (kind == "terrain") {  // small boxes on a few static slabs, each alone on its level
      centre = rng.vector(0, 20);
      half = rng.vector(0.2, 0.6);
      if (i < 3) {
        centre = Vec3(10, 10, 2.0 * i);
        half = Vec3(15.0 * (i + 1), 15.0 * (i + 1), 0.5 * (i + 1));
      }
    } else {  // "borders": boxes snapped so their faces sit on multiples of their size
      half = Vec3::Constant(0.5);
      centre =
          Vec3(rng.integer(0, 15), rng.integer(0, 15), rng.integer(0, 15)) + Vec3::Constant(0.5);
      if (i % 2) centre += Vec3(0.5, 0, 0);  // faces exactly touching neighbours
    }
    // Every fifth body static, and the terrain's slabs.
    add_box(s, centre + offset, half, i % 5 != 0 && !(kind == "terrain" && i < 3));
  }
  // A ground half-space (unbounded, static), a dead slot, and a second unbounded dynamic body.
  s.bounds.push_back(Aabb::infinite());
  s.movable.push_back(0);
  s.bounds.push_back(Aabb());
  s.movable.push_back(0);
  return s;
}

class BroadPhaseScenes : public ::testing::TestWithParam<std::string> {};

TEST_P(BroadPhaseScenes, PairsEqualBruteForce) {
  Random rng(99);
  const Scene scene = make_scene(GetParam(), rng, 1500);
  const std::vector<BodyPair> expected = brute_force(scene);
  ASSERT_GT(expected.size(), 100u) << "a scene with few pairs tests little";
  for (int threads : {1, 2}) {
    const BroadPhaseInput input{scene.bounds, scene.movable, threads};
    std::vector<BodyPair> grid, sap;
    HashGrid hash_grid;
    hash_grid.find_pairs(input, &grid);
    EXPECT_EQ(grid, expected) << "hash grid, " << threads << " threads";
    sweep_and_prune(input, &sap);
    EXPECT_EQ(sap, expected) << "sweep and prune, " << threads << " threads";
    // A second call reuses the buffers and must give the same answer.
    hash_grid.find_pairs(input, &grid);
    EXPECT_EQ(grid, expected);
  }
}

// Sweep and prune starts each call from the last call's order along x: reused while the boxes
// drift, jump across the scene, die, come back, turn unbounded and more slots appear, it must give
// brute force's pairs every call (a stale order or a body left out of it would lose pairs).
TEST(BroadPhase, SweepAndPruneKeptFromCallToCallEqualsBruteForce) {
  Random rng(7);
  Scene scene = make_scene("uniform", rng, 120);
  SweepAndPrune sweep;
  std::vector<BodyPair> pairs;
  std::size_t compared = 0;
  for (int call = 0; call < 60; ++call) {
    for (std::size_t i = 0; i < scene.bounds.size(); ++i) {
      Aabb& box = scene.bounds[i];
      if (call % 10 == 9 && i % 7 == call % 7) {
        const Vec3 centre = rng.vector(0, 20), half = rng.vector(0.2, 0.6);
        box = {centre - half, centre + half};  // a jump: far out of order
      } else if (box.is_bounded() && box.min.x() <= box.max.x()) {
        const Vec3 drift = rng.vector(-0.3, 0.3);
        box.min += drift;
        box.max += drift;
      }
    }
    if (call == 20) scene.bounds[3] = Aabb();  // dead
    if (call == 30) scene.bounds[3] = {Vec3(5, 5, 5), Vec3(6, 6, 6)};
    if (call == 25) scene.bounds[10] = Aabb::infinite();
    if (call == 40) scene.bounds[10] = {Vec3(1, 1, 1), Vec3(2, 2, 2)};
    if (call == 35) add_box(scene, Vec3(10, 10, 10), Vec3::Constant(3), true);
    if (call == 45) scene.movable[scene.bounds.size() - 1] = 0;
    const BroadPhaseInput input{scene.bounds, scene.movable, 1};
    EXPECT_FALSE(sweep.find_pairs(input, &pairs));
    const std::vector<BodyPair> expected = brute_force(scene);
    EXPECT_EQ(pairs, expected) << "call " << call;
    compared += expected.size();
  }
  EXPECT_GT(compared, 60u * 50u) << "a scene with few pairs tests little";
}

// Issue 31 (4): bodies heaped inside one another have pairs in the square of their number (3000
// boxes spawned at one point took 17 GB and a minute a step). Past input.max_pairs both methods
// keep the first pairs in order, the same for any thread count, and say so.
TEST(BroadPhase, PairsPastTheBoundAreTheFirstOnesForAnyThreadCount) {
  Random rng(31);
  Scene scene = make_scene("clustered", rng, 800);
  for (int i = 0; i < 300; ++i)  // a heap: 300 boxes at one point, 45,000 pairs among them
    add_box(scene, Vec3(1, 1, 1), Vec3::Constant(0.5), true);
  const std::vector<BodyPair> all = brute_force(scene);
  ASSERT_GT(all.size(), 45000u);
  for (std::size_t bound : {std::size_t{1}, std::size_t{1000}, all.size() / 2, all.size()}) {
    const std::vector<BodyPair> first(all.begin(), all.begin() + static_cast<long>(bound));
    for (int threads : {1, 2, 3}) {
      BroadPhaseInput input{scene.bounds, scene.movable, threads};
      input.max_pairs = bound;
      std::vector<BodyPair> grid, sap;
      HashGrid hash_grid;
      EXPECT_EQ(hash_grid.find_pairs(input, &grid), bound < all.size()) << bound;
      EXPECT_EQ(grid, first) << "hash grid, bound " << bound << ", " << threads << " threads";
      EXPECT_EQ(sweep_and_prune(input, &sap), bound < all.size()) << bound;
      EXPECT_EQ(sap, first) << "sweep and prune, bound " << bound;
    }
  }
}

// A box of half extent 1e18 m once made the grid put it on its coarsest level, where it still
// covered 1e4 cells a side: memory grew without bound. It, and bodies too far out for the cell
// numbers, must meet every body directly, with the same pairs as brute force.
TEST(BroadPhase, HugeAndFarBodiesCostNoMemoryInProportionToTheirSize) {
  Random rng(7);
  Scene scene = make_scene("uniform", rng, 200);
  add_box(scene, Vec3::Zero(), Vec3::Constant(1e18), true);
  add_box(scene, Vec3(10, 10, 10), Vec3(1e18, 0.5, 0.5), false);
  add_box(scene, Vec3(1e300, 0, 0), Vec3::Constant(1), true);
  add_box(scene, Vec3(1e300, 0, 0.5), Vec3::Constant(1), true);
  const std::vector<BodyPair> expected = brute_force(scene);
  ASSERT_GT(expected.size(), 300u);  // the huge box meets every body
  for (int threads : {1, 2}) {
    HashGrid grid;
    std::vector<BodyPair> pairs;
    grid.find_pairs({scene.bounds, scene.movable, threads}, &pairs);
    EXPECT_EQ(pairs, expected) << threads << " threads";
  }
}

// Resting bodies (not movable) keep their cells while the caller's resting_version stays: the
// moving bodies move, grow and shrink between calls, and the pairs still equal brute force; a
// change of the resting bodies under a new version is picked up. Most bodies rest here, and sizes
// span 1 mm to 100 m, so moving boxes meet finer resting levels both cell by cell and body by body.
TEST_P(BroadPhaseScenes, RestingCellsKeptWhileTheyDoNotChange) {
  Random rng(5);
  Scene scene = make_scene(GetParam(), rng, 1500);
  for (std::size_t i = 0; i + 2 < scene.movable.size(); ++i)
    scene.movable[i] = i % 7 == 0 ? 1 : 0;
  auto moving_of = [](const Scene& s) {
    std::vector<std::uint32_t> moving;
    for (std::uint32_t i = 0; i < s.movable.size(); ++i)
      if (s.movable[i]) moving.push_back(i);
    return moving;
  };
  for (int threads : {1, 2}) {
    HashGrid grid;
    Scene now = scene;
    std::uint64_t version = 7;
    for (int call = 0; call < 6; ++call) {
      if (call == 4) {
        // A resting body grows over its neighbours and another starts to move.
        now.bounds[3].max += Vec3::Constant(5);
        now.movable[10] = 1;
        ++version;
      }
      const std::vector<std::uint32_t> moving = moving_of(now);
      BroadPhaseInput input{now.bounds, now.movable, threads};
      input.moving = moving;
      input.moving_listed = true;
      input.resting_version = version;
      std::vector<BodyPair> pairs;
      grid.find_pairs(input, &pairs);
      const std::vector<BodyPair> expected = brute_force(now);
      ASSERT_GT(expected.size(), 20u);
      EXPECT_EQ(pairs, expected) << threads << " threads, call " << call;
      for (std::uint32_t i : moving) {
        if (!now.bounds[i].is_bounded()) continue;
        const Vec3 shift = rng.vector(-1, 1);
        const double grow = rng.uniform(0.5, 2.0);
        const Vec3 centre = 0.5 * (now.bounds[i].min + now.bounds[i].max) + shift;
        const Vec3 half = 0.5 * grow * (now.bounds[i].max - now.bounds[i].min);
        now.bounds[i] = {centre - half, centre + half};
      }
    }
  }
}

// A few resting bodies change between calls and the caller lists them (resting_changes, since the
// version of the call before): the grid relists those alone. Each round one resting body moves onto
// its neighbours, one grows, one starts to move, one comes to rest where another moving body was,
// and one slot dies, some slots listed twice; the pairs must equal brute force. A call whose list
// starts at a version the grid never saw (the list is then incomplete for it) relists everything.
TEST_P(BroadPhaseScenes, LoggedRestingChangesRelistThoseBodiesAlone) {
  Random rng(11);
  Scene scene = make_scene(GetParam(), rng, 1500);
  for (std::size_t i = 0; i + 2 < scene.movable.size(); ++i)
    scene.movable[i] = i % 7 == 0 ? 1 : 0;
  for (int threads : {1, 2}) {
    HashGrid grid;
    Scene now = scene;
    std::uint64_t version = 3;
    std::vector<std::uint32_t> changes;
    std::uint64_t since = 0;
    for (int call = 0; call < 8; ++call) {
      if (call > 0) {
        since = version;
        changes.clear();
        const auto pick_resting = [&] {
          for (;;) {
            const auto i = static_cast<std::uint32_t>(rng.uniform(0, now.bounds.size() - 1));
            if (!now.movable[i] && now.bounds[i].is_bounded() &&
                now.bounds[i].min.x() <= now.bounds[i].max.x())
              return i;
          }
        };
        const auto pick_moving = [&] {
          for (;;) {
            const auto i = static_cast<std::uint32_t>(rng.uniform(0, now.bounds.size() - 1));
            if (now.movable[i] && now.bounds[i].is_bounded()) return i;
          }
        };
        const std::uint32_t moved = pick_resting();
        const std::uint32_t target = pick_resting();
        const Vec3 half = 0.5 * (now.bounds[moved].max - now.bounds[moved].min);
        const Vec3 centre = 0.5 * (now.bounds[target].min + now.bounds[target].max);
        now.bounds[moved] = {centre - half, centre + half};
        const std::uint32_t grown = pick_resting();
        now.bounds[grown].max += Vec3::Constant(3);
        const std::uint32_t woken = pick_resting();
        now.movable[woken] = 1;
        const std::uint32_t settled = pick_moving();
        now.movable[settled] = 0;
        const std::uint32_t died = pick_resting();
        now.bounds[died] = Aabb();
        changes = {moved, grown, woken, settled, died, moved, settled};
        version += 2;
      }
      std::vector<std::uint32_t> moving;
      for (std::uint32_t i = 0; i < now.movable.size(); ++i)
        if (now.movable[i]) moving.push_back(i);
      BroadPhaseInput input{now.bounds, now.movable, threads};
      input.moving = moving;
      input.moving_listed = true;
      input.resting_version = version;
      if (call > 0 && call != 5) {
        input.resting_changes = changes;
        input.changes_since = since;
      }
      if (call == 6) input.changes_since = since + 1;  // a version the grid never saw
      std::vector<BodyPair> pairs;
      grid.find_pairs(input, &pairs);
      EXPECT_EQ(pairs, brute_force(now)) << threads << " threads, call " << call;
      // The moving bodies move between calls, as in a world.
      for (std::uint32_t i : moving) {
        if (!now.bounds[i].is_bounded()) continue;
        const Vec3 shift = rng.vector(-0.5, 0.5);
        now.bounds[i] = {now.bounds[i].min + shift, now.bounds[i].max + shift};
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, BroadPhaseScenes,
                         ::testing::Values("uniform", "clustered", "wide", "borders", "far",
                                           "terrain", "heap"));

TEST(BroadPhase, WorldNeverPairsStaticBodiesAndFindsContacts) {
  World world;
  BodyDef ground;
  ground.shape = HalfSpaceDef{};
  ground.type = BodyType::kStatic;
  ASSERT_TRUE(world.create_body(ground).ok());
  BodyDef wall;
  wall.type = BodyType::kStatic;
  wall.position = Vec3(0, 0, 0.4);  // a static box sunk into the static ground
  ASSERT_TRUE(world.create_body(wall).ok());
  BodyDef box;
  box.position = Vec3(3, 0, 0.45);
  ASSERT_TRUE(world.create_body(box).ok());
  for (BroadPhaseMethod method : {BroadPhaseMethod::kHashGrid, BroadPhaseMethod::kSweepAndPrune}) {
    world.set_broad_phase(method);
    const auto pairs = world.find_pairs();
    ASSERT_EQ(pairs.size(), 1u);
    EXPECT_EQ(pairs[0], (BodyPair{0, 2}));
    const auto contacts = world.find_contacts();
    ASSERT_EQ(contacts.size(), 1u);
    EXPECT_EQ(contacts[0].manifold.count, 4);
    EXPECT_NEAR(contacts[0].manifold.depth, 0.05, 1e-12);
  }
}

}  // namespace
}  // namespace tumble
