// The exact solver with joints (physics/src/exact_joints.h): contacts, limits and cones as one
// LCP each substep, the joints held through their tree. Each against statics in closed form: a
// hinged bar resting on a ball shares its weight between hinge and contact as its moments say, a
// bar resting on its hinge's limit carries its weight's torque there exactly, a limit away from
// its bound carries nothing; the island counted as exact, too large a problem refused to Lemke,
// and the same bits for any thread count.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

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
BodyId add_bar(World& world, double friction = 0.5) {
  BodyDef def;
  def.friction = friction;
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

// The bar level on its hinge, its underside on a static ball at x = `at`: the contact carries
// m g (L/2) / at, the hinge the rest. Frictionless: with friction the split is statically
// indeterminate (the hinge can hold any horizontal push the contact's friction gives, and that
// push's lever about the hinge moves the weight's share), and any answer in the cone is right.
struct BarOnBall {
  World world;
  BodyId bar;
  JointId hinge;
};
void make_bar_on_ball(BarOnBall* s, SolverKind solver, double at) {
  WorldSettings settings = exact_settings();
  settings.solver.kind = solver;
  s->world = World(settings);
  s->bar = add_bar(s->world, 0);
  s->hinge = hinge_bar(s->world, s->bar);
  BodyDef ball;
  ball.friction = 0;
  ball.type = BodyType::kStatic;
  ball.shape = SphereDef{0.1};
  ball.position = Vec3(at, 0, 4.85);
  (void)s->world.create_body(ball).value();
}

double contact_force(const World& world) {
  const std::span<const double> impulses = world.contact_impulses();
  return std::accumulate(impulses.begin(), impulses.end(), 0.0) / kDt;
}

TEST(ExactJoints, AHingedBarOnABallSharesItsWeightAsItsMomentsSay) {
  const double at = 0.9;
  const double on_ball = kG * 0.5 / at, on_hinge = kG - on_ball;
  BarOnBall s;
  make_bar_on_ball(&s, SolverKind::kExact, at);
  for (int i = 0; i < 60; ++i)
    ASSERT_TRUE(s.world.step(kDt));
  // One island, solved exactly: the contact and the hinge together.
  EXPECT_EQ(s.world.last_step().exact_islands, 1u);
  EXPECT_EQ(s.world.last_step().joint_tree_islands, 1u);
  EXPECT_EQ(s.world.last_step().exact_fallbacks, 0u);
  EXPECT_NEAR(contact_force(s.world), on_ball, 1e-6 * on_ball);
  const JointReading r = s.world.joint_reading(s.hinge).value();
  EXPECT_NEAR(r.force.norm(), on_hinge, 1e-6 * on_hinge);
  // The LCP's compliance (1e-6 of each row's own stiffness) leaves a millionth of the velocity
  // the contact's impulse gives (0.07 m/s a substep).
  EXPECT_LT(std::abs(r.speed), 1e-6);
}

TEST(ExactJoints, AThousandKilogramBoxOnTheBarIsHeldAsItsMomentsSay) {
  // The same bar with a 1000 kg, 0.2 m box resting on its middle: the ball carries
  // g (0.5 m + 1000 kg 0.5 m) / 0.9 m, the hinge the rest, and the box does not sink into the
  // bar. (Measured with auto, whose contacts are soft beside the tree: the box sinks 14 mm into
  // the bar and the hinge carries 1951 N of its 4364.)
  const double at = 0.9;
  const double on_ball = kG * (0.5 + 1000 * 0.5) / at, on_hinge = kG * 1001 - on_ball;
  BarOnBall s;
  make_bar_on_ball(&s, SolverKind::kExact, at);
  BodyDef box;
  box.shape = BoxDef{Vec3(0.1, 0.1, 0.1)};
  box.mass = 1000;
  box.friction = 0;
  box.position = Vec3(0.5, 0, 5.15);
  const BodyId heavy = s.world.create_body(box).value();
  double deepest = 0;
  for (int i = 0; i < 120; ++i) {
    ASSERT_TRUE(s.world.step(kDt));
    for (const Contact& contact : s.world.contacts())
      deepest = std::max(deepest, contact.manifold.depth);
  }
  EXPECT_EQ(s.world.last_step().exact_islands, 1u);
  EXPECT_EQ(s.world.last_step().exact_fallbacks, 0u);
  EXPECT_LT(deepest, 1e-6);
  EXPECT_NEAR(s.world.body(heavy)->position().z(), 5.15, 1e-6);
  const JointReading r = s.world.joint_reading(s.hinge).value();
  EXPECT_NEAR(r.force.norm(), on_hinge, 1e-6 * on_hinge);
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

}  // namespace
}  // namespace tumble
