// Kinematic bodies: moved by the velocity the user gives them, exactly (x0 + v t, the rotation
// exp(w t)), pushing dynamic bodies as if of infinite mass and never pushed back; what they carry
// stays on them and awake, what they meet wakes. Refusals name the field; snapshots keep them.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <tuple>
#include <vector>

#include "physics/world.h"
#include "scenes/scene.h"
#include "scenes/standard.h"

namespace tumble {
namespace {

constexpr double kDt = 1.0 / 60;

BodyId add_ground(World* world) {
  BodyDef ground;
  ground.shape = HalfSpaceDef{};
  ground.type = BodyType::kStatic;
  return world->create_body(ground).value();
}

BodyDef box(const Vec3& half_extents, const Vec3& position,
            BodyType type = BodyType::kDynamic) {
  BodyDef def;
  def.shape = BoxDef{half_extents};
  def.position = position;
  def.type = type;
  def.mass = type == BodyType::kDynamic ? 1 : 0;
  return def;
}

void run(World* world, int steps) {
  for (int i = 0; i < steps; ++i)
    ASSERT_TRUE(world->step(kDt).is_ok());
}

// A body's position in the frame of another (the platform's).
Vec3 seen_from(const World& world, BodyId frame, BodyId body) {
  const BodyView f = world.body(frame);
  return f.orientation().conjugate() * (world.body(body)->position() - f.position());
}

// A 1 kg ball of 0.1 m at `at`, hung by a ball joint at `pivot` from `crane`.
BodyId hang_ball(World* world, BodyId crane, const Vec3& pivot, const Vec3& at,
                 const Vec3& velocity = Vec3::Zero()) {
  BodyDef bob;
  bob.shape = SphereDef{0.1};
  bob.mass = 1;
  bob.position = at;
  bob.linear_velocity = velocity;
  const BodyId ball = world->create_body(bob).value();
  JointDef rod;
  rod.kind = JointKind::kBall;
  rod.a = ball;
  rod.b = crane;
  rod.anchor = pivot;
  EXPECT_TRUE(world->create_joint(rod).status().is_ok());
  return ball;
}

TEST(Kinematic, MovesExactlyByItsVelocityAndIsNeverPushedBack) {
  World world;
  add_ground(&world);
  BodyDef wall = box(Vec3(0.2, 1, 0.5), Vec3(-2, 0, 0.6), BodyType::kKinematic);
  wall.linear_velocity = Vec3(1, 0, 0);
  wall.angular_velocity = Vec3(0, 0, 0.3);
  const BodyId pusher = world.create_body(wall).value();
  BodyDef heavy = box(Vec3(0.5, 0.5, 0.5), Vec3(0, 0, 0.5));
  heavy.mass = 1000;
  const BodyId pushed = world.create_body(heavy).value();
  const int steps = 120;
  run(&world, steps);
  const double t = steps * kDt;
  const BodyView k = world.body(pusher);
  EXPECT_NEAR(k.position().x(), -2 + t, 1e-12);
  EXPECT_NEAR(k.position().y(), 0, 1e-12);
  EXPECT_NEAR(k.position().z(), 0.6, 1e-12);
  const Quat expected(Eigen::AngleAxisd(0.3 * t, Vec3::UnitZ()));
  EXPECT_LT(k.orientation().angularDistance(expected), 1e-9);
  EXPECT_EQ(k.linear_velocity(), Vec3(1, 0, 0));
  EXPECT_EQ(k.angular_velocity(), Vec3(0, 0, 0.3));
  // The tonne it met went ahead of it at its speed or more (it slides on after a push).
  const BodyView box_view = world.body(pushed);
  EXPECT_GT(box_view.position().x(), 0.2);
  EXPECT_GT(box_view.position().x() - k.position().x(), 0.5);
  EXPECT_GT(box_view.linear_velocity().x(), 0.5);
}

// The issue's goal: a platform carrying a stack of five boxes at 2 m/s around a circle of 4 m,
// turning with its heading as a vehicle does (the user steers it every step). It gathers speed
// over 2 s (1 m/s^2; a deck that jumps to 2 m/s slides out from under what stands on it, as it
// should), then goes once around; the stack stays on it, standing.
TEST(Kinematic, TurningPlatformCarriesAStackOfFive) {
  World world;
  add_ground(&world);
  const double top_speed = 2, radius = 4;  // m/s, m: 1 m/s^2 towards the centre
  BodyDef deck = box(Vec3(1.5, 1.5, 0.1), Vec3(0, 0, 0.3), BodyType::kKinematic);
  const BodyId platform = world.create_body(deck).value();
  std::vector<BodyId> stack;
  for (int k = 0; k < 5; ++k) {
    BodyDef b = box(Vec3(0.25, 0.25, 0.25), Vec3(0, 0, 0.4 + 0.25 + 0.5 * k));
    b.friction = 0.8;
    stack.push_back(world.create_body(b).value());
  }
  double heading = 0, worst_slide = 0, worst_lean = 0, worst_height = 0;
  int steps = 0;
  while (heading < 2 * M_PI + 0.5 && steps < 100000) {
    const double speed = std::min(top_speed, 1.0 * world.time());
    const double turn = speed / radius;
    BodyMotion steer;
    steer.linear_velocity = Vec3(speed * std::cos(heading), speed * std::sin(heading), 0);
    steer.angular_velocity = Vec3(0, 0, turn);
    ASSERT_TRUE(world.set_motion(platform, steer).is_ok());
    ASSERT_TRUE(world.step(kDt).is_ok());
    heading += turn * kDt;
    ++steps;
    for (int k = 0; k < 5; ++k) {
      const Vec3 on_deck = seen_from(world, platform, stack[k]);
      worst_slide = std::max(worst_slide, on_deck.head<2>().norm());
      worst_height = std::max(worst_height, std::abs(on_deck.z() - (0.1 + 0.25 + 0.5 * k)));
      if (k > 0) {
        const Vec3 below = seen_from(world, platform, stack[k - 1]);
        worst_lean = std::max(worst_lean, (on_deck - below).head<2>().norm());
      }
    }
  }
  // It went once around its circle (and a bit) at 2 m/s.
  EXPECT_GT(heading, 2 * M_PI);
  EXPECT_NEAR(world.body(platform)->linear_velocity().norm(), top_speed, 1e-12);
  EXPECT_LT(worst_slide, 0.02) << "the stack slid on the deck";
  EXPECT_LT(worst_lean, 0.01) << "the stack leaned";
  EXPECT_LT(worst_height, 0.01) << "a box left the one below it";
  for (BodyId id : stack)
    EXPECT_FALSE(world.body(id)->asleep());
}

// An elevator going up at 1 m/s, slowing at 2 m/s^2 (less than gravity: a lift that reverses
// faster throws what it carries, as it should) and going down at 1 m/s: the box on it rides it,
// touching all the way (no gap opens on the way down, nothing sinks in on the way up).
TEST(Kinematic, ElevatorCarriesABoxUpAndDown) {
  for (const SolverKind solver : {SolverKind::kSoft, SolverKind::kPgs, SolverKind::kExact}) {
    WorldSettings settings;
    settings.solver.kind = solver;
    World world(settings);
    BodyDef floor = box(Vec3(1, 1, 0.1), Vec3(0, 0, 0), BodyType::kKinematic);
    const BodyId lift = world.create_body(floor).value();
    const BodyId rider = world.create_body(box(Vec3(0.25, 0.25, 0.25), Vec3(0, 0, 0.35))).value();
    run(&world, 30);  // settle at rest first
    double worst_gap = 0, worst_sink = 0, lift_z = 0;
    for (int i = 0; i < 240; ++i) {
      const double t = i * kDt;  // 1 s up, 1 s slowing and reversing, 2 s down
      const double vz = t < 1 ? 1 : t < 2 ? 1 - 2 * (t - 1) : -1;
      BodyMotion motion;
      motion.linear_velocity = Vec3(0, 0, vz);
      ASSERT_TRUE(world.set_motion(lift, motion).is_ok());
      ASSERT_TRUE(world.step(kDt).is_ok());
      lift_z += vz * kDt;
      const double gap =
          world.body(rider)->position().z() - 0.35 - world.body(lift)->position().z();
      worst_gap = std::max(worst_gap, gap);
      worst_sink = std::max(worst_sink, -gap);
    }
    EXPECT_NEAR(world.body(lift)->position().z(), lift_z, 1e-12);
    EXPECT_LT(worst_gap, 1e-6) << solver_name(solver);
    EXPECT_LT(worst_sink, 1e-6) << solver_name(solver);
  }
}

TEST(Kinematic, WakesWhatItMeetsAndKeepsWhatItCarriesAwake) {
  World world;
  add_ground(&world);
  const BodyId sleeper = world.create_body(box(Vec3(0.5, 0.5, 0.5), Vec3(0, 0, 0.5))).value();
  BodyDef door = box(Vec3(0.1, 1, 1), Vec3(-3, 0, 1.05), BodyType::kKinematic);
  const BodyId pusher = world.create_body(door).value();
  run(&world, 120);
  ASSERT_TRUE(world.body(sleeper)->asleep());
  BodyMotion go;
  go.linear_velocity = Vec3(0.5, 0, 0);
  ASSERT_TRUE(world.set_motion(pusher, go).is_ok());
  run(&world, 60 * 6);  // reaches it after 4.8 s
  EXPECT_FALSE(world.body(sleeper)->asleep());
  EXPECT_GT(world.body(sleeper)->position().x(), 0.5);

  // A body on a deck creeping slower than the sleep threshold stays awake while it moves, and
  // sleeps once it stops.
  World creep;
  BodyDef slow_deck = box(Vec3(2, 2, 0.1), Vec3(0, 0, 0), BodyType::kKinematic);
  slow_deck.linear_velocity = Vec3(0.001, 0, 0);
  const BodyId deck = creep.create_body(slow_deck).value();
  const BodyId rider = creep.create_body(box(Vec3(0.25, 0.25, 0.25), Vec3(0, 0, 0.35))).value();
  run(&creep, 300);
  EXPECT_FALSE(creep.body(rider)->asleep());
  EXPECT_NEAR(creep.body(rider)->position().x(), 0.005, 1e-3);
  BodyMotion stop;
  stop.linear_velocity = Vec3::Zero();
  ASSERT_TRUE(creep.set_motion(deck, stop).is_ok());
  run(&creep, 300);
  EXPECT_TRUE(creep.body(rider)->asleep());
}

TEST(Kinematic, RefusesWhatWouldMoveItOtherwise) {
  World world;
  BodyDef def = box(Vec3(0.5, 0.5, 0.5), Vec3::Zero(), BodyType::kKinematic);
  def.force = Vec3(1, 0, 0);
  EXPECT_EQ(world.create_body(def).status().message(),
            "force: a kinematic body moves only by the velocity given it");
  def.force = Vec3::Zero();
  def.linear_damping = 1;
  EXPECT_EQ(world.create_body(def).status().message(),
            "linear_damping: a kinematic body moves only by the velocity given it");
  def.linear_damping = 0;
  def.linear_velocity = Vec3(1e9, 0, 0);
  EXPECT_NE(world.create_body(def).status().message().find("linear_velocity"), std::string::npos);
  def.linear_velocity = Vec3::Zero();
  BodyDef plane;
  plane.shape = HalfSpaceDef{};
  plane.type = BodyType::kKinematic;
  EXPECT_EQ(world.create_body(plane).status().message(), "type: a half_space must be static");
  BodyDef still = box(Vec3(0.5, 0.5, 0.5), Vec3::Zero(), BodyType::kStatic);
  still.linear_velocity = Vec3(1, 0, 0);
  EXPECT_NE(world.create_body(still).status().message().find("linear_velocity"),
            std::string::npos);

  const BodyId k = world.create_body(def).value();
  EXPECT_EQ(world.apply_impulse(k, Vec3(1, 0, 0), nullptr).message(),
            "body: a kinematic body moves only by the velocity given it");
  BodyMotion push;
  push.force = Vec3(1, 0, 0);
  EXPECT_EQ(world.set_motion(k, push).message(),
            "force: a kinematic body moves only by the velocity given it");
  BodyMotion fast;
  fast.angular_velocity = Vec3(0, 0, 1e9);
  EXPECT_NE(world.set_motion(k, fast).message().find("angular_velocity"), std::string::npos);
  BodyDef other_def = box(Vec3(0.5, 0.5, 0.5), Vec3(3, 0, 0), BodyType::kKinematic);
  const BodyId other = world.create_body(other_def).value();
  JointDef hinge;
  hinge.kind = JointKind::kBall;
  hinge.a = other;
  hinge.b = k;
  hinge.anchor = Vec3(1.5, 0, 0);
  EXPECT_EQ(world.create_joint(hinge).status().message(),
            "a: a joint needs a dynamic body on one side");
  hinge.b = BodyId{};  // the world
  EXPECT_EQ(world.create_joint(hinge).status().message(),
            "a: a joint needs a dynamic body on one side");
  // Nothing refused changed the body.
  EXPECT_EQ(world.body(k)->linear_velocity(), Vec3::Zero());
  EXPECT_EQ(world.body(k)->mass(), 0);
}

// A pendulum hung from a kinematic crane moving at a steady velocity swings, seen from the
// crane, as one hung from a fixed pivot (Galilean invariance): the same path to rounding, and the
// joint holds as well. Both solvers of joints: Gauss-Seidel rows and the direct solve.
TEST(Kinematic, APendulumFromAMovingCraneSwingsAsFromAFixedOne) {
  for (const bool direct : {true, false}) {
    auto hang = [direct](BodyType pivot_type, const Vec3& velocity) {
      WorldSettings settings;
      settings.solver.kind = direct ? SolverKind::kAuto : SolverKind::kSoft;
      World world(settings);
      BodyDef pivot = box(Vec3(0.2, 0.2, 0.2), Vec3(0, 0, 5), pivot_type);
      pivot.linear_velocity = velocity;
      const BodyId crane = world.create_body(pivot).value();
      // Level with the pivot: a swing of 180 degrees.
      const BodyId ball = hang_ball(&world, crane, Vec3(0, 0, 5), Vec3(1, 0, 5), velocity);
      return std::tuple{std::move(world), crane, ball};
    };
    auto [fixed, fixed_crane, fixed_ball] = hang(BodyType::kStatic, Vec3::Zero());
    const Vec3 velocity(2, 0.5, 1);
    auto [moving, crane, ball] = hang(BodyType::kKinematic, velocity);
    double worst = 0, worst_gap = 0;
    for (int i = 0; i < 120; ++i) {
      ASSERT_TRUE(fixed.step(kDt).is_ok());
      ASSERT_TRUE(moving.step(kDt).is_ok());
      const Vec3 seen = moving.body(ball)->position() - moving.body(crane)->position();
      const Vec3 expected = fixed.body(fixed_ball)->position() - fixed.body(fixed_crane)->position();
      worst = std::max(worst, (seen - expected).norm());
      worst_gap = std::max(worst_gap, std::abs(seen.norm() - 1));
    }
    EXPECT_NEAR((moving.body(crane)->position() - Vec3(0, 0, 5) - 2.0 * velocity).norm(), 0,
                1e-12);
    EXPECT_LT(worst, 1e-6) << (direct ? "direct" : "Gauss-Seidel");
    EXPECT_LT(worst_gap, 1e-9) << (direct ? "direct" : "Gauss-Seidel");
    EXPECT_FALSE(moving.body(ball)->asleep());
  }
}

// A pendulum asleep under a still crane wakes when the crane starts to move, and is carried.
TEST(Kinematic, AMovingCraneWakesWhatHangsFromIt) {
  World world;
  BodyDef pivot = box(Vec3(0.2, 0.2, 0.2), Vec3(0, 0, 5), BodyType::kKinematic);
  const BodyId crane = world.create_body(pivot).value();
  const BodyId ball = hang_ball(&world, crane, Vec3(0, 0, 5), Vec3(0, 0, 4));
  run(&world, 180);
  ASSERT_TRUE(world.body(ball)->asleep());
  BodyMotion go;
  go.linear_velocity = Vec3(1, 0, 0);
  ASSERT_TRUE(world.set_motion(crane, go).is_ok());
  run(&world, 60);
  EXPECT_FALSE(world.body(ball)->asleep());
  EXPECT_GT(world.body(ball)->position().x(), 0.5);  // dragged along behind the crane
  EXPECT_NEAR((world.body(ball)->position() - world.body(crane)->position()).norm(), 1, 1e-6);
}

// A restored world steps on bit for bit, kinematic bodies and their riders included, and the
// answer does not depend on the thread count.
TEST(Kinematic, SnapshotsAndThreadCountsGiveTheSameBits) {
  auto make = [](int threads) {
    WorldSettings settings;
    settings.threads = threads;
    World world(settings);
    add_ground(&world);
    BodyDef deck = box(Vec3(3, 3, 0.1), Vec3(0, 0, 0.5), BodyType::kKinematic);
    deck.linear_velocity = Vec3(0.5, 0.2, 0.1);
    deck.angular_velocity = Vec3(0, 0, 0.4);
    world.create_body(deck).value();
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        for (int k = 0; k < 3; ++k)
          world.create_body(box(Vec3(0.2, 0.2, 0.2), Vec3(-1.2 + 0.8 * i, -1.2 + 0.8 * j,
                                                          0.85 + 0.45 * k)))
              .value();
    return world;
  };
  World one = make(1), two = make(2);
  run(&one, 60);
  run(&two, 60);
  World again(one.settings());
  const Status restored = again.restore_state(one.save_state());
  ASSERT_TRUE(restored.is_ok()) << restored.message();
  run(&one, 60);
  run(&two, 60);
  run(&again, 60);
  for (std::uint32_t slot = 0; slot < one.slot_count(); ++slot) {
    const BodyId id = one.id_at(slot);
    EXPECT_EQ(one.body(id)->position(), two.body(id)->position()) << slot;
    EXPECT_EQ(one.body(id)->position(), again.body(id)->position()) << slot;
    EXPECT_EQ(one.body(id)->linear_velocity(), again.body(id)->linear_velocity()) << slot;
  }
  EXPECT_TRUE(again.body(again.id_at(1))->is_kinematic());
}

// The standard scene `carousel`: four stacks of five on a deck turning at 0.5 rad/s for its 20 s
// stay standing where they stand on it, turning with it. Their one error is the creep outward of
// friction solved at the velocity level: a box carried round moves along the tangent through a
// step while the deck's point under it turns, and ends r (w dt)^2 / 2 farther out, which nothing
// pulls back (docs/DYNAMICS.md, "Kinematic bodies").
TEST(Kinematic, CarouselKeepsItsStacks) {
  const SceneDef scene = carousel_scene();
  Result<World> made = make_world(scene);
  ASSERT_TRUE(made) << made.status().message();
  World& world = made.value();
  const int steps = static_cast<int>(std::lround(scene.duration / scene.dt));
  for (int i = 0; i < steps; ++i)
    ASSERT_TRUE(world.step(scene.dt).is_ok());
  const BodyId deck = world.id_at(1);
  const double turn = 0.5, turned = turn * world.time();
  EXPECT_LT(world.body(deck)->orientation().angularDistance(
                Quat(Eigen::AngleAxisd(turned, Vec3::UnitZ()))),
            1e-9);
  const double radius = 2.5;
  const double creep = steps * radius * std::pow(turn * scene.dt, 2) / 2;  // 0.104 m
  for (std::uint32_t slot = 2; slot < world.slot_count(); ++slot) {
    const Vec3 start = scene.bodies[slot].position;
    const Vec3 now = world.body(world.id_at(slot))->position();
    const double bearing = std::atan2(now.y(), now.x()) - std::atan2(start.y(), start.x());
    EXPECT_LT(std::abs(std::remainder(bearing - turned, 2 * M_PI)), 0.01) << slot;
    EXPECT_NEAR(now.z(), start.z(), 0.01) << slot;
    const double outward = now.head<2>().norm() - radius;
    EXPECT_GT(outward, 0.9 * creep) << slot;
    EXPECT_LT(outward, 1.1 * creep) << slot;
  }
}

TEST(Kinematic, SceneFilesReadAndWriteIt) {
  const char* text = R"({"bodies": [
    {"shape": "box", "size": [4, 4, 0.2], "kinematic": true, "linear_velocity": [1, 0, 0],
     "angular_velocity": [0, 0, 0.5]}]})";
  Result<SceneDef> scene = parse_scene(text);
  ASSERT_TRUE(scene.ok()) << scene.error();
  EXPECT_EQ(scene.value().bodies[0].type, BodyType::kKinematic);
  Result<SceneDef> again = parse_scene(scene_to_json(scene.value()));
  ASSERT_TRUE(again.ok()) << again.error();
  EXPECT_EQ(again.value().bodies[0].type, BodyType::kKinematic);
  EXPECT_EQ(again.value().bodies[0].angular_velocity, Vec3(0, 0, 0.5));
  Result<SceneDef> both = parse_scene(
      R"({"bodies": [{"shape": "box", "size": [1, 1, 1], "static": true, "kinematic": true}]})");
  ASSERT_FALSE(both.ok());
  EXPECT_NE(both.error().find("bodies[0].kinematic: a body is static or kinematic, not both"),
            std::string::npos)
      << both.error();
  Result<SceneDef> pushed = parse_scene(
      R"({"bodies": [{"shape": "box", "size": [1, 1, 1], "kinematic": true, "force": [1, 0, 0]}]})");
  ASSERT_FALSE(pushed.ok());
  EXPECT_NE(pushed.error().find("force: a kinematic body moves only by the velocity given it"),
            std::string::npos)
      << pushed.error();
}

}  // namespace
}  // namespace tumble
