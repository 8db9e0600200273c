// Sleeping: resting islands stop costing anything, and wake when touched or undermined.
#include <gtest/gtest.h>

#include <string>

#include "scene_runner.h"

namespace tumble::testing {
namespace {

bool all_asleep(const World& world) {
  for (const BodyView b : dynamic_bodies(world))
    if (!b->asleep()) return false;
  return true;
}

TEST(Sleeping, SettledStackSleepsAndCostsNothing) {
  World world = build(tower_scene(5));
  double fell_asleep = -1;
  run(world, 1.0 / 60, 300, [&](long s) {
    if (fell_asleep < 0 && all_asleep(world)) fell_asleep = s / 60.0;
  });
  ASSERT_GT(fell_asleep, 0);
  EXPECT_LT(fell_asleep, 2.0);  // at rest from the start: the delay (0.5 s) and settling
  const StepStats& stats = world.last_step();
  EXPECT_EQ(stats.sleeping_bodies, 5u);
  EXPECT_EQ(stats.pairs, 0u);  // sleepers pair with nothing but moving bodies
  EXPECT_EQ(stats.contact_points, 0u);
  EXPECT_EQ(stats.islands, 0u);
}

// Asleep, a stack still rests on the floor: its contacts are reported (not solved), and each
// box's contacts carry the weight above it. They go when the stack wakes, and return when it
// sleeps again.
TEST(Sleeping, SleepersReportTheContactsThatCarryTheirWeight) {
  World world = build(tower_scene(5));
  run(world, 1.0 / 60, 300);
  ASSERT_TRUE(all_asleep(world));
  EXPECT_EQ(world.contacts().size(), 0u);  // nothing solved
  const auto resting = world.resting_contacts();
  const auto forces = world.resting_contact_forces();
  ASSERT_EQ(resting.size(), 5u);  // floor-box and four box-box faces
  std::size_t points = 0;
  for (const Contact& c : resting)
    points += static_cast<std::size_t>(c.manifold.count);
  EXPECT_EQ(forces.size(), points);
  EXPECT_EQ(world.last_step().resting_contact_points, points);
  // The floor carries all five boxes: the forces of the contacts with the static ground sum to
  // the stack's weight.
  double on_floor = 0, weight = 0;
  std::size_t point = 0;
  for (const Contact& c : resting)
    for (int i = 0; i < c.manifold.count; ++i, ++point)
      if (world.body(c.a)->is_static() || world.body(c.b)->is_static()) on_floor += forces[point];
  for (const BodyView b : dynamic_bodies(world))
    weight += b->mass() * world.settings().gravity.norm();
  EXPECT_NEAR(on_floor, weight, 1e-3 * weight);

  // Woken: the stored contacts go; the step solves its own again.
  ASSERT_TRUE(world.wake(world.id_at(3)).is_ok());
  EXPECT_EQ(world.resting_contacts().size(), 0u);
  ASSERT_TRUE(world.step(1.0 / 60).is_ok());
  EXPECT_EQ(world.last_step().resting_contact_points, 0u);
  EXPECT_GT(world.last_step().contact_points, 0u);
  run(world, 1.0 / 60, 120);
  ASSERT_TRUE(all_asleep(world));
  EXPECT_EQ(world.resting_contacts().size(), 5u);
}

// Switching sleeping off wakes every sleeper at once (else only a touch would).
TEST(Sleeping, SwitchedOffWhileAsleepWakesEverySleeper) {
  World world = build(pile_scene(27));
  run(world, 1.0 / 60, 600);
  ASSERT_GT(world.last_step().sleeping_bodies, 0u);
  WorldSettings settings = world.settings();
  settings.solver.sleeping = false;
  ASSERT_TRUE(world.set_settings(settings).is_ok());
  for (const BodyView b : dynamic_bodies(world))
    EXPECT_FALSE(b->asleep());
  EXPECT_EQ(world.resting_contacts().size(), 0u);
  ASSERT_TRUE(world.step(1.0 / 60).is_ok());
  EXPECT_EQ(world.last_step().sleeping_bodies, 0u);
}

// A pile of 250 falls, tumbles and settles; once every box is slower than the sleep speeds
// (0.05 m/s and rad/s) the whole pile is asleep within a second (the delay is 0.5 s).
TEST(Sleeping, SettledPileFallsAsleepSoonAfterSettling) {
  World world = build(pile_scene(250));
  const SolverSettings& solver = world.settings().solver;
  double last_moving = 0, all_asleep_at = -1;
  run(world, 1.0 / 60, 1200, [&](long s) {
    if (all_asleep_at >= 0) return;
    for (const BodyView b : dynamic_bodies(world))
      if (b->linear_velocity().norm() >= solver.sleep_linear_speed ||
          b->angular_velocity().norm() >= solver.sleep_angular_speed)
        last_moving = s / 60.0;
    if (all_asleep(world)) all_asleep_at = s / 60.0;
  });
  ASSERT_GT(all_asleep_at, 0) << "still awake after 20 s";
  EXPECT_LE(all_asleep_at - last_moving, 1.0);
  EXPECT_EQ(world.last_step().sleeping_bodies, 250u);
  EXPECT_EQ(world.last_step().contact_points, 0u);
}

TEST(Sleeping, RemovingTheBottomBoxWakesTheStackAndItFalls) {
  World world = build(tower_scene(3));
  run(world, 1.0 / 60, 120);
  ASSERT_TRUE(all_asleep(world));
  const BodyId bottom = world.id_at(1);
  const BodyId top = world.id_at(3);
  const double top_before = world.body(top)->position().z();
  ASSERT_TRUE(world.remove_body(bottom).is_ok());
  EXPECT_FALSE(world.body(top)->asleep());
  run(world, 1.0 / 60, 90);
  EXPECT_NEAR(world.body(top)->position().z(), top_before - 1.0, 0.01);
}

TEST(Sleeping, SleeperHitByANewBoxWakes) {
  World world = build(tower_scene(1));
  run(world, 1.0 / 60, 90);
  ASSERT_TRUE(all_asleep(world));
  BodyDef dropped;
  dropped.shape = BoxDef{Vec3::Constant(0.5)};
  dropped.mass = 1;
  dropped.position = Vec3(0.3, 0, 3);
  ASSERT_TRUE(world.create_body(dropped).ok());
  std::uint32_t woken = 0;
  run(world, 1.0 / 60, 120, [&](long) { woken += world.last_step().woken_bodies; });
  EXPECT_EQ(woken, 1u);
  // The new box came to rest on the old one (which did not let it through).
  const BodyView top = dynamic_bodies(world)[1];
  EXPECT_NEAR(top.position().z(), 1.5, 0.01);
  EXPECT_TRUE(all_finite(world));
}

TEST(Sleeping, CanBeSwitchedOff) {
  SceneDef scene = tower_scene(2);
  scene.world.solver.sleeping = false;
  World world = build(scene);
  run(world, 1.0 / 60, 120);
  EXPECT_EQ(world.last_step().sleeping_bodies, 0u);
  EXPECT_GT(world.last_step().contact_points, 0u);
}

}  // namespace
// Islands sleep as sets: waking one (by hand, or by removing a body under it) wakes its bodies
// and no others, in a world restored from a saved state as well.
TEST(Sleeping, WakingAnIslandWakesItsBodiesOnly) {
  WorldSettings settings;
  World world(settings);
  BodyDef ground;
  ground.type = BodyType::kStatic;
  ground.shape = HalfSpaceDef{};
  ASSERT_TRUE(world.create_body(ground));
  // Five stacks of two boxes, far apart: five islands.
  std::vector<std::pair<BodyId, BodyId>> stacks;
  for (int k = 0; k < 5; ++k) {
    BodyDef box;
    box.position = Vec3(4.0 * k, 0, 0.5);
    const BodyId bottom = world.create_body(box).value();
    box.position.z() = 1.5;
    stacks.push_back({bottom, world.create_body(box).value()});
  }
  for (int n = 0; n < 120 && world.last_step().sleeping_bodies < 10; ++n)
    ASSERT_TRUE(world.step(1.0 / 60));
  ASSERT_EQ(world.last_step().sleeping_bodies, 10u);

  auto awake = [](const World& w, const std::vector<std::pair<BodyId, BodyId>>& all) {
    std::vector<int> which;
    for (std::size_t k = 0; k < all.size(); ++k)
      which.push_back((w.body(all[k].first).asleep() ? 0 : 1) +
                      (w.body(all[k].second).asleep() ? 0 : 2));
    return which;
  };
  World restored = World::from_state(world.settings(), world.save_state()).value();
  for (World* w : {&world, &restored}) {
    ASSERT_TRUE(w->wake(stacks[1].second));
    EXPECT_EQ(awake(*w, stacks), (std::vector<int>{0, 3, 0, 0, 0}));
    ASSERT_TRUE(w->remove_body(stacks[3].first));  // the top box must fall: it wakes
    EXPECT_TRUE(!w->body(stacks[3].second).asleep());
    EXPECT_TRUE(w->body(stacks[4].first).asleep() && w->body(stacks[2].second).asleep());
  }
}

// The step keeps the moving bodies as a set: it solves those and the statics they touch, not
// every slot. The set follows bodies made, removed, put to sleep and woken, also when a body takes
// a freed slot below the others; a world restored from the state (which lists the moving bodies
// afresh) steps on to the same bits.
TEST(Sleeping, AStepSolvesTheMovingBodiesOnly) {
  World world;
  BodyDef ground;
  ground.type = BodyType::kStatic;
  ground.shape = HalfSpaceDef{};
  ASSERT_TRUE(world.create_body(ground));
  std::vector<BodyId> bottoms, tops;
  for (int k = 0; k < 6; ++k) {
    BodyDef box;
    box.position = Vec3(4.0 * k, 0, 0.5);
    bottoms.push_back(world.create_body(box).value());
    box.position.z() = 1.5;
    tops.push_back(world.create_body(box).value());
  }
  for (int n = 0; n < 120 && world.last_step().sleeping_bodies < 12; ++n)
    ASSERT_TRUE(world.step(1.0 / 60));
  ASSERT_EQ(world.last_step().sleeping_bodies, 12u);
  ASSERT_TRUE(world.step(1.0 / 60));
  EXPECT_EQ(world.last_step().solver_bodies, 0u);

  ASSERT_TRUE(world.wake(tops[4]));
  ASSERT_TRUE(world.step(1.0 / 60));
  EXPECT_EQ(world.last_step().solver_bodies, 3u);  // the stack and the ground under it
  EXPECT_EQ(world.last_step().sleeping_bodies, 10u);

  // Slot 1 (the first stack's bottom) is freed and taken by a box falling beside stack 5: the
  // first stack's top falls, and the set now holds slots out of order until the step sorts it.
  ASSERT_TRUE(world.remove_body(bottoms[0]));
  BodyDef dropped;
  dropped.position = Vec3(21.5, 0, 3);
  dropped.angular_velocity = Vec3(0.3, 0.2, 0.1);
  ASSERT_TRUE(world.create_body(dropped));
  ASSERT_TRUE(world.step(1.0 / 60));
  // stack 4 (2), the fallen top (1), the new box (1) and the ground.
  EXPECT_EQ(world.last_step().solver_bodies, 5u);
  World restored = World::from_state(world.settings(), world.save_state()).value();
  for (int n = 0; n < 90; ++n) {
    ASSERT_TRUE(world.step(1.0 / 60));
    ASSERT_TRUE(restored.step(1.0 / 60));
  }
  EXPECT_EQ(state_hash(world), state_hash(restored));
  EXPECT_EQ(world.last_step().solver_bodies, restored.last_step().solver_bodies);
  EXPECT_EQ(world.last_step().sleeping_bodies, restored.last_step().sleeping_bodies);
  EXPECT_GT(world.last_step().sleeping_bodies, 0u);
}

// Removing or moving a static body wakes the sleepers on it (a static joins no island, so only
// this look finds them), through the broad phase's kept cells and the bodies fallen asleep since it
// last listed them, instead of a look at every slot: a hundred boxes on static pedestals, enough
// for the hash grid. Right after they fall asleep, one step later, and when the ground moves
// (a half-space is near everything).
TEST(Sleeping, RemovingAStaticWakesTheSleepersOnItOnly) {
  World world;
  BodyDef ground;
  ground.type = BodyType::kStatic;
  ground.shape = HalfSpaceDef{};
  const BodyId floor = world.create_body(ground).value();
  std::vector<BodyId> pedestals, boxes;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) {
      BodyDef box;
      box.position = Vec3(3.0 * i, 3.0 * j, 0.5);
      box.type = BodyType::kStatic;
      pedestals.push_back(world.create_body(box).value());
      box.type = BodyType::kDynamic;
      box.position.z() = 1.5;
      boxes.push_back(world.create_body(box).value());
    }
  for (int n = 0; n < 120 && world.last_step().sleeping_bodies < 100; ++n)
    ASSERT_TRUE(world.step(1.0 / 60));
  ASSERT_EQ(world.last_step().sleeping_bodies, 100u);
  auto awake = [&] {
    std::vector<std::size_t> which;
    for (std::size_t k = 0; k < boxes.size(); ++k)
      if (!world.body(boxes[k]).asleep()) which.push_back(k);
    return which;
  };
  ASSERT_TRUE(world.remove_body(pedestals[0]));  // they fell asleep in the last step
  EXPECT_EQ(awake(), (std::vector<std::size_t>{0}));
  ASSERT_TRUE(world.step(1.0 / 60));
  ASSERT_TRUE(world.remove_body(pedestals[57]));  // listed by the grid now
  EXPECT_EQ(awake(), (std::vector<std::size_t>{0, 57}));
  BodyMotion lowered;
  lowered.position = Vec3(3.0 * 3, 3.0 * 3, 0.499);
  ASSERT_TRUE(world.set_motion(pedestals[33], lowered));
  EXPECT_EQ(awake(), (std::vector<std::size_t>{0, 33, 57}));
  lowered.position = Vec3(0, 0, -0.001);
  ASSERT_TRUE(world.set_motion(floor, lowered));
  EXPECT_EQ(awake().size(), 100u);
}

