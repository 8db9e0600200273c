// The exact solver with joints (physics/src/exact_joints.h): limits, cones and contacts as one
// LCP each substep, the joints held through their tree. Against statics in closed form: a bar
// resting on its hinge's limit carries its weight's torque there exactly, a limit away from its
// bound carries nothing, a heavy box resting on such a bar is held by contact, bar and limit
// together; the island counted as exact, too large a problem left to the soft contacts, and the
// same bits for any thread count.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "physics/world.h"
#include "scene_runner.h"
#include "scenes/standard.h"

namespace tumble {
namespace {

constexpr double kDt = 1.0 / 60;
constexpr double kG = 9.81;

WorldSettings exact_settings() {
  WorldSettings settings;
  settings.solver.kind = SolverKind::kExact;
  settings.solver.sleeping = false;
  return settings;
}

// A 1 kg bar, 1 m long, along x from a hinge at (0, 0, 5) about y; its underside at z 4.95.
BodyId add_bar(World& world) {
  BodyDef def;
  def.shape = BoxDef{Vec3(0.5, 0.05, 0.05)};
  def.position = Vec3(0.5, 0, 5);
  def.mass = 1;
  return world.create_body(def).value();
}

JointId hinge_bar(World& world, BodyId bar, const JointLimit& limit = {}) {
  JointDef def;
  def.kind = JointKind::kHinge;
  def.a = bar;
  def.anchor = Vec3(0, 0, 5);
  def.axis = Vec3::UnitY();
  def.limit = limit;
  return world.create_joint(def).value();
}

// A 0.2 m box of `mass` 1 mm above the level bar's top, 0.8 m out from the hinge.
BodyId add_box_on_bar(World& world, double mass) {
  BodyDef def;
  def.shape = BoxDef{Vec3(0.1, 0.1, 0.1)};
  def.position = Vec3(0.8, 0, 5.151);
  def.mass = mass;
  return world.create_body(def).value();
}

TEST(ExactJoints, ABarOnItsHingesLimitCarriesItsWeightsTorqueThere) {
  // The bar released level falls onto the bound 0.5 rad below it (a is the bar and b the world:
  // the world turns by -angle relative to the bar).
  World world(exact_settings());
  const BodyId bar = add_bar(world);
  const JointId hinge = hinge_bar(world, bar, {true, -0.5, 0.5});
  double most = 0;
  for (int i = 0; i < 180; ++i) {
    ASSERT_TRUE(world.step(kDt));
    most = std::max(most, std::abs(world.joint_reading(hinge).value().position));
  }
  EXPECT_EQ(world.last_step().exact_islands, 1u);
  EXPECT_EQ(world.last_step().exact_fallbacks, 0u);
  const JointReading r = world.joint_reading(hinge).value();
  EXPECT_NEAR(std::abs(r.position), 0.5, 1e-9);
  EXPECT_LT(most, 0.5 + 1e-9);         // the gap closes over the move, no further
  EXPECT_LT(std::abs(r.speed), 1e-6);  // the compliance's millionth, as above
  const double torque = kG * 0.5 * std::cos(0.5);
  EXPECT_NEAR(std::abs(r.effort), torque, 1e-6 * torque);
  EXPECT_NEAR(r.force.norm(), kG, 1e-6 * kG);
}

TEST(ExactJoints, ALimitAwayFromItsBoundCarriesNothing) {
  // The bar swings freely between bounds at +-2 rad: the limit's row is in every LCP, and its
  // impulse stays exactly 0 (a Gauss-Seidel row's would too; a regularised one would not).
  World world(exact_settings());
  const BodyId bar = add_bar(world);
  const JointId hinge = hinge_bar(world, bar, {true, -2, 2});
  for (int i = 0; i < 30; ++i) {
    ASSERT_TRUE(world.step(kDt));
    const JointReading r = world.joint_reading(hinge).value();
    ASSERT_LT(std::abs(r.position), 1.8);
    EXPECT_EQ(r.effort, 0) << "step " << i;
  }
}

// A 1000 kg box resting on the 1 kg bar, the bar on its hinge's lower limit: the contact's
// impulse passes through the bar to the limit within one LCP, so the box rests. Over 3 s it sinks
// less than 1e-5 m (measured 7.2e-7: the answer's compliance, 2.4e-7 m/s) and creeps along the
// bar less than 1e-4 m (5.9e-5), and the limit carries both weights' torque within 1e-4 of it
// (7.4e-5, the creep's lever). Before the push-out held the bounds too, the push between the box
// and the bar moved the bar through its limit alone and the box sank on at its answer's
// compliance (2.9e-4 m in 3 s). `auto` gives the island the same LCP (the box more than
// kAutoExactJointedMassRatio times the bar); with soft contacts, swept beside the limit's row,
// the box sank 1.5 cm at 100 kg and fell through the bar at 1000.
TEST(ExactJoints, AHeavyBoxRestsOnALightHingedBarOnItsLimit) {
  for (const SolverKind kind : {SolverKind::kExact, SolverKind::kAuto}) {
    SCOPED_TRACE(std::string(solver_name(kind)));
    WorldSettings settings = exact_settings();
    settings.solver.kind = kind;
    World world(settings);
    const BodyId bar = add_bar(world);
    const JointId hinge = hinge_bar(world, bar, {true, 0, 0.5});
    const BodyId box = add_box_on_bar(world, 1000);
    double rest_z = 0;
    for (int i = 0; i < 180; ++i) {
      ASSERT_TRUE(world.step(kDt));
      if (i == 29) rest_z = world.body(box).position().z();  // landed, 0.5 s in
      EXPECT_EQ(world.last_step().exact_fallbacks, 0u);
    }
    EXPECT_EQ(world.last_step().exact_islands, 1u);
    const Vec3 end = world.body(box).position();
    EXPECT_LT(rest_z - end.z(), 1e-5);
    EXPECT_GT(end.z(), 5.15 - 1e-4);  // on the bar's top (5.05), not in it past the slop
    EXPECT_LT(std::abs(end.x() - 0.8), 1e-4);
    const JointReading r = world.joint_reading(hinge).value();
    EXPECT_LT(std::abs(r.position), 1e-9);
    const double torque = kG * (1000 * 0.8 + 0.5);
    EXPECT_NEAR(std::abs(r.effort), torque, 1e-4 * torque);
  }
  // Below the ratio auto keeps its soft contacts (the box of 10 kg gives 1.6 mm).
  WorldSettings settings = exact_settings();
  settings.solver.kind = SolverKind::kAuto;
  World world(settings);
  hinge_bar(world, add_bar(world), {true, 0, 0.5});
  add_box_on_bar(world, 10);
  std::uint32_t exact = 0;
  for (int i = 0; i < 60; ++i) {
    ASSERT_TRUE(world.step(kDt));
    exact += world.last_step().exact_islands;
  }
  EXPECT_EQ(exact, 0u);
}

TEST(ExactJoints, TooManyBoundRowsForLemkeAreSolvedAsAutoSolvesThem) {
  // 60 hinges with ranged limits: 60 rows, past exact_max_island_points (48): the island is
  // counted oversized and solved by the direct tree solve with soft contacts.
  World world(exact_settings());
  BodyId previous{};
  for (int i = 0; i < 60; ++i) {
    BodyDef def;
    def.shape = BoxDef{Vec3(0.05, 0.05, 0.05)};
    def.position = Vec3(0.2 * i + 0.1, 0, 5);
    def.mass = 1;
    const BodyId link = world.create_body(def).value();
    JointDef hinge;
    hinge.kind = JointKind::kHinge;
    hinge.a = link;
    hinge.b = previous;
    hinge.anchor = Vec3(0.2 * i, 0, 5);
    hinge.axis = Vec3::UnitY();
    hinge.limit = {true, -1, 1};
    ASSERT_TRUE(world.create_joint(hinge));
    previous = link;
  }
  ASSERT_TRUE(world.step(kDt));
  EXPECT_EQ(world.last_step().exact_oversized, 1u);
  EXPECT_EQ(world.last_step().exact_islands, 0u);
  EXPECT_EQ(world.last_step().joint_tree_islands, 1u);
}

TEST(ExactJoints, RagdollsOnTheGroundTakeTheSameBitsForAnyThreadCount) {
  SceneDef scene = standard_scene("ragdolls:4").value();
  scene.world.solver.kind = SolverKind::kExact;
  std::uint64_t hashes[2];
  std::uint32_t exact = 0;
  for (int t = 0; t < 2; ++t) {
    scene.world.threads = t + 1;
    World world = make_world(scene).value();
    for (int i = 0; i < 120; ++i) {
      ASSERT_TRUE(world.step(scene.dt));
      exact += t == 0 ? world.last_step().exact_islands : 0;
    }
    hashes[t] = testing::state_hash(world);
  }
  EXPECT_EQ(hashes[0], hashes[1]);
  EXPECT_GT(exact, 0u);  // the LCP with joints really ran
}

// The direct solve's position passes hold the limits and cones past their bounds with the joints'
// own rows (joint_solver.h, position_equations): the ragdolls falling and piling (8 of them, 5 s)
// end every step with their joints within 1e-5 m or rad on average. (With the bounds a pass of
// their own between the direct ones, each undid part of the other: 4.4e-5 on average.) The worst
// is one joint at one hard landing, a draw of the pile's chaos: over dt = 1/60 (1 + 0.002 k),
// k = 0..9, it ranged from 2.6e-4 to 3.1e-2 (auto) and 1.7e-3 to 2.0e-2 (exact) with the midpoint
// rule for every top, and from 5.5e-4 to 3.1e-2 and 2.1e-3 to 2.2e-2 with the symmetric tops'
// closed form (integrate.cc), their means 2.1e-6 and 2.4e-6 (auto): the bound is that spread's.
TEST(ExactJoints, RagdollsHoldTheirJointsAndBoundsTogether) {
  for (const SolverKind kind : {SolverKind::kAuto, SolverKind::kExact}) {
    SceneDef scene = standard_scene("ragdolls:8").value();
    scene.world.solver.kind = kind;
    scene.world.threads = 1;
    World world = make_world(scene).value();
    double worst = 0, sum = 0;
    int count = 0;
    for (int i = 0; i < 300; ++i) {
      ASSERT_TRUE(world.step(scene.dt));
      for (std::uint32_t slot = 0; slot < world.joint_slot_count(); ++slot) {
        const JointId id = world.joint_at(slot);
        if (!world.contains(id)) continue;
        const double error = world.joint_error(id).value();
        worst = std::max(worst, error);
        sum += error;
        ++count;
      }
    }
    ASSERT_GT(count, 300 * 50);
    EXPECT_LT(sum / count, 1e-5) << solver_name(kind);
    EXPECT_LT(worst, 5e-2) << solver_name(kind);
  }
}

}  // namespace
}  // namespace tumble
