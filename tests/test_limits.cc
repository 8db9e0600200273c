// The world's limits (physics/limits.h): every value beyond them is refused before anything
// changes, with a message naming the field and the limit, and the step holds every body within
// them. Issue 17, defects 1 and 2: a spin of 1e308 rad/s was accepted and turned into NaN.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "physics/world.h"
#include "scene_runner.h"
#include "state_format.h"
#include "step_limits.h"

namespace tumble {
namespace {

using testing::all_finite;
using testing::state_hash;

BodyDef unit_box(const Vec3& position) {
  BodyDef def;
  def.shape = BoxDef{Vec3::Constant(0.5)};
  def.position = position;
  return def;
}

World world_with_a_box_on_the_ground() {
  World world;
  BodyDef ground;
  ground.shape = HalfSpaceDef{};
  ground.type = BodyType::kStatic;
  EXPECT_TRUE(world.create_body(ground).ok());
  EXPECT_TRUE(world.create_body(unit_box(Vec3(0, 0, 0.5))).ok());
  EXPECT_TRUE(world.step(1.0 / 60).is_ok());
  return world;
}

// What a refusal must leave alone: the bodies, their states, the step count.
struct Fingerprint {
  std::size_t bodies;
  std::uint32_t slots;
  std::uint64_t hash, step;
  explicit Fingerprint(const World& w)
      : bodies(w.body_count()), slots(w.slot_count()), hash(state_hash(w)), step(w.step_count()) {}
  bool operator==(const Fingerprint&) const = default;
};

void expect_refused(const Status& status, const std::string& field, const std::string& limit) {
  EXPECT_FALSE(status.is_ok());
  EXPECT_NE(status.message().find(field), std::string::npos) << status.message();
  EXPECT_NE(status.message().find(limit), std::string::npos) << status.message();
}

TEST(Limits, TheSpinThatTurnedIntoNaNIsRefusedAndChangesNothing) {
  World world = world_with_a_box_on_the_ground();
  const Fingerprint before(world);
  BodyDef spinning = unit_box(Vec3(0, 0, 5));
  spinning.angular_velocity = Vec3(1e308, 0, 0);
  expect_refused(world.create_body(spinning).status(), "angular_velocity: 1e+308 rad/s",
                 "max_angular_speed");
  EXPECT_EQ(Fingerprint(world), before);

  const BodyId box = world.id_at(1);
  BodyMotion spin;
  spin.angular_velocity = Vec3(1e308, 0, 0);
  expect_refused(world.set_motion(box, spin), "angular_velocity", "max_angular_speed");
  const Vec3 impulse(1e300, 0, 0);
  expect_refused(world.apply_impulse(box, impulse, nullptr), "impulse", "max_linear_speed");
  EXPECT_EQ(Fingerprint(world), before);
  ASSERT_TRUE(world.step(1.0 / 60).is_ok());
  EXPECT_TRUE(all_finite(world));
}

TEST(Limits, EveryBodyLimitNamesItsFieldAndNothingOfTheBatchIsMade) {
  struct Case {
    const char* what;
    BodyDef def;
    const char* field;
    const char* limit;
  };
  auto with = [](auto change) {
    BodyDef def = unit_box(Vec3(0, 0, 3));
    change(def);
    return def;
  };
  const Case cases[] = {
      {"far", with([](BodyDef& d) { d.position = Vec3(0, 0, -2e9); }), "position[2]",
       "max_coordinate"},
      {"huge sphere", with([](BodyDef& d) { d.shape = SphereDef{1e18}; }), "shape.radius",
       "max_size"},
      {"huge capsule", with([](BodyDef& d) {
         d.shape = CapsuleDef{1, 1e6};
       }),
       "shape.half_height", "max_size"},
      {"thin box", with([](BodyDef& d) { d.shape = BoxDef{Vec3(1, 1, 1e-7)}; }),
       "shape.half_extents", "min_size"},
      {"tiny hull", with([](BodyDef& d) {
         d.shape = HullDef{{Vec3(0, 0, 0), Vec3(1e-6, 0, 0), Vec3(0, 1e-6, 0), Vec3(0, 0, 1e-6)}};
       }),
       "shape.points", "min_size"},
      {"light", with([](BodyDef& d) { d.mass = 1e-20; }), "mass", "min_mass"},
      {"heavy", with([](BodyDef& d) { d.mass = 1e20; }), "mass", "max_mass"},
      {"dense", with([](BodyDef& d) { d.density = 1e25; }), "mass", "max_mass"},
      {"fast", with([](BodyDef& d) { d.linear_velocity = Vec3(0, 2e5, 0); }), "linear_velocity",
       "max_linear_speed"},
      {"spinning", with([](BodyDef& d) { d.angular_velocity = Vec3(0, 0, 2e6); }),
       "angular_velocity", "max_angular_speed"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    World world = world_with_a_box_on_the_ground();
    const Fingerprint before(world);
    const BodyDef batch[] = {unit_box(Vec3(3, 0, 0.5)), c.def};
    const Status status = world.create_bodies(batch).status();
    expect_refused(status, std::string("bodies[1].") + c.field, c.limit);
    EXPECT_EQ(Fingerprint(world), before);
  }
}

TEST(Limits, MovesBeyondTheLimitsAreRefused) {
  World world = world_with_a_box_on_the_ground();
  const Fingerprint before(world);
  BodyMotion far;
  far.position = Vec3(1e10, 0, 0);
  expect_refused(world.check_motion(world.id_at(1), far), "position[0]", "max_coordinate");
  expect_refused(world.set_motion(world.id_at(0), far), "position[0]", "max_coordinate");
  BodyMotion fast;
  fast.linear_velocity = Vec3(0, 0, -1e6);
  expect_refused(world.set_motion(world.id_at(1), fast), "linear_velocity", "max_linear_speed");
  EXPECT_EQ(Fingerprint(world), before);
}

TEST(Limits, NarrowerLimitsAreRefusedWhileABodyIsBeyondThem) {
  World world = world_with_a_box_on_the_ground();
  WorldSettings narrower = world.settings();
  narrower.limits.max_size = 0.1;
  expect_refused(world.set_settings(narrower), "slot 1", "max_size");
  EXPECT_EQ(world.settings().limits.max_size, WorldLimits{}.max_size);
  narrower.limits.max_size = 10;
  EXPECT_TRUE(world.set_settings(narrower).is_ok());
  EXPECT_EQ(world.settings().limits.max_size, 10);
}

TEST(Limits, TheLimitsThemselvesAreChecked) {
  WorldSettings settings;
  settings.limits.min_size = settings.limits.max_size * 2;
  expect_refused(validate(settings), "limits.max_size", ">= min_size");
  settings = {};
  settings.limits.max_linear_speed = std::numeric_limits<double>::quiet_NaN();
  expect_refused(validate(settings), "limits.max_linear_speed", "finite");
  settings = {};
  settings.gravity = Vec3(0, 0, -1e6);  // one step of it alone is faster than the speed limit
  expect_refused(validate(settings), "gravity", "max_linear_speed");
  World world = world_with_a_box_on_the_ground();
  const Fingerprint before(world);
  expect_refused(world.step(2), "dt", "max_time_step");
  EXPECT_EQ(Fingerprint(world), before);
}

TEST(Limits, TheStepHoldsBodiesAtTheSpeedLimitAndTheEdgeOfTheWorld) {
  WorldSettings settings;
  settings.limits.max_linear_speed = 5;
  settings.limits.max_time_step = 0.1;
  settings.limits.max_coordinate = 20;
  World world(settings);
  ASSERT_TRUE(world.create_body(unit_box(Vec3(0, 0, 0))).ok());
  std::uint32_t slowed = 0, at_edge = 0;
  for (int step = 0; step < 400; ++step) {
    ASSERT_TRUE(world.step(1.0 / 60).is_ok());
    const BodyView body = world.body(world.id_at(0));
    ASSERT_LE(body.linear_velocity().norm(), 5 + 1e-12);
    ASSERT_GE(body.position().z(), -20);
    slowed += world.last_step().slowed_bodies;
    at_edge += world.last_step().bodies_at_edge;
  }
  EXPECT_GT(slowed, 100u);  // from about 0.5 s on, gravity would take it past 5 m/s
  // It reaches -20 m after about 4.3 s, is held there until it falls asleep (0.5 s at rest).
  EXPECT_GE(at_edge, 25u);
  EXPECT_EQ(world.body(world.id_at(0))->position().z(), -20);
}

TEST(Limits, AStepResultThatIsNotFiniteKeepsThePoseFromBeforeAtRest) {
  Body body = make_body(unit_box(Vec3(1, 2, 3))).value();
  body.linear_velocity = Vec3(1, 0, 0);
  const Pose next{Vec3(1.1, 2, 3), Quat::Identity()};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(take_step_result(&body, next, Vec3(nan, 0, 0), Vec3::Zero(), WorldLimits{}),
            kStepNonFinite);
  EXPECT_EQ(body.position, Vec3(1, 2, 3));
  EXPECT_TRUE(body.linear_velocity.isZero(0));
  EXPECT_TRUE(body.angular_velocity.isZero(0));
  const Pose inf_pose{Vec3(std::numeric_limits<double>::infinity(), 0, 0), Quat::Identity()};
  EXPECT_EQ(take_step_result(&body, inf_pose, Vec3::Zero(), Vec3::Zero(), WorldLimits{}),
            kStepNonFinite);
  EXPECT_EQ(body.position, Vec3(1, 2, 3));
  EXPECT_EQ(take_step_result(&body, next, Vec3(1, 0, 0), Vec3(0, 0, 2e6), WorldLimits{}),
            kStepSlowed);
  EXPECT_NEAR(body.angular_velocity.z(), WorldLimits{}.max_angular_speed, 1e-6);
  EXPECT_EQ(body.position, next.position);
}

TEST(Limits, ARestoredStateIsCheckedAgainstTheLimitsAndForConsistency) {
  World world = world_with_a_box_on_the_ground();
  struct Case {
    const char* what;
    void (*tamper)(Body&);
    const char* field;
  };
  const Case cases[] = {
      {"fast", [](Body& b) { b.linear_velocity = Vec3(1e200, 0, 0); }, "linear_velocity"},
      {"far", [](Body& b) { b.position = Vec3(0, 0, 1e12); }, "position[2]"},
      {"inverse mass", [](Body& b) { b.inverse_mass = 1e12; }, "inverse_mass"},
      {"inverse inertia", [](Body& b) { b.inverse_inertia_body *= 1e6; }, "inverse_inertia_body"},
      {"negative inertia",
       [](Body& b) {
         b.inertia_body = -b.inertia_body;
         b.inverse_inertia_body = b.inertia_body.inverse();
       },
       "inertia_body"},
      {"world inertia", [](Body& b) { b.inverse_inertia_world *= 2; }, "inverse_inertia_world"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    WorldStateData state = decode_state(world.save_state()).value();
    c.tamper(state.slots[1].body);
    Result<World> restored = World::from_state(world.settings(), encode_state(state));
    ASSERT_FALSE(restored.ok());
    EXPECT_NE(restored.error().find(std::string("slots[1].") + c.field), std::string::npos)
        << restored.error();
  }
  EXPECT_TRUE(World::from_state(world.settings(), world.save_state()).ok());
}

TEST(Limits, SceneFilesSetThemAndAreCheckedAgainstThem) {
  Result<SceneDef> scene = parse_scene(R"({"limits": {"max_size": 2, "max_linear_speed": 50},
      "bodies": [{"shape": "sphere", "radius": 1}]})");
  ASSERT_TRUE(scene.ok()) << scene.error();
  EXPECT_EQ(scene.value().world.limits.max_size, 2);
  EXPECT_EQ(scene.value().world.limits.max_linear_speed, 50);
  Result<SceneDef> again = parse_scene(scene_to_json(scene.value()));
  ASSERT_TRUE(again.ok()) << again.error();
  EXPECT_EQ(again.value().world.limits.max_size, 2);

  Result<SceneDef> unknown = parse_scene(R"({"limits": {"max_sise": 2}})");
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().find("limits.max_sise: unknown field"), std::string::npos);
  Result<SceneDef> slow_steps = parse_scene(R"({"dt": 2})");
  ASSERT_FALSE(slow_steps.ok());
  EXPECT_NE(slow_steps.error().find("max_time_step"), std::string::npos);
  Result<SceneDef> big = parse_scene(R"({"limits": {"max_size": 2},
      "bodies": [{"shape": "sphere", "radius": 3}]})");
  ASSERT_FALSE(big.ok());
  EXPECT_NE(big.error().find("bodies[0].shape.radius"), std::string::npos) << big.error();
}

}  // namespace
}  // namespace tumble
