// Changing bodies between steps: poses and velocities set by hand, impulses applied; bad values
// refused with nothing changed; sleepers woken.
#include <gtest/gtest.h>

#include <limits>

#include "scene_runner.h"

namespace tumble::testing {
namespace {

TEST(BodyMotion, SetsWhatIsGivenAndRefusesTheRest) {
  World world = build(tower_scene(1));
  const BodyId box = world.id_at(1);
  BodyMotion motion;
  motion.position = Vec3(1, 2, 3);
  motion.angular_velocity = Vec3(0, 0, 4);
  ASSERT_TRUE(world.set_motion(box, motion));
  EXPECT_EQ(world.body(box)->position, Vec3(1, 2, 3));
  EXPECT_EQ(world.body(box)->angular_velocity, Vec3(0, 0, 4));
  EXPECT_EQ(world.body(box)->linear_velocity, Vec3::Zero());  // not given: unchanged

  BodyMotion bad;
  bad.position = Vec3(5, 5, 5);
  bad.orientation = Quat(2, 0, 0, 0);
  const Status refused = world.set_motion(box, bad);
  EXPECT_FALSE(refused);
  EXPECT_EQ(refused.message().rfind("orientation:", 0), 0u);
  EXPECT_EQ(world.body(box)->position, Vec3(1, 2, 3));  // nothing applied

  bad = {};
  bad.linear_velocity = Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0);
  EXPECT_FALSE(world.set_motion(box, bad));
  BodyMotion moving_ground;
  moving_ground.linear_velocity = Vec3(1, 0, 0);
  EXPECT_FALSE(world.set_motion(world.id_at(0), moving_ground));
  EXPECT_FALSE(world.set_motion(BodyId{99, 0}, motion));
}

TEST(BodyMotion, ImpulseAtAPointChangesBothVelocities) {
  SceneDef scene = spin_scene();  // no gravity, one 1 x 2 x 3 box
  World world = build(scene);
  const BodyId box = world.id_at(0);
  const Body before = *world.body(box);
  const Vec3 impulse(0, 2, 0), point = before.position + Vec3(0.5, 0, 0);
  ASSERT_TRUE(world.apply_impulse(box, impulse, &point));
  const Body& after = *world.body(box);
  EXPECT_TRUE((after.linear_velocity - before.linear_velocity).isApprox(impulse / before.mass));
  const Vec3 expected = before.inverse_inertia_world * Vec3(0.5, 0, 0).cross(impulse);
  EXPECT_TRUE((after.angular_velocity - before.angular_velocity).isApprox(expected, 1e-12));
  EXPECT_FALSE(world.apply_impulse(box, Vec3(INFINITY, 0, 0), nullptr));
}

TEST(BodyMotion, SleepersWakeWhenPushedOrWhenTheirSupportMoves) {
  World world = build(tower_scene(2));
  run(world, 1.0 / 60, 120);
  ASSERT_TRUE(world.body(world.id_at(2))->asleep);
  ASSERT_TRUE(world.apply_impulse(world.id_at(2), Vec3(0.1, 0, 0), nullptr));
  EXPECT_FALSE(world.body(world.id_at(2))->asleep);
  EXPECT_FALSE(world.body(world.id_at(1))->asleep);  // its island woke with it

  run(world, 1.0 / 60, 240);
  ASSERT_TRUE(world.body(world.id_at(1))->asleep);
  BodyMotion lower;
  lower.position = Vec3(0, 0, -1);  // the ground drops by a metre
  ASSERT_TRUE(world.set_motion(world.id_at(0), lower));
  EXPECT_FALSE(world.body(world.id_at(1))->asleep);
  const double z = world.body(world.id_at(1))->position.z();
  run(world, 1.0 / 60, 120);
  EXPECT_NEAR(world.body(world.id_at(1))->position.z(), z - 1, 0.02);  // fell onto it
}

}  // namespace
}  // namespace tumble::testing
