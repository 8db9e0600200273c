// Changing bodies between steps: poses and velocities set by hand, impulses applied; bad values
// refused with nothing changed; sleepers woken.
#include <gtest/gtest.h>

#include <limits>

#include "scene_runner.h"

namespace tumble::testing {
namespace {

// A body is read through its id: the view shows what the world holds now (after a step, a move),
// and a removed body's id gives a view that says so instead of a neighbour's data.
TEST(BodyView, ShowsTheBodyAsItIsNowAndNothingForAStaleId) {
  World world = build(tower_scene(1));
  const BodyId box = world.id_at(1);
  const BodyView view = world.body(box);
  ASSERT_TRUE(view);
  EXPECT_EQ(view.type(), BodyType::kDynamic);
  EXPECT_EQ(view.mass(), 1.0);
  EXPECT_EQ(view.shape().half_extents(), Vec3::Constant(0.5));
  const double z = view.position().z();
  BodyMotion motion;
  motion.position = Vec3(3, 0, z + 1);
  ASSERT_TRUE(world.set_motion(box, motion));
  EXPECT_EQ(view.position(), Vec3(3, 0, z + 1));
  EXPECT_EQ(view.pose().position, view.position());
  run(world, 1.0 / 60, 1);
  EXPECT_NEAR(view.linear_velocity().z(), -9.81 / 60, 1e-12);  // lifted off the ground: falls
  EXPECT_LT(view.position().z(), z + 1);

  ASSERT_TRUE(world.remove_body(box));
  EXPECT_FALSE(world.body(box));
  const BodyId next = world.create_body(BodyDef{}).value();
  EXPECT_EQ(next.index, box.index);  // the slot is reused under a new generation
  EXPECT_FALSE(world.body(box));
  EXPECT_TRUE(world.body(next));
  EXPECT_FALSE(world.body(BodyId{}));
}

TEST(BodyMotion, SetsWhatIsGivenAndRefusesTheRest) {
  World world = build(tower_scene(1));
  const BodyId box = world.id_at(1);
  BodyMotion motion;
  motion.position = Vec3(1, 2, 3);
  motion.angular_velocity = Vec3(0, 0, 4);
  ASSERT_TRUE(world.set_motion(box, motion));
  EXPECT_EQ(world.body(box)->position(), Vec3(1, 2, 3));
  EXPECT_EQ(world.body(box)->angular_velocity(), Vec3(0, 0, 4));
  EXPECT_EQ(world.body(box)->linear_velocity(), Vec3::Zero());  // not given: unchanged

  BodyMotion bad;
  bad.position = Vec3(5, 5, 5);
  bad.orientation = Quat(2, 0, 0, 0);
  const Status refused = world.set_motion(box, bad);
  EXPECT_FALSE(refused);
  EXPECT_EQ(refused.message().rfind("orientation:", 0), 0u);
  EXPECT_EQ(world.body(box)->position(), Vec3(1, 2, 3));  // nothing applied

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
  const BodyView body = world.body(box);
  const Vec3 v_before = body.linear_velocity(), w_before = body.angular_velocity();
  const Vec3 impulse(0, 2, 0), point = body.position() + Vec3(0.5, 0, 0);
  ASSERT_TRUE(world.apply_impulse(box, impulse, &point));
  EXPECT_TRUE((body.linear_velocity() - v_before).isApprox(impulse / body.mass()));
  const Vec3 expected = body.inverse_inertia_world() * Vec3(0.5, 0, 0).cross(impulse);
  EXPECT_TRUE((body.angular_velocity() - w_before).isApprox(expected, 1e-12));
  EXPECT_FALSE(world.apply_impulse(box, Vec3(INFINITY, 0, 0), nullptr));
}

TEST(BodyMotion, SleepersWakeWhenPushedOrWhenTheirSupportMoves) {
  World world = build(tower_scene(2));
  run(world, 1.0 / 60, 120);
  ASSERT_TRUE(world.body(world.id_at(2))->asleep());
  ASSERT_TRUE(world.apply_impulse(world.id_at(2), Vec3(0.1, 0, 0), nullptr));
  EXPECT_FALSE(world.body(world.id_at(2))->asleep());
  EXPECT_FALSE(world.body(world.id_at(1))->asleep());  // its island woke with it

  run(world, 1.0 / 60, 240);
  ASSERT_TRUE(world.body(world.id_at(1))->asleep());
  BodyMotion lower;
  lower.position = Vec3(0, 0, -1);  // the ground drops by a metre
  ASSERT_TRUE(world.set_motion(world.id_at(0), lower));
  EXPECT_FALSE(world.body(world.id_at(1))->asleep());
  const double z = world.body(world.id_at(1))->position().z();
  run(world, 1.0 / 60, 120);
  EXPECT_NEAR(world.body(world.id_at(1))->position().z(), z - 1, 0.02);  // fell onto it
}

}  // namespace
}  // namespace tumble::testing
