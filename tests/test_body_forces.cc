// What acts on a body beyond gravity and contacts (held forces and torques, gravity scale,
// damping) against closed forms, and collision filters: filtered pairs never touch, a filter
// changed while running takes effect and wakes what it concerns. Refusals name the field;
// snapshots and scene files keep every field.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>

#include "physics/world.h"
#include "scenes/scene.h"

namespace tumble {
namespace {

constexpr double kDt = 1.0 / 60;
constexpr double kG = 9.81;

WorldSettings plain_settings() {
  WorldSettings settings;
  settings.solver.sleeping = false;
  return settings;
}

BodyDef sphere_at(const Vec3& position, double mass = 2) {
  BodyDef def;
  def.shape = SphereDef{0.5};
  def.mass = mass;
  def.position = position;
  return def;
}

BodyId add_ground(World* world) {
  BodyDef ground;
  ground.shape = HalfSpaceDef{};
  ground.type = BodyType::kStatic;
  return world->create_body(ground).value();
}

// A 1 m cube resting on the ground (z = 0.5).
BodyDef cube_on_ground() {
  BodyDef box;
  box.shape = BoxDef{Vec3(0.5, 0.5, 0.5)};
  box.position = Vec3(0, 0, 0.5);
  return box;
}

// Steps of kDt until t seconds have passed.
void run(World* world, double seconds) {
  const int steps = static_cast<int>(std::lround(seconds / kDt));
  for (int i = 0; i < steps; ++i)
    ASSERT_TRUE(world->step(kDt).is_ok());
}

TEST(BodyForces, HeldForceAcceleratesAsNewtonSays) {
  World world(plain_settings());
  BodyDef def = sphere_at(Vec3(0, 0, 10));
  def.gravity_scale = 0;
  def.force = Vec3(3, 0, 0);  // 1.5 m/s^2 on 2 kg
  const BodyId id = world.create_body(def).value();
  run(&world, 2.0);
  const double a = 1.5, t = 2.0;
  EXPECT_NEAR(world.body(id)->linear_velocity().x(), a * t, 1e-9);
  // Semi-implicit Euler over steps of h <= kDt (a body alone takes the step whole): x = a t^2/2
  // + a h t/2.
  const double x = world.body(id)->position().x();
  EXPECT_GE(x, a * t * t / 2);
  EXPECT_LE(x, a * t * t / 2 + a * kDt * t / 2 + 1e-12);
  EXPECT_NEAR(world.body(id)->position().z(), 10, 1e-12);  // no gravity
}

TEST(BodyForces, GravityScaleScalesTheFall) {
  World world(plain_settings());
  BodyId ids[3];
  const double scales[3] = {0, 0.5, -1};
  for (int k = 0; k < 3; ++k) {
    BodyDef def = sphere_at(Vec3(3.0 * k, 0, 10));
    def.gravity_scale = scales[k];
    ids[k] = world.create_body(def).value();
  }
  run(&world, 1.0);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(world.body(ids[k])->linear_velocity().z(), -scales[k] * kG * 1.0, 1e-9) << k;
}

TEST(BodyForces, DampingDecaysAsTheExponentialAndNeverReverses) {
  World world(plain_settings());
  BodyDef def = sphere_at(Vec3(0, 0, 10));
  def.gravity_scale = 0;
  def.linear_velocity = Vec3(4, 0, 0);
  def.angular_velocity = Vec3(0, 0, 6);
  def.linear_damping = 0.5;
  def.angular_damping = 2;
  const BodyId id = world.create_body(def).value();
  BodyDef stiff = sphere_at(Vec3(0, -50, 10));
  stiff.gravity_scale = 0;
  stiff.linear_velocity = Vec3(0, 4, 0);
  stiff.linear_damping = kMaxDamping;
  const BodyId stiff_id = world.create_body(stiff).value();
  const double t = 3.0;
  run(&world, t);
  // Implicit Euler of dv/dt = -c v over n steps of h (a body alone takes the step whole):
  // v0 (1 + c h)^-n exactly; against e^-ct its relative error is about c^2 h t / 2.
  const double h = kDt;
  const int n = static_cast<int>(std::lround(t / h));
  const double v = world.body(id)->linear_velocity().x();
  const double w = world.body(id)->angular_velocity().z();
  EXPECT_NEAR(v, 4 * std::pow(1 + 0.5 * h, -n), 1e-12);
  EXPECT_NEAR(w, 6 * std::pow(1 + 2 * h, -n), 1e-12);
  EXPECT_NEAR(v, 4 * std::exp(-0.5 * t), 4 * std::exp(-0.5 * t) * 0.5 * 0.5 * h * t);
  EXPECT_NEAR(w, 6 * std::exp(-2 * t), 6 * std::exp(-2 * t) * 2 * 2 * h * t);
  // A million per second stops the body at once, without turning it back.
  const double stopped = world.body(stiff_id)->linear_velocity().y();
  EXPECT_GE(stopped, 0);
  EXPECT_LT(stopped, 1e-12);
}

TEST(BodyForces, TorqueAndAForceAtAPoint) {
  World world(plain_settings());
  BodyDef def = sphere_at(Vec3(0, 0, 10));
  def.gravity_scale = 0;
  def.torque = Vec3(0, 0, 0.2);
  const BodyId spun = world.create_body(def).value();
  const BodyId pushed = world.create_body(sphere_at(Vec3(5, 0, 10))).value();
  // 1 N along y at 0.5 m along x from the centre: a torque of 0.5 N m about z.
  BodyMotion motion;
  motion.force = Vec3(0, 1, 0);
  motion.force_point = Vec3(5.5, 0, 10);
  motion.gravity_scale = 0;
  ASSERT_TRUE(world.set_motion(pushed, motion).is_ok());
  EXPECT_NEAR(world.body(pushed)->torque().z(), 0.5, 1e-15);
  run(&world, 1.0);
  // A sphere's inertia 2/5 m r^2 = 0.2 kg m^2.
  EXPECT_NEAR(world.body(spun)->angular_velocity().z(), 0.2 / 0.2 * 1.0, 1e-9);
  EXPECT_NEAR(world.body(pushed)->angular_velocity().z(), 0.5 / 0.2 * 1.0, 1e-9);
  EXPECT_NEAR(world.body(pushed)->linear_velocity().y(), 1.0 / 2 * 1.0, 1e-9);
  // A torque given with the point is added to the force's moment; a force alone keeps the torque.
  motion.torque = Vec3(0.1, 0, 0);
  ASSERT_TRUE(world.set_motion(pushed, motion).is_ok());
  EXPECT_NEAR(world.body(pushed)->torque().x(), 0.1, 1e-15);
  EXPECT_NEAR(world.body(pushed)->torque().z(), 0.5 - world.body(pushed)->position().x() + 5,
              1e-12);
  BodyMotion force_only;
  force_only.force = Vec3(0, 2, 0);
  const Vec3 torque_before = world.body(pushed)->torque();
  ASSERT_TRUE(world.set_motion(pushed, force_only).is_ok());
  EXPECT_EQ(world.body(pushed)->torque(), torque_before);
}

TEST(BodyForces, AHeldForceWakesASleeperAndKeepsItMoving) {
  World world{WorldSettings{}};  // sleeping on
  add_ground(&world);
  const BodyId id = world.create_body(cube_on_ground()).value();
  run(&world, 3.0);
  ASSERT_TRUE(world.body(id)->asleep());
  BodyMotion motion;
  motion.force = Vec3(0, 0, 2 * 1000 * kG);  // twice its weight: it rises
  ASSERT_TRUE(world.set_motion(id, motion).is_ok());
  EXPECT_FALSE(world.body(id)->asleep());
  run(&world, 1.0);
  EXPECT_NEAR(world.body(id)->linear_velocity().z(), kG * 1.0, 1e-6);
}

TEST(BodyForces, RefusalsNameTheField) {
  World world(plain_settings());
  const BodyId id = world.create_body(sphere_at(Vec3(0, 0, 10))).value();
  auto refused = [&](BodyDef def, const std::string& field) {
    Result<BodyId> made = world.create_body(def);
    ASSERT_FALSE(made.ok()) << field;
    EXPECT_EQ(made.error().rfind(field + ":", 0), 0u) << made.error();
  };
  BodyDef def = sphere_at(Vec3(0, 0, 0));
  def.gravity_scale = 1e4;
  refused(def, "gravity_scale");
  def = sphere_at(Vec3(0, 0, 0));
  def.gravity_scale = NAN;
  refused(def, "gravity_scale");
  def = sphere_at(Vec3(0, 0, 0));
  def.linear_damping = -1;
  refused(def, "linear_damping");
  def = sphere_at(Vec3(0, 0, 0));
  def.angular_damping = 2e6;
  refused(def, "angular_damping");
  def = sphere_at(Vec3(0, 0, 0));
  def.force = Vec3(0, NAN, 0);
  refused(def, "force[1]");
  def = sphere_at(Vec3(0, 0, 0));
  def.force = Vec3(1e20, 0, 0);  // 5e19 m/s^2 on 2 kg
  refused(def, "force");
  def = sphere_at(Vec3(0, 0, 0));
  def.torque = Vec3(0, 0, 1e20);
  refused(def, "torque");
  def.torque = Vec3::Zero();
  def.type = BodyType::kStatic;
  def.force = Vec3(1, 0, 0);
  refused(def, "force");

  auto refused_motion = [&](const BodyMotion& motion, const std::string& field) {
    const Status s = world.set_motion(id, motion);
    ASSERT_FALSE(s.is_ok()) << field;
    EXPECT_EQ(s.message().rfind(field + ":", 0), 0u) << s.message();
  };
  BodyMotion motion;
  motion.force_point = Vec3(0, 0, 0);
  refused_motion(motion, "force_point");
  motion = {};
  motion.force = Vec3(1e20, 0, 0);
  refused_motion(motion, "force");
  motion = {};
  motion.torque = Vec3(INFINITY, 0, 0);
  refused_motion(motion, "torque");
  motion = {};
  motion.linear_damping = -0.1;
  refused_motion(motion, "linear_damping");
  motion = {};
  motion.gravity_scale = -2000;
  refused_motion(motion, "gravity_scale");
  // Nothing changed.
  EXPECT_EQ(world.body(id)->force(), Vec3::Zero());
  EXPECT_EQ(world.body(id)->gravity_scale(), 1);
  EXPECT_EQ(world.body(id)->linear_damping(), 0);
}

// Two boxes dropped one onto the other, and onto the ground, with and without filters.
struct Drop {
  World world{plain_settings()};
  BodyId ground, lower, upper;
};

void make_drop(Drop* d, const CollisionFilter& lower, const CollisionFilter& upper) {
  d->ground = add_ground(&d->world);
  BodyDef box = cube_on_ground();
  box.filter = lower;
  d->lower = d->world.create_body(box).value();
  box.position = Vec3(0, 0, 2);
  box.filter = upper;
  d->upper = d->world.create_body(box).value();
}

TEST(CollisionFilters, FilteredPairsNeverTouch) {
  // Both boxes in layer 2, meeting layer 2 alone (the ground is in layer 1): they meet each other
  // and not the ground.
  Drop d;
  make_drop(&d, CollisionFilter{2, 2}, CollisionFilter{2, 2});
  BodyMotion thrown;
  thrown.linear_velocity = Vec3(0, 0, -5);  // it catches up with the lower one in 0.1 s
  ASSERT_TRUE(d.world.set_motion(d.upper, thrown).is_ok());
  run(&d.world, 0.5);
  for (const Contact& c : d.world.contacts()) {
    const bool with_ground = c.a == d.ground || c.b == d.ground;
    EXPECT_FALSE(with_ground && (c.a == d.upper || c.b == d.upper));
  }
  // Both fall past the ground together, the upper resting on the lower.
  EXPECT_LT(d.world.body(d.lower)->position().z(), 0.5 - 0.5 * kG * 0.25 + 0.05);
  EXPECT_NEAR(d.world.body(d.upper)->position().z() - d.world.body(d.lower)->position().z(), 1.0,
              0.02);

  // Disjoint masks: the two pass through each other; the lower one still stands on the ground.
  Drop apart;
  make_drop(&apart, CollisionFilter{1, 1}, CollisionFilter{2, 2});
  run(&apart.world, 1.0);
  EXPECT_NEAR(apart.world.body(apart.lower)->position().z(), 0.5, 0.01);
  EXPECT_LT(apart.world.body(apart.upper)->position().z(), -1);  // through both
  for (const Contact& c : apart.world.contacts())
    EXPECT_TRUE(c.a != apart.upper && c.b != apart.upper);
}

TEST(CollisionFilters, AFilterChangedWhileRunningWakesAndTakesEffect) {
  World world{WorldSettings{}};  // sleeping on
  add_ground(&world);
  BodyDef box = cube_on_ground();
  box.filter.layers = 2;  // meets everything, as everything's mask is every layer
  const BodyId lower = world.create_body(box).value();
  box.position = Vec3(0, 0, 1.5);
  box.filter = CollisionFilter{};
  const BodyId upper = world.create_body(box).value();
  run(&world, 3.0);
  ASSERT_TRUE(world.body(upper)->asleep());
  // The upper box stops meeting layer 2: it wakes and falls through the lower one to the ground.
  BodyMotion upper_motion;
  upper_motion.filter = CollisionFilter{1, ~std::uint32_t{2}};
  ASSERT_TRUE(world.set_motion(upper, upper_motion).is_ok());
  EXPECT_FALSE(world.body(upper)->asleep());
  EXPECT_FALSE(world.body(lower)->asleep());  // it touches the upper one: woken with it
  run(&world, 0.2);
  EXPECT_LT(world.body(upper)->position().z(), 1.5 - 0.05);
  run(&world, 2.0);
  EXPECT_NEAR(world.body(upper)->position().z(), 0.5, 0.02);  // on the ground, inside the lower
  EXPECT_NEAR(world.body(lower)->position().z(), 0.5, 0.02);
}

TEST(BodyForces, SnapshotsKeepEveryFieldAndPlainWorldsWriteTheOldBytes) {
  World world(plain_settings());
  const BodyId plain = world.create_body(sphere_at(Vec3(0, 0, 10))).value();
  constexpr std::size_t kFlagsOffset = 36;
  auto flags_of = [&](const std::string& bytes) {
    std::uint32_t flags = 0;
    std::memcpy(&flags, bytes.data() + kFlagsOffset, sizeof flags);
    return flags;
  };
  EXPECT_EQ(flags_of(world.save_state()) & 8u, 0u);
  BodyDef def = sphere_at(Vec3(3, 0, 10));
  def.gravity_scale = 0.25;
  def.linear_damping = 0.3;
  def.angular_damping = 0.7;
  def.force = Vec3(1, 2, 3);
  def.torque = Vec3(0.1, 0.2, 0.3);
  def.filter = CollisionFilter{6, 0xF0F0F0F0};
  const BodyId odd = world.create_body(def).value();
  run(&world, 0.5);
  const std::string bytes = world.save_state();
  EXPECT_NE(flags_of(bytes) & 8u, 0u);
  Result<World> restored = World::from_state(world.settings(), bytes);
  ASSERT_TRUE(restored.ok()) << restored.error();
  EXPECT_EQ(restored.value().save_state(), bytes);
  const BodyView b = restored.value().body(odd);
  EXPECT_EQ(b.gravity_scale(), 0.25);
  EXPECT_EQ(b.linear_damping(), 0.3);
  EXPECT_EQ(b.angular_damping(), 0.7);
  EXPECT_EQ(b.force(), Vec3(1, 2, 3));
  EXPECT_EQ(b.torque(), Vec3(0.1, 0.2, 0.3));
  EXPECT_EQ(b.filter(), (CollisionFilter{6, 0xF0F0F0F0}));
  EXPECT_EQ(restored.value().body(plain).filter(), CollisionFilter{});
  // Both step on to the same bits.
  run(&world, 0.5);
  run(&restored.value(), 0.5);
  EXPECT_EQ(restored.value().save_state(), world.save_state());
  // A crafted state with a damping out of range is refused naming it.
  std::string bad = bytes;
  const double negative = -1;
  const std::string needle(reinterpret_cast<const char*>(&def.linear_damping), sizeof(double));
  const std::size_t at = bad.find(needle);
  ASSERT_NE(at, std::string::npos);
  std::memcpy(bad.data() + at, &negative, sizeof negative);
  Result<World> refused = World::from_state(world.settings(), bad);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().find("damping"), std::string::npos) << refused.error();
}

TEST(BodyForces, SceneFilesReadAndWriteEveryField) {
  const char* text = R"({"bodies": [
    {"shape": "sphere", "radius": 0.5, "position": [0, 0, 3], "gravity_scale": 0.5,
     "linear_damping": 0.1, "angular_damping": 0.2, "force": [1, 0, 0], "torque": [0, 0, 1],
     "collision_layers": 2, "collision_mask": 4294967294}]})";
  Result<SceneDef> scene = parse_scene(text);
  ASSERT_TRUE(scene.ok()) << scene.error();
  const BodyDef& def = scene.value().bodies[0];
  EXPECT_EQ(def.gravity_scale, 0.5);
  EXPECT_EQ(def.linear_damping, 0.1);
  EXPECT_EQ(def.angular_damping, 0.2);
  EXPECT_EQ(def.force, Vec3(1, 0, 0));
  EXPECT_EQ(def.torque, Vec3(0, 0, 1));
  EXPECT_EQ(def.filter, (CollisionFilter{2, 4294967294u}));
  Result<SceneDef> again = parse_scene(scene_to_json(scene.value()));
  ASSERT_TRUE(again.ok()) << again.error();
  EXPECT_EQ(again.value().bodies[0].filter, def.filter);
  EXPECT_EQ(again.value().bodies[0].force, def.force);
  EXPECT_EQ(again.value().bodies[0].gravity_scale, def.gravity_scale);
  for (const auto& [field, value] :
       {std::pair{"collision_layers", "-1"}, {"collision_mask", "4294967296"},
        {"collision_layers", "1.5"}, {"gravity_scale", "5000"}, {"linear_damping", "-1"}}) {
    const std::string bad = std::string(R"({"bodies": [{"shape": "sphere", ")") + field +
                            "\": " + value + "}]}";
    Result<SceneDef> refused = parse_scene(bad);
    ASSERT_FALSE(refused.ok()) << bad;
    EXPECT_NE(refused.error().find(std::string("bodies[0].") + field), std::string::npos)
        << refused.error();
  }
}

}  // namespace
}  // namespace tumble