// A world keeps its resting bodies' bounds and grid cells while bodies are made, removed, woken
// and put to sleep around them; a twin world whose broad phase keeps nothing (sweep and prune)
// must find the same pairs, so both step on to the same bits. Boxes are dropped on sleepers (which
// wake), moving ones and sleepers are removed, slots are freed and taken again.
TEST(Sleeping, KeptRestingCellsGiveTheSweepAndPrunePairs) {
  auto build_world = [](BroadPhaseMethod method) {
    WorldSettings settings;
    settings.broad_phase = method;
    World world(settings);
    BodyDef ground;
    ground.type = BodyType::kStatic;
    ground.shape = HalfSpaceDef{};
    EXPECT_TRUE(world.create_body(ground));
    for (int i = 0; i < 12; ++i)
      for (int j = 0; j < 12; ++j) {
        BodyDef box;
        box.position = Vec3(1.5 * i, 1.5 * j, 0.5);
        EXPECT_TRUE(world.create_body(box));
      }
    return world;
  };
  World grid = build_world(BroadPhaseMethod::kHashGrid);
  World sap = build_world(BroadPhaseMethod::kSweepAndPrune);
  auto step_both = [&](const std::string& when) {
    ASSERT_TRUE(grid.step(1.0 / 60));
    ASSERT_TRUE(sap.step(1.0 / 60));
    ASSERT_EQ(grid.last_step().pairs, sap.last_step().pairs) << when;
    ASSERT_EQ(state_hash(grid), state_hash(sap)) << when;
  };
  std::vector<BodyId> dropped;
  for (int n = 0; n < 150; ++n) {
    if (n >= 60 && n % 3 == 0) {
      BodyDef box;
      box.position = Vec3(1.5 * (n % 12), 1.5 * ((n / 12) % 12), 3.0);
      box.angular_velocity = Vec3(0.5, -0.3, 0.2);
      const BodyId a = grid.create_body(box).value();
      const BodyId b = sap.create_body(box).value();
      ASSERT_EQ(a, b);
      dropped.push_back(a);
    }
    if (n >= 60 && n % 10 == 5 && dropped.size() > 2) {  // a moving body goes
      const BodyId id = dropped[dropped.size() - 2];
      if (grid.contains(id)) {
        ASSERT_TRUE(grid.remove_body(id));
        ASSERT_TRUE(sap.remove_body(id));
      }
    }
    if (n >= 60 && n % 14 == 0) {  // a sleeper, or a body that woke, goes
      const BodyId id = grid.id_at(1 + (n * 7) % 144);
      if (id.is_valid()) {
        ASSERT_TRUE(grid.remove_body(id));
        ASSERT_TRUE(sap.remove_body(id));
      }
    }
    ASSERT_NO_FATAL_FAILURE(step_both("step " + std::to_string(n)));
  }
  // Then, once everything sleeps, boxes dropped in the open and removed while they fall: the
  // resting bodies do not change at all, so nothing is listed again, and a removed box must leave
  // no bounds behind.
  for (int n = 0; n < 600 && grid.last_step().solver_bodies > 0; ++n) {
    ASSERT_TRUE(grid.step(1.0 / 60));
    ASSERT_TRUE(sap.step(1.0 / 60));
  }
  ASSERT_EQ(grid.last_step().solver_bodies, 0u);
  BodyId falling;
  for (int n = 0; n < 60; ++n) {
    if (n % 4 == 0) {
      BodyDef box;
      box.position = Vec3(40 + n, 0, 5);
      falling = grid.create_body(box).value();
      ASSERT_EQ(sap.create_body(box).value(), falling);
    }
    if (n % 4 == 2) {
      ASSERT_TRUE(grid.remove_body(falling));
      ASSERT_TRUE(sap.remove_body(falling));
    }
    ASSERT_NO_FATAL_FAILURE(step_both("open step " + std::to_string(n)));
  }
  // Then one sleeper woken by hand every step, which falls asleep again half a second later, and
  // boxes dropped onto sleepers that woke and fell asleep again since the grid last listed every
  // resting body: the grid relists only the bodies that changed (World's resting log), and must
  // still know every sleeper.
  for (int n = 0; n < 150; ++n) {
    const BodyId poked = grid.id_at(1 + (n * 5) % 144);
    if (poked.is_valid()) {
      ASSERT_TRUE(grid.wake(poked));
      ASSERT_TRUE(sap.wake(poked));
    }
    if (n >= 45 && n % 6 == 0) {
      const BodyId below = grid.id_at(1 + ((n - 40) * 5) % 144);
      if (below.is_valid() && grid.body(below).asleep()) {
        BodyDef box;
        box.position = grid.body(below).position() + Vec3(0.1, -0.1, 1.2);
        const BodyId a = grid.create_body(box).value();
        ASSERT_EQ(sap.create_body(box).value(), a);
      }
    }
    ASSERT_NO_FATAL_FAILURE(step_both("poked step " + std::to_string(n)));
  }
}

}  // namespace tumble::testing

namespace tumble::testing {
namespace {

// A 1 kg box on a frictionless slider held by a 100 N/m spring to the world (no damping): it
// swings about where the spring rests with amplitude `amplitude` at 10 rad/s, its speed peaking
// at 10 times the amplitude.
World swinging_box(double amplitude) {
  World world;
  BodyDef box;
  box.shape = BoxDef{Vec3::Constant(0.1)};
  box.mass = 1;
  box.position = Vec3(0, 0, 1);
  box.linear_velocity = Vec3(10 * amplitude, 0, 0);
  JointDef slider;
  slider.kind = JointKind::kSlider;
  slider.a = world.create_body(box).value();
  slider.anchor = box.position;
  slider.axis = Vec3::UnitX();
  slider.spring = {true, 0, 100, 0};
  EXPECT_TRUE(world.create_joint(slider).ok());
  return world;
}

// When (s, from now) the world's bodies are all asleep, or -1 if they are not after 5 s.
double falls_asleep_after(World& world) {
  for (int step = 1; step <= 300; ++step) {
    EXPECT_TRUE(world.step(1.0 / 60).is_ok());
    if (all_asleep(world)) return step / 60.0;
  }
  return -1;
}

// What a body moved counts, not how fast it moves: a box swinging 1 cm either way at up to 0.1
// m/s (twice the sleep speed at every peak; a speed test alone never lets it sleep) stays within
// 2.5 cm of where it was and falls asleep after the 0.5 s delay; one swinging 5 cm either way
// (0.5 m/s) keeps leaving that reach and stays awake.
TEST(Sleeping, ABodySwingingInPlaceFallsAsleepAndOneSwingingFarDoesNot) {
  World small = swinging_box(0.01);
  const double asleep_after = falls_asleep_after(small);
  EXPECT_GE(asleep_after, 0.5);
  EXPECT_LE(asleep_after, 1.0);
  World far = swinging_box(0.05);
  EXPECT_EQ(falls_asleep_after(far), -1);
}

// The sleep anchor is part of the saved state: a world restored a quarter of a second into a
// swinging box's quiet time falls asleep on the same step as the world it was saved from (were
// the anchor lost, the box would be far from it and its quiet time would begin again).
TEST(Sleeping, ARestoredWorldKeepsItsBodiesSleepAnchors) {
  World world = swinging_box(0.01);
  run(world, 1.0 / 60, 15);
  ASSERT_FALSE(all_asleep(world));
  World restored = World::from_state(world.settings(), world.save_state()).value();
  const double expected = falls_asleep_after(world);
  ASSERT_GT(expected, 0);
  EXPECT_EQ(falls_asleep_after(restored), expected);
}

}  // namespace
}  // namespace tumble::testing
